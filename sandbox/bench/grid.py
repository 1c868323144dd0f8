"""Work-precision grids: each integrator at timesteps spanning two decades around a
scene's default, each run measured for the key quantity's error against the course, the
invariant's drift, the constraint violation, and the CPU cost of stepping (readouts
excluded).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import numpy as np

from sandbox.bench.cost import evaluation_cost, session_cost, stepping_cost
from sandbox.bench.pareto import mark_pareto
from sandbox.bench.results import Run, SceneResult
from sandbox.physics.model import INTEGRATORS
from sandbox.physics.simulation import Simulation
from sandbox.physics.spec import Accuracy, Scene
from sandbox.runner import simulate

FACTORS = (0.1, 0.3, 1.0, 3.0, 10.0)
"""Timesteps of the grid, as multiples of the scene's default (two decades)."""

QUICK_DURATION = 0.25
"""Fraction of each scene's run duration used by ``--quick``."""


def _series(samples: dict[str, list[float]]) -> dict[str, np.ndarray]:
    return {k: np.asarray(v, dtype=float) for k, v in samples.items()}


def run_one(
    target: Scene | str | Path,
    acc: Accuracy,
    integrator: str,
    timestep: float,
    duration: float,
    *,
    simulation: Callable[..., Simulation] = Simulation,
    motion: str = "free",
) -> Run:
    """Simulate ``duration`` seconds and measure error, drift, constraint and cost.

    The cost is timed separately (:func:`stepping_cost`): stepping only, no readouts.
    ``motion``: "free" (the integrators' grid) or "imposed" (a scene's imposed motion,
    computed exactly: the integrator and timestep then only set the sampling).
    """
    run = Run(
        target.name if isinstance(target, Scene) else str(target),
        integrator,
        timestep,
        duration,
        motion=motion,
    )
    sim = simulation(
        target, values=dict(acc.values), integrator=integrator, timestep=timestep, motion=motion
    )
    names = tuple(dict.fromkeys(("time", *acc.readouts)))
    columns, rows, error = simulate(sim, duration, acc.rate, progress=False, names=names)
    if error is not None:
        run.diverged, run.detail = True, str(error)
    if not run.diverged and motion == "imposed":  # one evaluation a timestep: an upper bound
        run.evaluation_s = evaluation_cost(simulation, target, acc, timestep)
        run.cpu_per_sim_s = run.evaluation_s / timestep
        run.realtime_factor = 1.0 / run.cpu_per_sim_s
    elif not run.diverged:
        cost = stepping_cost(simulation, target, acc, integrator, timestep, duration, motion)
        run.cpu_per_sim_s = cost
        run.realtime_factor = 1.0 / cost if cost > 0 else math.inf
    if run.diverged:
        return run
    series = _series({n: [row[i] for row in rows] for i, n in enumerate(columns)})
    keep = series["time"] >= acc.settle
    if keep.sum() >= 2:
        series = {k: v[keep] for k, v in series.items()}
    values = sim.values
    run.error = _finite(acc.error(series, values))
    run.drift = _finite(acc.drift(series, values))
    if acc.constraint is not None:
        run.constraint = _finite(acc.constraint(series, values))
    return run


def _finite(x: float) -> float:
    return float(x) if math.isfinite(x) else math.inf


def bench_scene(
    scene: Scene,
    *,
    quick: bool = False,
    integrators: Iterable[str] = INTEGRATORS,
    factors: Sequence[float] = FACTORS,
    progress: Callable[[str], None] | None = None,
) -> SceneResult:
    """The integrator × timestep grid of one scene."""
    acc = scene.accuracy
    if acc is None:
        raise ValueError(f"scene {scene.name!r} declares no accuracy measure")
    duration = acc.duration * (QUICK_DURATION if quick else 1.0)
    default_dt = scene.default_timestep(acc.values)  # at the benchmark's speed
    result = SceneResult(
        scene.name,
        acc.key,
        acc.invariant,
        scene.integrator,
        default_dt,
        runs=[],
        drift_tol=acc.drift_tol,
        constraint_tol=acc.constraint_tol,
    )
    # A timestep the scene refuses (over its max_timestep: stable but no longer the
    # accuracy it promises) is left out of the grid rather than failing the benchmark.
    grid = acc.timesteps or tuple(default_dt * f for f in factors)
    # The timestep in force when the web page opens (the scene's default parameters, which
    # may be easier than the benchmark's): « Précision et coût » reads that setting here.
    opening_dt = scene.default_timestep()
    if not any(math.isclose(dt, opening_dt, rel_tol=1e-6) for dt in grid):
        grid = tuple(sorted((*grid, opening_dt)))
    timesteps = tuple(dt for dt in grid if dt <= scene.max_timestep * (1 + 1e-9))
    for integrator in integrators:
        for dt in timesteps:
            run = run_one(scene, acc, integrator, dt, duration)
            run.default = integrator == scene.integrator and math.isclose(dt, default_dt)
            result.runs.append(run)
            if progress is not None:
                speed = "" if run.diverged else f"{run.realtime_factor:8.1f}x real time"
                status = "diverged" if run.diverged else f"error {run.error:.2e}"
                progress(
                    f"  {scene.name:<18} {integrator:<13} dt = {dt:<8.2g} {status:<16} {speed}"
                )
    mark_pareto(result.runs, acc)
    if (
        scene.imposed is not None
        and scene.imposed.refusal({**scene.defaults(), **acc.values}) is None
    ):
        # the same case, computed exactly: its error against the course and its cost (the
        # timestep only samples it)
        result.imposed = run_one(scene, acc, scene.integrator, default_dt, duration,
                                 motion="imposed")  # fmt: skip
        if progress is not None:
            r = result.imposed
            progress(
                f"  {scene.name:<18} {'imposed':<13} (exact)       error {r.error:.2e}   "
                f"{r.realtime_factor:8.1f}x real time"
            )
    result.session = session_cost(scene)
    return result
