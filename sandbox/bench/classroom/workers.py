"""A classroom run seen worker by worker: which browsers each server process served, at
what frame rate, for how much CPU.

When a class fills the two cores, the same code gave the heavy top 48.7 then 27.5 frames/s
from one run to the next, and within one run the browsers of one worker process got
~35 frames/s while those of the other got ~25, each worker's busiest thread using the same
0.8 core. Figures summed over the class hide that; :func:`by_worker` keeps them apart
(frames/s of each worker's browsers, the worker's CPU, its CPU per drawn frame), so that
the next run can tell a worker that costs more per frame from one that gets less of the
processor.

Browsers are told apart by the local port of their connection: the server's connection
of that browser has it as its remote port
(:func:`sandbox.bench.classroom.processes.browsers_by_process`).
"""

from __future__ import annotations

import statistics
from collections.abc import Mapping, Sequence
from typing import Any


def by_worker(
    fps: Sequence[float],
    ports: Sequence[int | None],
    owner: Mapping[int, int],
    thread_cores: Mapping[tuple[int, int], float],
) -> list[dict[str, Any]]:
    """One record per server process that served a browser, most browsers first.

    Args:
        fps: Update frames/s of each browser over the window.
        ports: Local port of each browser's connection (None: not known).
        owner: Browser port -> server pid
            (:func:`sandbox.bench.classroom.processes.browsers_by_process`).
        thread_cores: Cores each server thread used over the window, keyed (pid, tid).

    Returns:
        Records with ``pid``, ``browsers``, ``fps_median``, ``fps_min``, ``cpu_cores``
        (all its threads), ``busiest_thread_cores`` and ``cpu_ms_per_frame`` (its CPU
        over the frames its browsers got).
    """
    frames: dict[int, list[float]] = {}
    for rate, port in zip(fps, ports, strict=True):
        pid = owner.get(port) if port is not None else None
        if pid is not None:
            frames.setdefault(pid, []).append(float(rate))
    out = []
    for pid, rates in frames.items():
        cores = [c for (p, _), c in thread_cores.items() if p == pid]
        total = sum(cores)
        drawn = sum(rates)
        out.append(
            {
                "pid": pid,
                "browsers": len(rates),
                "fps_median": statistics.median(rates),
                "fps_min": min(rates),
                "cpu_cores": total,
                "busiest_thread_cores": max(cores, default=0.0),
                "cpu_ms_per_frame": total * 1000.0 / drawn if drawn > 0 else float("nan"),
            }
        )
    return sorted(out, key=lambda r: (-r["browsers"], r["pid"]))


def worker_lines(workers: Sequence[Mapping[str, Any]]) -> list[str]:
    """The report's lines for :func:`by_worker`'s records (none for a single worker)."""
    if len(workers) < 2:
        return []
    return [
        f"  worker {i + 1}                     {w['browsers']} browsers, frames/s median "
        f"{w['fps_median']:.1f} (min {w['fps_min']:.1f}), {w['cpu_cores']:.2f} cores "
        f"(busiest thread {w['busiest_thread_cores']:.2f}), {w['cpu_ms_per_frame']:.2f} ms "
        "per frame"
        for i, w in enumerate(workers)
    ]


def fps_ratio(workers: Sequence[Mapping[str, Any]]) -> float:
    """The slowest worker's median frames/s over the fastest one's: 1 when the workers
    serve their browsers alike (NaN with fewer than two workers, or none drawn)."""
    rates = [float(w["fps_median"]) for w in workers]
    if len(rates) < 2 or max(rates) <= 0:
        return float("nan")
    return min(rates) / max(rates)
