"""Run the installed ``sandbox`` console script as a hostile input's victim: in a child
process with a time limit and a 4 GB address-space cap, its peak memory read from
``wait4`` by a small launcher; and the clean refusal every robustness suite expects
(one line, exit 2)."""

from __future__ import annotations

import os
import signal
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


LAUNCHER = """
import os, resource, sys
limit, report, argv = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
pid = os.fork()
if pid == 0:
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    os.execv(argv[0], argv)
_, status, usage = os.wait4(pid, 0)
with open(report, "w") as f:
    f.write(str(usage.ru_maxrss))
code = os.waitstatus_to_exitcode(status)
sys.exit(code if code >= 0 else 128 - code)
"""
"""Starts ``sandbox`` from a fresh, small Python and reports its peak RSS. Linux carries
a process's high-water RSS across ``exec``: a child forked straight from this test
process (hundreds of MB after a thousand tests) would report the test process's own
peak, not the one of ``sandbox``."""


def run_cli(
    *args: str, cwd: Path | None = None, timeout: float = TIMEOUT, env: dict | None = None
) -> Outcome:
    """Run ``sandbox ARGS`` in ``cwd``; its exit code, output, wall time and peak RSS.

    A child still running after ``timeout`` seconds is killed and the test fails. The
    address space is capped at 4 GB so that a regression fails here instead of swapping.
    """
    with (
        tempfile.TemporaryFile() as out,
        tempfile.TemporaryFile() as err,
        tempfile.TemporaryDirectory() as tmp,
    ):
        report = Path(tmp) / "maxrss"
        start = time.monotonic()
        proc = subprocess.Popen(
            [sys.executable, "-c", LAUNCHER, str(4 * GIB), str(report), SANDBOX, *args],
            cwd=cwd,
            stdout=out,
            stderr=err,
            stdin=subprocess.DEVNULL,
            env={**os.environ, **(env or {})},
            start_new_session=True,  # the launcher and sandbox: one group, killed together
        )
        try:
            code = proc.wait(timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            pytest.fail(f"sandbox {' '.join(a[:40] for a in args)} ran over {timeout} s")
        seconds = time.monotonic() - start
        out.seek(0)
        err.seek(0)
        return Outcome(
            code,
            out.read().decode(errors="replace"),
            err.read().decode(errors="replace"),
            seconds,
            int(report.read_text()) * 1024,
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
