"""What accuracy costs in time: work-precision grids, effects and overhead benchmarks.

``sandbox bench`` runs, for every scene with an :class:`~sandbox.scenes.base.Accuracy`,
each integrator at timesteps spanning two decades around the scene's default, and
measures the key quantity's error against the course, the invariant's drift, the
constraint violation, and the CPU cost of stepping (readouts excluded). Timings are
printed and written, never asserted.
"""

from __future__ import annotations

import json
import math
import platform
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from sandbox.data import data_dir
from sandbox.physics.model import INTEGRATORS
from sandbox.physics.simulation import Simulation, step_model
from sandbox.runner import simulate
from sandbox.scenes import SCENES
from sandbox.scenes.base import Accuracy, Scene

SCHEMA = 1
"""Version of results.json (documented in docs/reference.md)."""

FACTORS = (0.1, 0.3, 1.0, 3.0, 10.0)
"""Timesteps of the grid, as multiples of the scene's default (two decades)."""

QUICK_DURATION = 0.25
"""Fraction of each scene's run duration used by ``--quick``."""


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

    def admissible(self, run: Run) -> bool:
        """Within this scene's drift and constraint limits (and not diverged)."""
        if run.diverged or not math.isfinite(run.error) or run.drift > self.drift_tol:
            return False
        return run.constraint is None or run.constraint <= self.constraint_tol

    @property
    def default(self) -> Run | None:
        """The run at the scene's defaults."""
        return next((r for r in self.runs if r.default), None)


def _series(samples: dict[str, list[float]]) -> dict[str, np.ndarray]:
    return {k: np.asarray(v, dtype=float) for k, v in samples.items()}


def run_one(
    target: str,
    acc: Accuracy,
    integrator: str,
    timestep: float,
    duration: float,
    *,
    simulation: Callable[..., Simulation] = Simulation,
) -> Run:
    """Simulate ``duration`` seconds and measure error, drift, constraint and cost.

    The cost is timed separately (:func:`stepping_cost`): stepping only, no readouts.
    """
    run = Run(str(target), integrator, timestep, duration)
    sim = simulation(target, values=dict(acc.values), integrator=integrator, timestep=timestep)
    names = tuple(dict.fromkeys(("time", *acc.readouts)))
    columns, rows, error = simulate(sim, duration, acc.rate, progress=False, names=names)
    if error is not None:
        run.diverged, run.detail = True, str(error)
    if not run.diverged:
        cost = stepping_cost(simulation, target, acc, integrator, timestep, duration)
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


MIN_CPU = 0.03
"""CPU seconds of stepping in one cost measurement, at least."""

REPEATS = 3
"""Cost measurements per run; the fastest is kept."""


def stepping_cost(
    simulation: Callable[..., Simulation],
    target: str,
    acc: Accuracy,
    integrator: str,
    timestep: float,
    duration: float,
) -> float:
    """CPU seconds per simulated second of MuJoCo's stepping alone (``Simulation.step``
    over the whole run in one call, so that Python's per-call overhead does not hide the
    integrators' own cost).

    Each of :data:`REPEATS` measurements lasts at least :data:`MIN_CPU` CPU seconds (the
    run restarts when it reaches ``duration``); the smallest is kept, since other
    processes can only slow a measurement down.
    """
    sim = simulation(target, values=dict(acc.values), integrator=integrator, timestep=timestep)
    total = max(1, int(round(duration / timestep)))
    best = math.inf
    done = 0
    for _ in range(REPEATS):
        cpu, steps = 0.0, 0
        while cpu < MIN_CPU:
            if done >= total:
                sim.reset()
                done = 0
            n = total - done
            start = time.process_time()
            sim.step(n)
            cpu += time.process_time() - start
            done += n
            steps += n
        best = min(best, cpu / (steps * timestep))
    return best


