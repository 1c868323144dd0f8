"""How many server processes this machine runs by default: one module below both
``sandbox serve`` (:mod:`sandbox.web.serving.workers`) and the classroom benchmark that must
expect the same count (:mod:`sandbox.bench.classroom`)."""

from __future__ import annotations

import os
from collections.abc import Callable

DEFAULT_WORKERS_CAP = 4
"""Most worker processes started when ``--workers`` is not given.

Each worker is a whole interpreter with mujoco, viser and a simulation: about 85 MB. One
per core would start 8 to 16 of them on a teacher's laptop (an 8-16 core Mac), over 1 GB
before the first student arrives, for a class that 4 cores serve. ``--workers N`` given
explicitly still starts up to :data:`sandbox.cli.MAX_WORKERS`."""


def default_workers() -> int:
    """Worker processes ``sandbox serve`` starts by default: one per core this process may
    use, at most :data:`DEFAULT_WORKERS_CAP`, at least 1.

    The cores this process may use: :func:`os.process_cpu_count` where it exists (Python
    3.13+: honours the affinity mask and ``PYTHON_CPU_COUNT``), else the affinity mask
    (:func:`os.sched_getaffinity`, Linux), else every core (:func:`os.cpu_count`: macOS,
    Windows), which may be unknown (``None``: one worker).
    """
    cores: int | None
    process_cpu_count: Callable[[], int | None] | None = getattr(os, "process_cpu_count", None)
    sched_getaffinity: Callable[[int], set[int]] | None = getattr(os, "sched_getaffinity", None)
    if process_cpu_count is not None:
        cores = process_cpu_count()
    elif sched_getaffinity is not None:
        cores = len(sched_getaffinity(0))
    else:
        cores = os.cpu_count()
    return max(1, min(cores or 1, DEFAULT_WORKERS_CAP))
