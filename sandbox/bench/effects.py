"""Effects and overhead: a scene's declared effects against every effect MuJoCo has, and
``sandbox run`` against a bare ``mj_step`` loop.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco

from sandbox.bench.grid import QUICK_DURATION, run_one
from sandbox.bench.results import Run
from sandbox.physics.simulation import Simulation
from sandbox.physics.spec import Scene
from sandbox.physics.stepping import step_model
from sandbox.runner import simulate


def everything_on(sim: Simulation) -> None:
    """Switch on every effect MuJoCo has: gravity, contacts between all geoms, joint
    damping, friction and springs, limits, equality constraints."""
    sim.model.opt.disableflags = int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
    sim.model.geom_contype[:] = 1
    sim.model.geom_conaffinity[:] = 1
    sim.model.body_contype[:] = 1  # MuJoCo's broadphase filters on these per-body unions
    sim.model.body_conaffinity[:] = 1
    mujoco.mj_forward(sim.model, sim.data)


@dataclass
class EffectsResult:
    """Declared effects vs everything on, at the scene's defaults."""

    scene: str
    declared: Run
    all_on: Run

    @property
    def speed_ratio(self) -> float:
        """CPU cost with everything on / with the declared effects only."""
        return self.all_on.cpu_per_sim_s / self.declared.cpu_per_sim_s


def bench_effects(scene: Scene, *, quick: bool = False) -> EffectsResult:
    """Run the scene's accuracy case twice: declared effects, then everything on."""
    acc = scene.accuracy
    assert acc is not None
    duration = acc.duration * (QUICK_DURATION if quick else 1.0)

    def all_on(target: Scene, **kwargs: object) -> Simulation:
        sim = Simulation(target, **kwargs)  # type: ignore[arg-type]
        everything_on(sim)
        return sim

    dt = scene.default_timestep(acc.values)
    declared = run_one(scene, acc, scene.integrator, dt, duration)  # simulated, free
    on = run_one(scene, acc, scene.integrator, dt, duration, simulation=all_on)
    return EffectsResult(scene.name, declared, on)


@dataclass
class OverheadResult:
    """``sandbox run`` with readouts at 60 Hz against a bare ``mj_step`` loop."""

    scene: str
    bare_s: float
    run_s: float
    duration: float

    @property
    def ratio(self) -> float:
        """Wall time of the sandbox run / wall time of the bare loop (goal ≤ 1.25)."""
        return self.run_s / self.bare_s

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall second of the sandbox run (goal ≥ 20)."""
        return self.duration / self.run_s


def bench_overhead(scene: Scene, *, duration: float = 5.0, rate: float = 60.0) -> OverheadResult:
    """Time both loops on the same model at the scene's defaults (best of three)."""

    def bare() -> float:
        sim = Simulation(scene, motion="free")
        m, d = sim.model, sim.data
        per = max(1, int(round(1.0 / (rate * m.opt.timestep))))
        frames = int(round(duration * rate))
        start = time.perf_counter()
        control = sim.scene.control_at(sim.values) if sim.scene is not None else None
        for _ in range(frames):
            step_model(m, d, per, control, sim.values)  # mj_step(m, d, per) without control
        return time.perf_counter() - start

    def ours() -> float:
        sim = Simulation(scene, motion="free")
        start = time.perf_counter()
        simulate(sim, duration, rate, progress=False)
        return time.perf_counter() - start

    bare_s = min(bare() for _ in range(3))
    run_s = min(ours() for _ in range(3))
    return OverheadResult(scene.name, bare_s, run_s, duration)
