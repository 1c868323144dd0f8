"""The Pareto front of a work-precision grid: the runs no other run beats both on error and
on CPU cost, within a scene's drift and constraint limits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from sandbox.bench.results import Run
from sandbox.physics.spec import Accuracy

ERROR_FLOOR = 1e-12
"""Errors below this are round-off: all equal when comparing runs."""

COST_NOISE = 0.25
"""Relative CPU-time difference below which two runs cost the same: on a shared laptop
repeated measurements of one run spread by about that much."""


def dominates(a: Run, b: Run) -> bool:
    """``a`` is at least as accurate and clearly cheaper, or clearly more accurate and
    no dearer (errors under :data:`ERROR_FLOOR` and costs within :data:`COST_NOISE`
    count as equal)."""
    ea, eb = max(a.error, ERROR_FLOOR), max(b.error, ERROR_FLOOR)
    cheaper = a.cpu_per_sim_s < (1 - COST_NOISE) * b.cpu_per_sim_s
    not_dearer = a.cpu_per_sim_s <= (1 + COST_NOISE) * b.cpu_per_sim_s
    return (ea <= eb and cheaper) or (ea < eb and not_dearer and ea < 0.5 * eb)


def admissible(run: Run, acc: Accuracy | None = None) -> bool:
    """Not diverged, finite error, and within the scene's drift and constraint limits."""
    if run.diverged or not math.isfinite(run.error):
        return False
    if acc is None:
        return True
    if run.drift > acc.drift_tol:
        return False
    return run.constraint is None or run.constraint <= acc.constraint_tol


def mark_pareto(runs: Sequence[Run], acc: Accuracy | None = None) -> None:
    """Flag the admissible runs no other admissible run dominates (:func:`dominates`)."""
    ok = [r for r in runs if admissible(r, acc)]
    for r in runs:
        r.pareto = r in ok and not any(dominates(o, r) for o in ok if o is not r)
