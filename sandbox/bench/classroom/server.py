"""The server under test: ``python -m sandbox.cli serve SCENE --port P`` on a free loopback
port, in its own process group, ready once it answers HTTP, and always stopped (SIGTERM,
then SIGKILL, to the whole group; through psutil where there are no process groups).
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

from sandbox.bench.classroom.processes import stop_tree
from sandbox.errors import BadOption


def free_port() -> int:
    """A TCP port free on 127.0.0.1 right now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


class Server:
    """``sandbox serve`` in its own process group; a context manager that always stops it.

    Args:
        scene: Scene, lesson or MJCF path.
        follow: Pass ``--follow``.
        workers: Pass ``--workers N`` when not None.
        timeout: Bound on the wait for the first HTTP answer [s].
    """

    def __init__(
        self, scene: str, *, follow: bool = False, workers: int | None = None, timeout: float = 60
    ) -> None:
        self.port = free_port()
        self.command = [sys.executable, "-m", "sandbox.cli", "serve", scene]
        self.command += ["--port", str(self.port)]
        self.command += ["--follow"] if follow else []
        self.command += ["--workers", str(workers)] if workers is not None else []
        self.timeout = timeout
        self.log = tempfile.TemporaryFile()
        self.proc: subprocess.Popen[bytes] | None = None

    @property
    def pid(self) -> int:
        """Process id of the server (root of its tree)."""
        assert self.proc is not None
        return self.proc.pid

    def __enter__(self) -> Server:
        self.proc = subprocess.Popen(
            self.command,
            stdin=subprocess.DEVNULL,
            stdout=self.log,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # POSIX: its own process group (ignored on Windows)
            # the French banner in the log, whatever the locale (cp1252 has no "≥" or "→")
            env={**os.environ, "PYTHONIOENCODING": "utf-8"},
        )
        try:
            self._wait_ready()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def output(self, *, head: bool = False) -> str:
        """What the server printed so far: its last 2000 characters (first 20,000 with
        ``head``, where the banner is)."""
        self.log.seek(0)
        if head:
            return self.log.read(20_000).decode(errors="replace")
        return self.log.read().decode(errors="replace")[-2000:]

    def teacher_path(self, timeout: float = 10.0) -> str | None:
        """``/prof/<token>`` from the teacher link the server printed (``--follow``)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            found = re.search(r"https?://\S+?(/prof/[A-Za-z0-9_-]+)", self.output(head=True))
            if found:
                return found.group(1)
            time.sleep(0.2)
        return None

    def _wait_ready(self) -> None:
        assert self.proc is not None
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise BadOption(
                    f"the server exited with code {self.proc.returncode}: "
                    f"{' '.join(self.command[2:])}\n{self.output().strip()}"
                )
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{self.port}/", timeout=1):
                    return
            except OSError:
                time.sleep(0.2)
        raise BadOption(f"the server did not answer on port {self.port} within {self.timeout} s")

    def stop(self) -> None:
        """SIGTERM (the server closes its sessions), then SIGKILL, to the whole group.

        Each signal gets a bounded wait; SIGINT is not used because a bench started in
        the background of a shell inherits it ignored, and so would the server. Where
        there are no process groups (Windows), the server's tree is terminated, then
        killed, through psutil.
        """
        proc = self.proc
        if proc is None:
            return
        if PROCESS_GROUPS:
            for sig, wait in ((signal.SIGTERM, 8.0), (signal.SIGKILL, 3.0)):
                if proc.poll() is not None:
                    break
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(proc.pid, sig)
                with contextlib.suppress(subprocess.TimeoutExpired):
                    proc.wait(wait)
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(proc.pid, signal.SIGKILL)  # leftovers of the group
        else:
            stop_tree(proc.pid)
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(3.0)
        self.log.close()
        self.proc = None


PROCESS_GROUPS = hasattr(os, "killpg")
"""POSIX: :meth:`Server.stop` signals the server's process group (it has its own)."""
