"""The records of ``sandbox bench``: one (integrator, timestep) run of a scene, and every run
of one scene with what it measures and its limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from sandbox.bench.cost import SessionCost


@dataclass
class Run:
    """One (integrator, timestep) run of a scene.

    Attributes:
        scene: Scene name.
        integrator: Integrator name.
        timestep: Timestep [s].
        duration: Simulated time [s].
        error: Relative error of the key quantity against the course (inf if diverged).
        drift: Relative drift of the invariant (or energy-theorem residual).
        constraint: Largest constraint violation [m] (None where there is none).
        cpu_per_sim_s: CPU seconds of stepping per simulated second.
        realtime_factor: Simulated seconds per CPU second.
        diverged: True when MuJoCo reported a bad state (or NaN).
        detail: Divergence message.
        pareto: On the Pareto front (no other run is both cheaper and more accurate).
        default: The scene's default integrator and timestep.
        motion: "free" (simulated: the grid) or "imposed" (the scene's imposed motion,
            computed exactly by the closure equations and inverse dynamics).
        evaluation_s: CPU seconds of one evaluation of an imposed motion (its state and
            forces at an instant: a web frame needs one, whatever the timestep); NaN
            for a simulated run.
    """

    scene: str
    integrator: str
    timestep: float
    duration: float
    error: float = math.inf
    drift: float = math.inf
    constraint: float | None = None
    cpu_per_sim_s: float = math.nan
    realtime_factor: float = math.nan
    diverged: bool = False
    detail: str = ""
    pareto: bool = False
    default: bool = False
    motion: str = "free"
    evaluation_s: float = math.nan


@dataclass
class SceneResult:
    """Every run of one scene and what it measures."""

    scene: str
    key: str
    invariant: str
    default_integrator: str
    default_timestep: float
    runs: list[Run] = field(default_factory=list)
    drift_tol: float = math.inf
    constraint_tol: float = math.inf
    session: SessionCost | None = None
    imposed: Run | None = None
    """The scene's imposed motion (closure equations and inverse dynamics), where it has
    one, at the benchmark's values: its error against the course and its cost."""

    def admissible(self, run: Run) -> bool:
        """Within this scene's drift and constraint limits (and not diverged)."""
        if run.diverged or not math.isfinite(run.error) or run.drift > self.drift_tol:
            return False
        return run.constraint is None or run.constraint <= self.constraint_tol

    @property
    def default(self) -> Run | None:
        """The run at the scene's defaults."""
        return next((r for r in self.runs if r.default), None)
