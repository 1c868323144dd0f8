"""The server's queue of parameter studies: low priority on every platform, studies
taking turns, bounded, and no process left once a study ends or is cancelled."""

from __future__ import annotations

import os
import sys
import time
import types
from typing import Any

import psutil
import pytest
from conftest import wait_for

from sandbox.sweep import Measure, Study, Vary
from sandbox.web.loop.study_queue import NICE, StudyJob, StudyQueue, lower_priority, progress_words


def _rotor(count: int, duration: float = 0.05) -> StudyJob:
    study = Study("rotor", (Vary("speed_rpm", 0.0, 6000.0, count),), Measure("bearing_A"), duration)
    return StudyJob(study, study.points())


def niceness(study: Study, point: dict[str, float]) -> dict[str, Any]:
    """A run that reports the priority it ran at (picklable: the worker imports it)."""
    return {"nice": os.nice(0) if hasattr(os, "nice") else None, **point}


def slow(study: Study, point: dict[str, float]) -> dict[str, Any]:
    """A run of a tenth of a second (picklable)."""
    time.sleep(0.1)
    return {"status": "ok", **point}


def _children() -> set[int]:
    """Processes this one started, but multiprocessing's resource tracker (one per
    process that ever used a spawn context, gone with it: not a study's)."""
    out = set()
    for p in psutil.Process().children(recursive=True):
        try:
            if not any("resource_tracker" in part for part in p.cmdline()):
                out.add(p.pid)
        except psutil.Error:  # ended meanwhile
            pass
    return out


def test_priority_is_lowered_with_nice_where_it_exists(monkeypatch):
    calls: list[int] = []
    monkeypatch.setattr(os, "nice", lambda n: calls.append(n) or 0, raising=False)
    lower_priority()
    assert calls == [NICE]


def test_priority_is_lowered_through_psutil_on_windows(monkeypatch):
    """The path a Windows laptop takes: no os.nice, psutil's below-normal class."""
    monkeypatch.delattr(os, "nice", raising=False)
    set_to: list[int] = []
    fake = types.SimpleNamespace(
        BELOW_NORMAL_PRIORITY_CLASS=16384,
        Process=lambda: types.SimpleNamespace(nice=set_to.append),
    )
    monkeypatch.setitem(sys.modules, "psutil", fake)
    lower_priority()
    assert set_to == [16384]
    monkeypatch.setitem(sys.modules, "psutil", None)  # not installed: runs, unlowered
    lower_priority()


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
@pytest.mark.skipif(not hasattr(os, "nice"), reason="POSIX niceness")
def test_runs_go_to_a_lowered_process_that_ends_with_the_study():
    before = _children()
    queue = StudyQueue(run=niceness)
    job = _rotor(3)
    queue.submit(job)
    assert wait_for(lambda: job.finished, timeout=60)
    assert [r["nice"] for r in job.rows if r] == [os.nice(0) + NICE] * 3
    assert wait_for(lambda: queue.processes == 0 and _children() <= before, timeout=20)


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_studies_take_turns_run_by_run():
    """A short study that comes second is not held back by a long one."""
    queue = StudyQueue(run=slow)
    long, short = _rotor(30), _rotor(3)
    queue.submit(long)
    queue.submit(short)
    assert queue.ahead_of(short) >= 25
    assert wait_for(lambda: short.finished, timeout=60, poll=0.005)
    assert long.done <= 6  # the pool's two first runs, then one each in turn
    assert all(r is not None and r["status"] == "ok" for r in short.rows)
    assert wait_for(lambda: long.finished, timeout=60)
    queue.close()


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_a_cancelled_study_leaves_no_process_behind():
    before = _children()
    queue = StudyQueue()
    job = _rotor(200, duration=0.5)
    queue.submit(job)
    assert wait_for(lambda: queue.processes > 0, timeout=30)
    queue.cancel(job)
    assert job.finished and job.pending() == 0
    assert wait_for(lambda: queue.processes == 0 and _children() <= before, timeout=30)
    assert "annulée" in progress_words(job, 0)


def test_the_queue_is_bounded():
    queue = StudyQueue(max_waiting=10)
    with pytest.raises(OverflowError):
        queue.submit(_rotor(11))
    queue.close()
    with pytest.raises(OverflowError):
        queue.submit(_rotor(2))  # closed: the server stops


def test_the_shared_queue_is_one_per_process_and_renewed_after_close():
    a = StudyQueue.shared()
    assert StudyQueue.shared() is a
    a.close()
    assert StudyQueue.shared() is not a


def test_progress_in_french():
    job = _rotor(13)
    assert progress_words(job, 4) == (
        "0 simulations sur 13 faites (à tour de rôle avec 4 simulations d'autres élèves)."
    )
    job.done, job.ended = 13, job.started + 1.25
    assert progress_words(job, 0) == "Étude terminée : 13 simulations en 1,2 s."
