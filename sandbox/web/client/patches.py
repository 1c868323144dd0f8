"""What the project's uses of viser's internals share: each one (the upload cap of
:mod:`.uploads`, the fast pose messages of :mod:`.wire`, the loop-bound message events of
:mod:`.wakeups`) first checks that the viser installed has the internals it relies on,
and leaves viser as it is, with one warning line, when it does not; a change to viser's
classes is made once per process (:func:`install_once`)."""

from __future__ import annotations

import logging
from collections.abc import Callable

log = logging.getLogger(__name__)


def internals_present(check: Callable[[], bool], missing: str) -> bool:
    """True when ``check()`` finds what a change to viser needs; else log ``missing``
    (what stays as viser has it) once and return False. An ImportError counts as absent."""
    try:
        ok = check()
    except ImportError:
        ok = False
    if not ok:
        log.warning(missing)
    return ok


_installed: set[str] = set()


def install_once(
    name: str, check: Callable[[], bool], missing: str, apply: Callable[[], None]
) -> bool:
    """Change viser with ``apply()`` once per process under ``name``, when ``check()``
    finds the internals it needs (else log ``missing``, :func:`internals_present`); True
    when the change is in place."""
    if name in _installed:
        return True
    if not internals_present(check, missing):
        return False
    apply()
    _installed.add(name)
    return True