# -- what one browser session costs ----------------------------------------------------------
FRAME_RATE = 60.0
"""Frames per second of a web session: poses and the arrows' snapshot (at most)."""
PANEL_RATE = 10.0
"""Readout rows per second of a web session (tables, plots, lesson checks)."""
ARROW_READOUTS = ("sup_R_x", "dyn_R_x")
"""Readouts brought up to date for the arrows at every frame (the web app's
``physics.picture.FORCES``): one forward pass and the torsors the arrows use."""
GOAL = 20.0
"""Real-time factor every session's default must reach on one core (tested)."""
TARGET = 60.0
"""Real-time factor a session's default should reach on one core for a class of 30 on two
cores to leave room for drawing (issue 20): printed, never asserted."""


@dataclass
class SessionCost:
    """CPU cost of one web session at a scene's defaults, per simulated second.

    Attributes:
        scene: Scene name.
        integrator: Default integrator.
        timestep: Default timestep at the default parameters [s].
        step_s: CPU seconds of stepping per simulated second.
        snapshot_s: CPU seconds of one arrows snapshot (forward pass, torsors, arrows).
        row_s: CPU seconds of one row of every readout.
    """

    scene: str
    integrator: str
    timestep: float
    step_s: float
    snapshot_s: float
    row_s: float

    @property
    def per_sim_s(self) -> float:
        """Stepping + :data:`FRAME_RATE` snapshots + :data:`PANEL_RATE` rows [CPU s / sim s]."""
        return self.step_s + FRAME_RATE * self.snapshot_s + PANEL_RATE * self.row_s

    @property
    def step_factor(self) -> float:
        """Real-time factor of stepping alone on one core."""
        return 1.0 / self.step_s if self.step_s > 0 else math.inf

    @property
    def realtime_factor(self) -> float:
        """Real-time factor of the whole session on one core (sessions one core carries)."""
        return 1.0 / self.per_sim_s

    @property
    def meets_goal(self) -> bool:
        """Stepping and the whole session both reach :data:`GOAL`."""
        return self.step_factor >= GOAL and self.realtime_factor >= GOAL


def _best_cpu(fn: Callable[[], object], count: int) -> float:
    """CPU seconds of one call of ``fn``: best of :data:`REPEATS` batches of ``count``."""
    best = math.inf
    for _ in range(REPEATS):
        start = time.process_time()
        for _ in range(count):
            fn()
        best = min(best, (time.process_time() - start) / count)
    return best


def session_cost(scene: Scene, *, warmup: float = 0.1) -> SessionCost:
    """Measure :class:`SessionCost` at the scene's default parameters, integrator and
    timestep, after ``warmup`` simulated seconds (start-up transients, cached revolutions).

    Stepping is timed like :func:`stepping_cost` (one call per batch of at least
    :data:`MIN_CPU`); a snapshot and a row are timed over a simulated second's worth
    (:data:`FRAME_RATE` and :data:`PANEL_RATE` calls); each is the best of
    :data:`REPEATS`.
    """
    sim = Simulation(scene.name)
    sim.advance(warmup)
    dt = sim.timestep
    best = math.inf
    for _ in range(REPEATS):
        cpu, steps = 0.0, 0
        while cpu < MIN_CPU:
            n = max(1, int(round(0.05 / dt)))
            start = time.process_time()
            sim.step(n)
            cpu += time.process_time() - start
            steps += n
        best = min(best, cpu / (steps * dt))

    def snapshot() -> None:
        snap = sim.snapshot(ARROW_READOUTS)
        for arrow in scene.arrows:
            arrow.fn(snap)

    sim.readouts()  # first row of a steady state (the compressor simulates a revolution)
    return SessionCost(
        scene.name,
        sim.integrator,
        dt,
        best,
        _best_cpu(snapshot, int(FRAME_RATE)),
        _best_cpu(sim.readouts, int(PANEL_RATE)),
    )


def _finite(x: float) -> float:
    return float(x) if math.isfinite(x) else math.inf


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
            run = run_one(scene.name, acc, integrator, dt, duration)
            run.default = integrator == scene.integrator and math.isclose(dt, default_dt)
            result.runs.append(run)
            if progress is not None:
                speed = "" if run.diverged else f"{run.realtime_factor:8.1f}x real time"
                status = "diverged" if run.diverged else f"error {run.error:.2e}"
                progress(
                    f"  {scene.name:<18} {integrator:<13} dt = {dt:<8.2g} {status:<16} {speed}"
                )
    mark_pareto(result.runs, acc)
    result.session = session_cost(scene)
    return result


