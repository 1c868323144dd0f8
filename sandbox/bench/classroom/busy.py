"""``--busy-core``: another program keeping one core busy during a classroom run, as a
teacher's laptop driving a projector and a video call does."""

from __future__ import annotations

import subprocess
import sys
from types import TracebackType

SPIN = "while True:\n    pass\n"
"""The other program: Python spinning (the same on Linux, macOS and Windows)."""


class BusyCore:
    """One process spinning on a core from ``__enter__`` to ``__exit__`` (always stopped)."""

    def __init__(self, enabled: bool = True) -> None:
        self.enabled = enabled
        self.proc: subprocess.Popen[bytes] | None = None

    def __enter__(self) -> BusyCore:
        if self.enabled:
            self.proc = subprocess.Popen(  # a literal program: no user input reaches it
                [sys.executable, "-c", SPIN],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        proc, self.proc = self.proc, None
        if proc is not None:
            proc.kill()
            proc.wait(timeout=10)
