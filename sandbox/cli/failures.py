"""How a command that goes wrong ends (contracts).

Every user error prints one line ``sandbox: error: ...`` and exits with code 2; a
diverging simulation exits with code 3 after writing what was computed so far. Any other
exception (a bug) prints one line ``sandbox: error: internal error: <type>: <message> —
please report it (...)`` and exits with code 1; set the environment variable
``SANDBOX_DEBUG=1`` to get the traceback instead. Ctrl-C exits with code 130, quietly.
MuJoCo's warnings are held back meanwhile, and shown only after a command that succeeded.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator

import mujoco

from sandbox.errors import one_line

DEBUG_ENV = "SANDBOX_DEBUG"
"""Environment variable: ``1`` re-raises unexpected exceptions (a traceback for developers)."""

MAX_HELD_WARNINGS = 10
"""MuJoCo warnings kept for the end of a command (the rest are dropped)."""


@contextlib.contextmanager
def held_mujoco_warnings(held: list[str]) -> Iterator[None]:
    """Collect MuJoCo's warnings (printed on stderr by default) instead of printing them."""

    def keep(text: object) -> None:
        if len(held) < MAX_HELD_WARNINGS:
            held.append(one_line(str(text)))

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(keep)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def internal_error(exc: BaseException) -> int:
    """Print the last-resort line for an unexpected exception; exit code 1."""
    text = one_line(str(exc))
    text = text if len(text) <= 300 else text[:297] + "..."
    print(
        f"sandbox: error: internal error: {type(exc).__name__}: {text} — please report it "
        f"(with the command; {DEBUG_ENV}=1 shows the traceback)",
        file=sys.stderr,
    )
    return 1