# -- outputs -------------------------------------------------------------------------------
def machine() -> dict[str, object]:
    """Where the numbers were measured."""
    import os

    return {
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "platform": platform.platform(),
        "cpus": os.cpu_count(),
        "date": time.strftime("%Y-%m-%d"),
    }


def _json_number(x: float | None) -> float | str | None:
    if x is None:
        return None
    return x if math.isfinite(x) else ("inf" if x > 0 else "nan" if math.isnan(x) else "-inf")


def to_json(results: Sequence[SceneResult], *, quick: bool) -> dict[str, object]:
    """The results.json document (schema in docs/reference.md)."""
    scenes = {}
    for res in results:
        runs = []
        for r in res.runs:
            d = asdict(r)
            for k in ("error", "drift", "constraint", "cpu_per_sim_s", "realtime_factor"):
                d[k] = _json_number(d[k])
            runs.append(d)
        scenes[res.scene] = {
            "key": res.key,
            "invariant": res.invariant,
            "default": {"integrator": res.default_integrator, "timestep": res.default_timestep},
            "drift_tol": _json_number(res.drift_tol),
            "constraint_tol": _json_number(res.constraint_tol),
            "runs": runs,
        }
        if res.session is not None:
            c = res.session
            scenes[res.scene]["session"] = {
                "integrator": c.integrator,
                "timestep": c.timestep,
                "step_cpu_per_sim_s": c.step_s,
                "snapshot_cpu_s": c.snapshot_s,
                "row_cpu_s": c.row_s,
                "frame_rate": FRAME_RATE,
                "panel_rate": PANEL_RATE,
                "cpu_per_sim_s": c.per_sim_s,
                "step_realtime_factor": _json_number(c.step_factor),
                "realtime_factor": c.realtime_factor,
                "goal": GOAL,
                "meets_goal": c.meets_goal,
            }
    return {"schema": SCHEMA, "quick": quick, "machine": machine(), "scenes": scenes}


def _from_json_number(x: object) -> float:
    """Inverse of :func:`_json_number` for a number that is there.

    Raises:
        TypeError, ValueError: ``x`` is neither a number nor "inf", "-inf" or "nan".
    """
    if isinstance(x, bool) or not isinstance(x, (int, float, str)):
        raise TypeError(f"expected a number, got {x!r}")
    if isinstance(x, str) and x not in ("inf", "-inf", "nan"):
        raise ValueError(f"expected a number, got {x!r}")
    return float(x)


def _run_from_json(r: object) -> Run:
    """One run of a results.json document, each field checked against its type.

    Raises:
        KeyError: a required field is missing.
        TypeError, ValueError: ``r`` is not an object, or a field is unknown or of the
            wrong type.
    """
    if not isinstance(r, Mapping):
        raise TypeError(f"a run must be a JSON object, got {r!r}")
    unknown = set(r) - {f.name for f in fields(Run)}
    if unknown:
        raise TypeError(f"unknown run fields {sorted(unknown)!r}")

    def text(key: str, default: str | None = None) -> str:
        value = r[key] if default is None else r.get(key, default)
        if not isinstance(value, str):
            raise TypeError(f"run field {key!r} must be a string, got {value!r}")
        return value

    def flag(key: str) -> bool:
        value = r.get(key, False)
        if not isinstance(value, bool):
            raise TypeError(f"run field {key!r} must be true or false, got {value!r}")
        return value

    def number(key: str, default: float) -> float:
        return _from_json_number(r.get(key, default))

    constraint = r.get("constraint")
    return Run(
        scene=text("scene"),
        integrator=text("integrator"),
        timestep=_from_json_number(r["timestep"]),
        duration=_from_json_number(r["duration"]),
        error=number("error", math.inf),
        drift=number("drift", math.inf),
        constraint=None if constraint is None else _from_json_number(constraint),
        cpu_per_sim_s=number("cpu_per_sim_s", math.nan),
        realtime_factor=number("realtime_factor", math.nan),
        diverged=flag("diverged"),
        detail=text("detail", ""),
        pareto=flag("pareto"),
        default=flag("default"),
    )


