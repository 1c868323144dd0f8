"""The targets a classroom run is judged by (issues 12 and 20): a class of 30, a crowd of
60, ``--follow``, a flood, and those every run has; each applying target given its value
and PASS/FAIL (printed, never asserted).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Target:
    """One target of issue 12: ``value(results) op limit`` for ``browsers`` clients."""

    label: str
    key: str
    op: str  # ">=", "<=", "<" or "is"
    limit: float
    browsers: int | None = None


CLASS_TARGETS = (
    Target("median update frames/s >= 45", "fps.median", ">=", 45, 30),
    Target("min update frames/s >= 30", "fps.min", ">=", 30, 30),
    Target("simulated time >= 0.98 of real time (slowest)", "sim_rate.min", ">=", 0.98, 30),
    Target("server CPU per update frame <= 0.4 ms", "server_cpu_ms_per_frame", "<=", 0.4, 30),
    Target("worker sessions within one of each other", "split", "<=", 1),
)
"""Issue 20: what a class of 30, each with their own simulation, gets in every scene."""
CROWD_TARGETS = (
    Target("median update frames/s >= 30", "fps.median", ">=", 30, 60),
    Target("simulated time >= 0.98 of real time (slowest)", "sim_rate.min", ">=", 0.98, 60),
    Target("worker sessions within one of each other", "split", "<=", 1),
)
"""Sixty browsers on one laptop (the rotor): slower, never behind real time."""
FOLLOW_TARGETS = (
    Target("--follow: median update frames/s >= 30", "fps.median", ">=", 30, 120),
    Target("--follow: server CPU <= 1 core", "server_cpu_cores", "<=", 1.0, 120),
)
FLOOD_TARGET = Target(
    'a student flooding "Pas" leaves the others >= 80 % of their frames/s',
    "side.ratio_min",
    ">=",
    0.8,
)
BUSY_TARGETS = (
    Target("--busy-core: min update frames/s >= 15", "fps.min", ">=", 15, 30),
    Target("--busy-core: simulated time >= 0.98 of real time", "sim_rate.min", ">=", 0.98, 30),
)
"""Issue 35: one core kept busy by another program, the class still in real time at 15
frames/s or more."""
COMMON_TARGETS = (
    Target("idle after 20 connect-and-drop: < 0.05 cores within 10 s", "idle", "<", 0.05),
    Target("a foreign Origin gets no session", "origin", "is", 1.0),
)
CROWD = 45
"""From this many browsers a run is judged by :data:`CROWD_TARGETS`."""


def split(results: dict[str, Any]) -> float:
    """Largest difference between the browsers of two worker processes (0 for one)."""
    counts = list(results["main"]["clients_per_process"])
    workers = results.get("worker_count") or len(counts)
    counts += [0] * max(0, int(workers) - len(counts))
    return float(max(counts) - min(counts)) if len(counts) > 1 else 0.0


def _value(results: dict[str, Any], key: str) -> float:
    if key == "idle":
        return results["drop"]["idle_cores"] if "drop" in results else math.nan
    if key == "origin":
        return float(results["origin"]["refused"])
    if key == "split":
        return split(results)
    value: Any = results["main"]
    for part in key.split("."):
        value = value[part]
    return float(value)


def targets(results: dict[str, Any]) -> list[dict[str, Any]]:
    """The targets that apply to this run, each with its value and PASS/FAIL."""
    chosen: tuple[Target, ...]
    if results["follow"]:
        chosen = FOLLOW_TARGETS
    elif results.get("busy_core"):
        chosen = BUSY_TARGETS
    elif results["main"]["clients"] >= CROWD:
        chosen = CROWD_TARGETS
    else:
        chosen = CLASS_TARGETS
    if isinstance(results["main"].get("side"), dict) and "ratio_min" in results["main"]["side"]:
        chosen += (FLOOD_TARGET,)
    out = []
    for t in chosen + COMMON_TARGETS:
        if t.key == "idle" and "drop" not in results:
            continue  # connect-and-drop phase not run
        if t.key == "origin" and "origin" not in results:
            continue
        value = _value(results, t.key)
        ok = {
            ">=": value >= t.limit,
            "<=": value <= t.limit,
            "<": value < t.limit,
            "is": value == t.limit,
        }[t.op]
        out.append(
            {
                "target": t.label,
                "key": t.key,
                "value": value,
                "browsers": t.browsers,
                "verdict": "PASS" if ok else "FAIL",
            }
        )
    return out
