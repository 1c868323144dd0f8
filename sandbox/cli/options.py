"""Command-line values every command checks the same way: ``--set NAME=VALUE`` pairs, the
folders a command writes into, ports and worker counts. Each refusal is one line (a
:class:`~sandbox.errors.BadOption` or :class:`~sandbox.errors.BadParameter`, exit code 2).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from sandbox.errors import BadOption, BadParameter, shown
from sandbox.physics.limits import MAX_MODEL_BYTES, estimate, machine_bytes, prescan
from sandbox.physics.model import Source

MAX_WORKERS = 64
"""Most server processes ``--workers`` may start."""

MAX_NAME_CHARS = 200
"""Longest ``--set`` name or value accepted."""


def own_source(target: str | Path, max_memory: float | None) -> Source:
    """The scene or MJCF file named on the command line: the file is the user's own and
    may take :func:`~sandbox.physics.limits.machine_bytes` (``--max-memory``) to compile;
    above the limit of files from outside, a note on stderr says what it will take.

    Raises:
        UnknownScene, BadModel: see :func:`sandbox.scenes.resolve`.
    """
    from sandbox.scenes import resolve  # the registry: only once a command needs it

    source = resolve(target, max_bytes=machine_bytes(max_memory))
    if source.scene is None:
        prescan(source.path, source.max_bytes)  # nothing parsed that the limit refuses
        size, what = estimate(source.path)
        if MAX_MODEL_BYTES < size <= source.max_bytes:
            print(
                f"sandbox: note: {shown(str(source.path))} takes about {size / 2**20:,.0f} MB "
                f"to compile, mostly {what} (allowed: {source.max_bytes / 2**20:,.0f} MB, "
                "--max-memory)",
                file=sys.stderr,
            )
    return source


def pairs(items: Sequence[str]) -> dict[str, str]:
    """The ``--set NAME=VALUE`` items as {name: value} (both stripped, the value unparsed).

    Raises:
        BadParameter: an item without ``=`` or a name, or longer than
            :data:`MAX_NAME_CHARS`, or holding a NUL character.
    """
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise BadParameter(
                f"--set expects NAME=VALUE, got {shown(item)}; e.g. --set speed_rpm=3000"
            )
        if len(name) > MAX_NAME_CHARS or len(value) > MAX_NAME_CHARS or "\x00" in item:
            raise BadParameter(
                f"--set {shown(item)} is not a parameter name and a number; "
                "see 'sandbox describe SCENE' for the names"
            )
        out[name.strip()] = value.strip()
    return out


def check_folder(path: Path, option: str) -> None:
    """A folder a command writes into (it may not exist yet): refuse a file or a bad name."""
    no_nul(path, option)
    try:
        if path.exists() and not path.is_dir():
            raise BadOption(f"{option} {shown(str(path))} is a file; give a folder")
    except OSError as exc:
        raise BadOption(f"{option} {shown(str(path))}: {exc.strerror}; give another path") from None


def no_nul(path: Path, option: str) -> None:
    """Refuse a path holding a NUL character (no system call takes it), naming ``option``.

    Raises:
        BadOption: the path contains a NUL character.
    """
    if "\x00" in str(path):
        raise BadOption(f"{option} {shown(str(path))} contains a NUL character; give another path")


def check_port_range(port: int) -> None:
    """Refuse a TCP port outside 0 to 65535.

    Raises:
        BadOption: the port is out of range.
    """
    if not 0 <= port <= 65535:
        raise BadOption(f"--port must be between 0 and 65535, got {port!r}")
