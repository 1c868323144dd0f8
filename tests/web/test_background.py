"""The low-priority pool shared by studies and videos (sandbox.web.loop.background)."""

from __future__ import annotations

import os

import pytest

from sandbox.web.loop.background import NICE, BackgroundPool


def _priority() -> int:
    return os.nice(0) if hasattr(os, "nice") else 0


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_the_pool_starts_with_its_first_job_lowered_and_ends_when_stopped():
    pool = BackgroundPool(1)
    assert pool.processes == 0  # nothing started before a job
    try:
        got = pool.submit(_priority).result(timeout=60)
        if hasattr(os, "nice"):
            assert got == min(19, _priority() + NICE)
        assert pool.processes == 1
    finally:
        pool.stop()
    assert pool.processes == 0


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_a_stopped_pool_starts_again_for_the_next_job():
    pool = BackgroundPool(1)
    try:
        assert pool.submit(sum, range(10)).result(timeout=60) == 45
        pool.stop()
        assert pool.processes == 0
        assert pool.submit(sum, range(5)).result(timeout=60) == 10
        assert pool.processes == 1
    finally:
        pool.stop()
