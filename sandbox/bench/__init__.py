"""What accuracy costs in time: work-precision grids, effects and overhead benchmarks.

``sandbox bench`` runs, for every scene with an :class:`~sandbox.physics.spec.Accuracy`,
each integrator at timesteps spanning two decades around the scene's default, and
measures the key quantity's error against the course, the invariant's drift, the
constraint violation, and the CPU cost of stepping (readouts excluded). Timings are
printed and written, never asserted.

Modules: :mod:`~sandbox.bench.results` (the records), :mod:`~sandbox.bench.cost` (CPU
cost of stepping and of a browser session), :mod:`~sandbox.bench.pareto` (the front),
:mod:`~sandbox.bench.grid` (the integrator × timestep grid), :mod:`~sandbox.bench.store`
(results.json), :mod:`~sandbox.bench.report` (the files and tables written),
:mod:`~sandbox.bench.plot` (the charts), :mod:`~sandbox.bench.effects` (effects and
overhead), and the classroom load benchmark, :mod:`sandbox.bench.classroom`.
"""

from __future__ import annotations

from sandbox.bench.cost import FRAME_RATE, GOAL, PANEL_RATE, SessionCost, session_cost
from sandbox.bench.effects import bench_effects, bench_overhead
from sandbox.bench.grid import bench_scene, run_one
from sandbox.bench.pareto import mark_pareto
from sandbox.bench.report import CSV_COLUMNS, markdown, session_markdown, write_results
from sandbox.bench.results import Run, SceneResult
from sandbox.bench.store import load_results, merge_results, to_json

__all__ = [
    "CSV_COLUMNS",
    "FRAME_RATE",
    "GOAL",
    "PANEL_RATE",
    "Run",
    "SceneResult",
    "SessionCost",
    "bench_effects",
    "bench_overhead",
    "bench_scene",
    "load_results",
    "mark_pareto",
    "markdown",
    "merge_results",
    "run_one",
    "session_cost",
    "session_markdown",
    "to_json",
    "write_results",
]
