"""Run the installed ``sandbox`` console script as a hostile input's victim: in a child
process with a time limit and a 4 GB address-space cap, its peak memory read from
``wait4``; and the clean refusal every robustness suite expects (one line, exit 2)."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

SANDBOX = str(Path(sys.executable).parent / "sandbox")
TIMEOUT = 20.0  # seconds a refusal may take (the bound)
GIB = 2**30  # memory a refusal may take


@dataclass
class Outcome:
    code: int
    out: str
    err: str
    seconds: float
    rss_bytes: int


def run_cli(
    *args: str, cwd: Path | None = None, timeout: float = TIMEOUT, env: dict | None = None
) -> Outcome:
    """Run ``sandbox ARGS`` in ``cwd``; its exit code, output, wall time and peak RSS.

    A child still running after ``timeout`` seconds is killed and the test fails. The
    address space is capped at 4 GB so that a regression fails here instead of swapping.
    """

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (4 * GIB, 4 * GIB))

    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.monotonic()
        proc = subprocess.Popen(
            [SANDBOX, *args],
            cwd=cwd,
            stdout=out,
            stderr=err,
            stdin=subprocess.DEVNULL,
            preexec_fn=limit,
            env={**os.environ, **(env or {})},
        )
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - start > timeout:
                proc.kill()
                os.wait4(proc.pid, 0)
                pytest.fail(f"sandbox {' '.join(a[:40] for a in args)} ran over {timeout} s")
            time.sleep(0.01)
        seconds = time.monotonic() - start
        out.seek(0)
        err.seek(0)
        return Outcome(
            os.waitstatus_to_exitcode(status),
            out.read().decode(errors="replace"),
            err.read().decode(errors="replace"),
            seconds,
            usage.ru_maxrss * 1024,
        )


def assert_refused(res: Outcome, *words: str, code: int = 2) -> str:
    """One ``sandbox: error:`` line with ``words``, the exit code, no traceback, within
    :data:`TIMEOUT` and under 1 GB; returns the line."""
    assert "Traceback" not in res.err, res.err
    lines = res.err.strip().splitlines()
    assert res.code == code, (res.code, res.err)
    assert len(lines) == 1, res.err
    assert lines[0].startswith("sandbox: error: "), lines[0]
    for word in words:
        assert word in lines[0], (word, lines[0])
    assert res.seconds < TIMEOUT
    assert res.rss_bytes < GIB, f"{res.rss_bytes / 2**20:.0f} MB"
    print(f"{res.seconds:.1f} s, peak RSS {res.rss_bytes / 2**20:.0f} MB: {lines[0][:80]}")
    return lines[0]