def scene_from_json(
    scene: str, entry: Mapping[str, Any], acc: Accuracy | None = None
) -> SceneResult:
    """One scene of a results.json document (:func:`to_json`) back as a
    :class:`SceneResult`, its Pareto front marked again with ``acc``'s limits, with its
    session cost when the document has one.

    Raises:
        KeyError, TypeError, ValueError: the entry lacks a field or has one of the wrong
            type (an older or foreign document).
    """
    runs = [_run_from_json(r) for r in entry["runs"]]
    res = SceneResult(
        scene,
        entry["key"],
        entry["invariant"],
        entry["default"]["integrator"],
        entry["default"]["timestep"],
        runs,
        drift_tol=float(entry.get("drift_tol", math.inf)),
        constraint_tol=float(entry.get("constraint_tol", math.inf)),
        session=_session_from_json(scene, entry.get("session")),
    )
    mark_pareto(res.runs, acc)
    return res


def _session_from_json(scene: str, entry: object) -> SessionCost | None:
    """The ``session`` object of a results.json scene back as a :class:`SessionCost`
    (None when absent).

    Raises:
        KeyError, TypeError, ValueError: a field is missing or of the wrong type.
    """
    if entry is None:
        return None
    if not isinstance(entry, Mapping) or not isinstance(entry["integrator"], str):
        raise TypeError(f"a session must be a JSON object with an integrator, got {entry!r}")
    return SessionCost(
        scene,
        entry["integrator"],
        _from_json_number(entry["timestep"]),
        _from_json_number(entry["step_cpu_per_sim_s"]),
        _from_json_number(entry["snapshot_cpu_s"]),
        _from_json_number(entry["row_cpu_s"]),
    )


def merge_results(new: Sequence[SceneResult], path: Path) -> list[SceneResult]:
    """``new`` plus every other registered scene already benchmarked in ``path`` (a
    results.json), in the registry's order: refreshing a few scenes keeps the rest.

    A scene that cannot be read back (missing, foreign or older document) is left out.
    """
    fresh = {r.scene: r for r in new}
    merged = []
    for name in SCENES:
        if name in fresh:
            merged.append(fresh[name])
        else:
            kept = load_results(name, path)
            if kept is not None:
                merged.append(kept)
    merged += [r for r in new if r.scene not in SCENES]
    return merged


def load_results(scene: str, path: Path | None = None) -> SceneResult | None:
    """The benchmark of ``scene`` in ``path`` (default: the shipped bench/results.json),
    or None when the file, the scene or a field is missing."""
    path = data_dir("bench") / "results.json" if path is None else path
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        entry = doc["scenes"][scene]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    spec = SCENES.get(scene)
    try:
        return scene_from_json(scene, entry, spec.accuracy if spec else None)
    except (KeyError, TypeError, ValueError):
        return None


CSV_COLUMNS = (
    "scene",
    "integrator",
    "timestep",
    "duration",
    "error",
    "drift",
    "constraint",
    "cpu_per_sim_s",
    "realtime_factor",
    "diverged",
    "pareto",
    "default",
)


def write_results(results: Sequence[SceneResult], out: Path, *, quick: bool) -> list[Path]:
    """results.json, results.csv, results.md and one PNG per scene in ``out``."""
    import csv

    from sandbox.bench_plot import plot_scene

    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(
        json.dumps(to_json(results, quick=quick), indent=1), encoding="utf-8"
    )
    with (out / "results.csv").open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(CSV_COLUMNS)
        for res in results:
            for r in res.runs:
                row = asdict(r)
                writer.writerow(["" if row[c] is None else row[c] for c in CSV_COLUMNS])
    (out / "results.md").write_text(markdown(results), encoding="utf-8")
    paths = [out / "results.json", out / "results.csv", out / "results.md"]
    for res in results:
        paths.append(plot_scene(res, out / f"{res.scene}.png"))
    return paths


def _fmt(x: float | None, spec: str = ".2e") -> str:
    if x is None:
        return "—"
    return "∞" if math.isinf(x) else format(x, spec)


