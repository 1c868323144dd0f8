"""A setting's accuracy and cost on its scene's reference test.

The web page's « Précision et coût » shows, for the integrator and timestep in force and
for the scene's default, what ``sandbox bench`` measures on the scene's reference test
(:class:`~sandbox.physics.spec.Accuracy`: its parameter values and duration, from the
start): the key quantity's relative error against the course's closed form, the drift of
what the scene conserves, and the CPU cost of stepping. A setting the saved benchmark ran
is read from it (the numbers of ``bench/results.md``); any other is measured once per
process the same way (:func:`sandbox.bench.run_one`) and kept.

A live error, measured on whatever the session happens to be doing, is not the same
quantity: the robot axis' closed form is the torque step's, so its speed-servo default
read a 240 % "error", and a window sampled ten times a second integrates the powers too
coarsely for the energy theorem.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

from sandbox.bench import Run, SceneResult, run_one
from sandbox.errors import SandboxError
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.spec import Scene

KEPT = 64
"""Settings measured and kept per process (a class tries a few timesteps each)."""


@dataclass(frozen=True)
class Setting:
    """An integrator (contract name) and a timestep [s]."""

    integrator: str
    timestep: float

    def same(self, other: Setting) -> bool:
        return self.integrator == other.integrator and math.isclose(
            self.timestep, other.timestep, rel_tol=1e-6
        )


def in_force(sim: ReadOnlySimulation) -> Setting:
    """The setting ``sim`` runs: its integrator, and the timestep the user chose or else
    the scene's default for the parameters (a transient shrink is the default's own)."""
    scene = sim.scene
    if scene is None or sim.timestep_chosen:
        return Setting(sim.integrator, sim.timestep)
    return Setting(sim.integrator, scene.default_timestep(sim.values))


def default(sim: ReadOnlySimulation) -> Setting | None:
    """The scene's default setting for ``sim``'s parameters (None: not a scene)."""
    scene = sim.scene
    if scene is None:
        return None
    return Setting(scene.integrator, scene.default_timestep(sim.values))


def test_default(scene: Scene) -> Setting | None:
    """The scene's default at its reference test's parameter values (the benchmark's
    "default"): a default that follows the parameters (the compressor's timestep per
    revolution) is another timestep there than in a page at other values."""
    if scene.accuracy is None:
        return None
    return Setting(scene.integrator, scene.default_timestep(dict(scene.accuracy.values)))


def on_test(sim: ReadOnlySimulation, setting: Setting) -> Setting:
    """``setting`` as the reference test measures it: the same timestep, or where the
    scene's default is an angle per step (:attr:`~sandbox.physics.spec.Accuracy.same_angle`)
    the same angle per step at the test's speed (the page's default is then the test's
    default: the compressor's 500 µs at 3000 tr/min is 100 µs at 17,000)."""
    scene = sim.scene
    acc = scene.accuracy if scene is not None else None
    if scene is None or acc is None or not acc.same_angle:
        return setting
    page = scene.default_timestep(sim.values)
    test = scene.default_timestep(dict(acc.values))
    if not (page > 0 and test > 0):
        return setting
    return Setting(setting.integrator, float(f"{setting.timestep * test / page:.6g}"))


def saved(result: SceneResult | None, setting: Setting) -> Run | None:
    """The saved benchmark's run of ``setting``, if it ran it."""
    if result is None:
        return None
    for run in result.runs:
        if setting.same(Setting(run.integrator, run.timestep)):
            return run
    return None


_MEASURED: OrderedDict[tuple[str, str, float], Run] = OrderedDict()
_PENDING: dict[tuple[str, str, float], Future[Run]] = {}
_LOCK = threading.Lock()
_executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="sandbox-accuracy")


def _key(scene: Scene, setting: Setting) -> tuple[str, str, float]:
    return (scene.name, setting.integrator, float(f"{setting.timestep:.9g}"))


def measured(scene: Scene, setting: Setting) -> Run | None:
    """``setting``'s run on the reference test if this process measured it."""
    with _LOCK:
        return _MEASURED.get(_key(scene, setting))


def measure(scene: Scene, setting: Setting) -> Run:
    """``setting`` on ``scene``'s reference test, as ``sandbox bench`` measures it (once
    per process: kept). A timestep the test refuses gives a diverged run whose
    ``detail`` says why."""
    key = _key(scene, setting)
    with _LOCK:
        if key in _MEASURED:
            return _MEASURED[key]
    acc = scene.accuracy
    if acc is None:
        raise ValueError(f"scene {scene.name!r} has no reference test")
    try:
        run = run_one(scene, acc, setting.integrator, setting.timestep, acc.duration)
    except SandboxError as exc:  # a timestep over the scene's limit at the test's values
        run = Run(scene.name, setting.integrator, setting.timestep, acc.duration)
        run.diverged, run.detail = True, str(exc)
    with _LOCK:
        _MEASURED[key] = run
        while len(_MEASURED) > KEPT:
            _MEASURED.popitem(last=False)
    return run


def submit(scene: Scene, setting: Setting) -> Future[Run]:
    """:func:`measure` on this process' one measuring thread (off the sessions' loop;
    one measurement at a time, so a class trying timesteps costs at most that thread);
    a setting already on its way is not measured twice."""
    key = _key(scene, setting)
    with _LOCK:
        pending = _PENDING.get(key)
        if pending is not None:
            return pending

        def run() -> Run:
            try:
                return measure(scene, setting)
            finally:
                with _LOCK:
                    _PENDING.pop(key, None)

        future = _executor.submit(run)
        _PENDING[key] = future
        return future


def cheapest(result: SceneResult, tolerance: float) -> Run | None:
    """The cheapest run of the saved benchmark (least CPU per simulated second) whose key
    quantity is within ``tolerance`` (relative) of the course and that keeps the scene's
    drift and constraint limits; None when none does. The cheapest such run is on the
    Pareto front by construction (none is both cheaper and as accurate)."""
    fits = [r for r in result.runs if result.admissible(r) and r.error <= tolerance]
    fits = [r for r in fits if math.isfinite(r.cpu_per_sim_s)]
    return min(fits, key=lambda r: (r.cpu_per_sim_s, r.error), default=None)


def most_accurate(result: SceneResult) -> Run | None:
    """The admissible run with the smallest error (what a refusal points to)."""
    fits = [r for r in result.runs if result.admissible(r) and math.isfinite(r.error)]
    return min(fits, key=lambda r: (r.error, r.cpu_per_sim_s), default=None)
