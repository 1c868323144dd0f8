"""Running a parameter study: each run builds its own
:class:`~sandbox.physics.simulation.Simulation`, steps it for ``duration`` seconds,
samples the readout after ``settle`` seconds and reduces the samples to one number. Runs
are independent: they go to a pool of processes (``jobs``) or to a Dask cluster, and their
rows come back in the grid's order whatever the order they finish in, so a study gives the
same rows with one process or several. A run that diverges is kept as a row marked
``diverged``; the study goes on.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import BadOption, Diverged, shown
from sandbox.physics.simulation import Simulation
from sandbox.runner import check_run
from sandbox.sweep.reduction import reduce
from sandbox.sweep.study import RATE, Study, check

SMALL_STEPS = 300_000
"""Steps in all under which ``sandbox sweep`` runs a study in its own process by default:
starting worker processes costs about a second (50 runs of 2 s of the rotor: 1.3 s in one
process, 1.8 s in two)."""


def _first_hinge(sim: Simulation) -> int | None:
    """qpos address of the model's first hinge (the angle of the orders), None if none."""
    model = sim.model
    for j in range(model.njnt):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            return int(model.jnt_qposadr[j])
    return None


def run_one(study: Study, point: Mapping[str, float]) -> dict[str, Any]:
    """One run of ``study`` at ``point``: its row (see :data:`sandbox.sweep.COLUMNS_AFTER`)."""
    sim = Simulation(
        study.source,
        values={**dict(study.fixed), **point},
        integrator=study.integrator,
        timestep=study.timestep,
        motion=study.motion,
    )
    total, per = check_run(study.duration, RATE, sim.timestep)
    hinge = _first_hinge(sim) if study.measure.statistic.startswith("order") else None
    name = study.measure.readout
    values: list[float] = []
    angles: list[float] = []
    times: list[float] = []
    status = "ok"
    done = 0
    every = study.measure.statistic != "final"  # a final value needs the last sample only
    try:
        while True:
            settled = sim.data.time >= study.settle - 0.5 * sim.timestep
            if (every and settled) or done >= total:
                values.append(sim.readouts([name])[name])
                times.append(float(sim.data.time))
                if hinge is not None:
                    angles.append(float(sim.data.qpos[hinge]))
            if done >= total:
                break
            n = min(per, total - done)
            sim.step(n)
            done += n
    except Diverged:
        status = "diverged"
    measure = (
        reduce(
            study.measure.statistic,
            np.asarray(values),
            np.asarray(angles) if angles else None,
            np.asarray(times),
        )
        if status == "ok"
        else math.nan
    )
    course = math.nan
    statistic = study.measure.statistic
    if status == "ok" and (study.course or statistic in ("final", "mean", "order1", "order2")):
        # the course's value of the same quantity: the study's key, the readout's own, or
        # its order's ("pilon:order2" is the course's pilon_h2)
        ref = sim.reference()
        key = name if statistic in ("final", "mean") else f"{name}_h{statistic[-1]}"
        course = float(ref.get(study.course or key, math.nan))
    return {
        **point,
        "measure": measure,
        "closed_form": course,
        "gap": measure - course,
        "status": status,
    }


def run_study(
    study: Study,
    jobs: int = 1,
    progress: Callable[[int], None] | None = None,
    *,
    scheduler: str | None = None,
) -> list[dict[str, Any]]:
    """Every run of ``study`` (checked first), in the grid's order, on ``jobs``
    processes (1: in this one), or on the workers of the Dask scheduler at ``scheduler``;
    ``progress(done)`` after each run finishes."""
    check(study)
    points = study.points()
    rows: list[dict[str, Any] | None] = [None] * len(points)
    if scheduler is not None:
        return _on_cluster(study, points, scheduler, progress)
    if jobs <= 1 or len(points) == 1:
        for k, point in enumerate(points):
            rows[k] = run_one(study, point)
            if progress is not None:
                progress(k + 1)
    else:
        with ProcessPoolExecutor(
            max_workers=min(jobs, len(points)), mp_context=get_context("spawn")
        ) as pool:
            futures = {pool.submit(run_one, study, point): k for k, point in enumerate(points)}
            for done, future in enumerate(as_completed(futures), start=1):
                rows[futures[future]] = future.result()
                if progress is not None:
                    progress(done)
    return [r for r in rows if r is not None]


CLUSTER_TIMEOUT = 10.0
"""Seconds to reach a Dask scheduler before giving up."""


def _on_cluster(
    study: Study,
    points: list[dict[str, float]],
    address: str,
    progress: Callable[[int], None] | None,
) -> list[dict[str, Any]]:
    """The runs on a Dask distributed cluster (its workers need this package installed):
    the same function as a local run, so the same rows, in the grid's order."""
    try:
        # optional: Dask distributed comes with the cluster extra only
        from distributed import Client, as_completed
    except ImportError:
        raise BadOption(
            '--scheduler needs Dask distributed: pip install ".[cluster]" (or "sandbox[cluster]")'
        ) from None
    try:
        client = Client(address, timeout=CLUSTER_TIMEOUT)
    except (OSError, TimeoutError, ValueError) as exc:
        raise BadOption(
            f"cannot reach the Dask scheduler at {shown(address)} ({exc}); start one with "
            "'dask scheduler' and give its tcp://HOST:8786 address"
        ) from None
    try:
        futures = client.map(run_one, [study] * len(points), points, pure=False)
        index = {f.key: k for k, f in enumerate(futures)}
        rows: list[dict[str, Any] | None] = [None] * len(points)
        for done, future in enumerate(as_completed(futures), start=1):
            rows[index[future.key]] = future.result()
            if progress is not None:
                progress(done)
        return [r for r in rows if r is not None]
    finally:
        client.close()