def session_markdown(results: Sequence[SceneResult]) -> str:
    """One row per scene: its default session's cost on one core, the 20× goal and the 60×
    target."""
    rows = [r for r in results if r.session is not None]
    if not rows:
        return ""
    lines = [
        f"### Sessions at the defaults — one core, goal ≥ {GOAL:g}× real time\n",
        f"A web session steps in real time, takes an arrows snapshot {FRAME_RATE:g} times "
        f"and a row of every readout {PANEL_RATE:g} times per simulated second. "
        "Default parameters (the grids below may use harder ones: the benchmark's "
        "default run is also given).\n",
        "| scene | default | stepping × real time | snapshot [ms] | row [ms] | "
        f"session × real time | ≥ {GOAL:g}× | ≥ {TARGET:g}× | benchmark case |",
        "|:--|:--|--:|--:|--:|--:|:--|:--|:--|",
    ]
    for res in rows:
        c = res.session
        assert c is not None
        d = res.default
        case = (
            f"{d.integrator} dt = {d.timestep:.3g} s: {_fmt(d.realtime_factor, '.1f')}×"
            if d is not None
            else "—"
        )
        lines.append(
            f"| {res.scene} | {c.integrator}, dt = {c.timestep:.3g} s | "
            f"{_fmt(c.step_factor, '.1f')} | {c.snapshot_s * 1e3:.3f} | {c.row_s * 1e3:.3f} | "
            f"{c.realtime_factor:.1f} | {'yes' if c.meets_goal else '**no**'} | "
            f"{'yes' if c.realtime_factor >= TARGET else 'no'} | {case} |"
        )
    return "\n".join(lines) + "\n\n"


def markdown(results: Sequence[SceneResult]) -> str:
    """The sessions' table (:func:`session_markdown`), then one table per scene: every
    run, the Pareto front and the default marked."""
    parts = [session_markdown(results)] if any(r.session for r in results) else []
    for res in results:
        parts.append(
            f"### {res.scene} — key: `{res.key}`, invariant: {res.invariant}\n\n"
            "| integrator | dt [s] | error | drift | constraint [m] | CPU s / sim s | "
            "× real time | |\n|:--|--:|--:|--:|--:|--:|--:|:--|"
        )
        for r in res.runs:
            tags = []
            if r.default:
                tags.append("**default**")
            if r.pareto:
                tags.append("Pareto")
            if r.diverged:
                tags.append("diverged")
            parts.append(
                f"| {r.integrator} | {r.timestep:.3g} | {_fmt(r.error)} | {_fmt(r.drift)} | "
                f"{_fmt(r.constraint)} | {_fmt(r.cpu_per_sim_s, '.3g')} | "
                f"{_fmt(r.realtime_factor, '.1f')} | {', '.join(tags)} |"
            )
        parts.append("")
    return "\n".join(parts)


# -- effects and overhead --------------------------------------------------------------------
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

    def all_on(target: str, **kwargs: object) -> Simulation:
        sim = Simulation(target, **kwargs)  # type: ignore[arg-type]
        everything_on(sim)
        return sim

    dt = scene.default_timestep(acc.values)
    declared = run_one(scene.name, acc, scene.integrator, dt, duration)
    on = run_one(scene.name, acc, scene.integrator, dt, duration, simulation=all_on)
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
        sim = Simulation(scene.name)
        m, d = sim.model, sim.data
        per = max(1, int(round(1.0 / (rate * m.opt.timestep))))
        frames = int(round(duration * rate))
        start = time.perf_counter()
        control = sim.scene.control if sim.scene is not None else None
        for _ in range(frames):
            step_model(m, d, per, control, sim.values)  # mj_step(m, d, per) without control
        return time.perf_counter() - start

    def ours() -> float:
        sim = Simulation(scene.name)
        start = time.perf_counter()
        simulate(sim, duration, rate, progress=False)
        return time.perf_counter() - start

    bare_s = min(bare() for _ in range(3))
    run_s = min(ours() for _ in range(3))
    return OverheadResult(scene.name, bare_s, run_s, duration)
