"""Parameter studies (``sandbox sweep``): one readout measured over a grid of parameter
values, beside the course's closed form.

A study is a list of runs, one per point of the grid (one or two parameters varied, the
others fixed). Each run builds its own :class:`~sandbox.physics.simulation.Simulation`,
steps it for ``duration`` seconds, samples the readout after ``settle`` seconds and
reduces the samples to one number (:data:`STATISTICS`). Runs are independent: they go to
a pool of processes (``jobs``), and their rows come back in the grid's order whatever
the order they finish in, so a study gives the same rows with one process or several.
A run that diverges is kept as a row marked ``diverged``; the study goes on.

Layer: tools (above :mod:`sandbox.runner`, below cli; see ``tests/test_layers.py``).
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path
from typing import IO, Any, TextIO

import numpy as np

from sandbox.errors import BadOption, Diverged, shown
from sandbox.physics.simulation import Simulation
from sandbox.runner import MAX_STEPS, check_run, csv_cell

MAX_RUNS = 1000
"""Most runs one study may ask for."""

STATISTICS = ("final", "mean", "max", "amplitude", "order1", "order2", "period", "onset")
"""What a run's samples are reduced to: the last one, their mean, their largest value,
half their range, the amplitude of the first or second order over the last revolution
of the scene's first hinge (least squares on cos kθ, sin kθ), or the mean time between
two rises through the middle of their range (an oscillation's period, e.g. the flips of
a solid launched about its intermediate axis), or the time of an event: the first instant
the readout leaves its value at the settling time by more than :data:`ONSET` of its
largest departure over the run and by more than :data:`ONSET_FLOOR` in its unit (a slip
velocity that starts growing, a contact flag that drops); NaN when it never does."""

ONSET = 0.01
"""Share of a readout's largest departure that marks an event (statistic ``onset``)."""

ONSET_FLOOR = 1e-3
"""Smallest departure that is an event, in the readout's unit (1 mm/s of slip, 1 mN):
a soft contact lets a rolling cylinder creep at 10⁻⁶ m/s, which is no slip."""

SMALL_STEPS = 300_000
"""Steps in all under which ``sandbox sweep`` runs a study in its own process by default:
starting worker processes costs about a second (50 runs of 2 s of the rotor: 1.3 s in one
process, 1.8 s in two)."""

RATE = 1000.0
"""Samples per simulated second taken after the settling time (at most one a step)."""

COLUMNS_AFTER = ("measure", "closed_form", "gap", "status")
"""Columns after the varied parameters' (a contract): the measure, the course's value
where the scene has one for this readout and statistic (its final or mean value: the
readout's own closed form; an order: the closed form named ``READOUT_hN``), measure minus
closed form, and ``ok`` or ``diverged``."""

_VARY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)=([^:]+):([^:]+):([^:]+)$")


@dataclass(frozen=True)
class Vary:
    """A varied parameter: ``count`` values evenly spaced from ``start`` to ``stop``."""

    name: str
    start: float
    stop: float
    count: int

    @property
    def values(self) -> list[float]:
        """The values, in order (``start`` alone for a count of 1)."""
        if self.count == 1:
            return [self.start]
        return [float(x) for x in np.linspace(self.start, self.stop, self.count)]


@dataclass(frozen=True)
class Measure:
    """The readout a study measures and what it takes of its samples."""

    readout: str
    statistic: str = "final"

    @property
    def label(self) -> str:
        """``readout:statistic``."""
        return f"{self.readout}:{self.statistic}"


def parse_vary(text: str) -> Vary:
    """``NAME=START:STOP:COUNT``.

    Raises:
        BadOption: naming the expected form.
    """
    found = _VARY.match(text.strip()) if isinstance(text, str) and len(text) <= 200 else None
    if found is None:
        raise BadOption(
            f"--vary expects NAME=START:STOP:COUNT, got {shown(text)}; "
            "e.g. --vary speed_rpm=0:6000:13"
        )
    name, start_text, stop_text, count_text = found.groups()
    try:
        start, stop = float(start_text), float(stop_text)
        count = int(count_text)
    except ValueError:
        raise BadOption(
            f"--vary {shown(text)}: START and STOP must be numbers and COUNT a whole number; "
            "e.g. --vary speed_rpm=0:6000:13"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)) or count < 1:
        raise BadOption(f"--vary {shown(text)}: give finite bounds and a COUNT of 1 or more")
    return Vary(name, start, stop, count)


def parse_measure(text: str) -> Measure:
    """``READOUT[:STATISTIC]``.

    Raises:
        BadOption: an unknown statistic (the valid ones named).
    """
    readout, _, statistic = str(text).strip().partition(":")
    statistic = statistic or "final"
    if statistic not in STATISTICS:
        raise BadOption(
            f"--measure {shown(text)}: unknown statistic {shown(statistic)}; "
            f"choose one of {', '.join(STATISTICS)}"
        )
    if not readout:
        raise BadOption("--measure needs a readout name; e.g. --measure bearing_A:final")
    return Measure(readout, statistic)


@dataclass(frozen=True)
class Study:
    """A checked study: what varies, what is measured, for how long, on what."""

    target: str
    varies: tuple[Vary, ...]
    measure: Measure
    duration: float
    settle: float = 0.0
    fixed: tuple[tuple[str, str], ...] = ()
    integrator: str | None = None
    timestep: float | None = None
    course: str | None = None
    """Key of the closed form in the scene's reference when it is not the readout's own
    (e.g. ``flip_period`` for the period of ``spin_angle``)."""

    def points(self) -> list[dict[str, float]]:
        """The grid, first parameter varying slowest."""
        names = [v.name for v in self.varies]
        return [
            dict(zip(names, combo, strict=True))
            for combo in itertools.product(*(v.values for v in self.varies))
        ]


def check(study: Study) -> int:
    """Refuse a study before any run: parameters, bounds, readout, budget. Returns the
    steps of one run.

    Raises:
        BadOption: a repeated ``--vary``, too many runs or steps, a settling time past
            the duration, an unknown readout.
        BadParameter: an unknown parameter or a value outside its bounds (the scene's
            own message).
    """
    names = [v.name for v in study.varies]
    if not names:
        raise BadOption("give at least one --vary NAME=START:STOP:COUNT")
    if len(set(names)) != len(names):
        raise BadOption(f"--vary {shown(names[-1])} is given twice; vary each parameter once")
    if len(names) > 2:
        raise BadOption("at most two --vary (a family of curves); fix the others with --set")
    runs = math.prod(v.count for v in study.varies)
    if runs > MAX_RUNS:
        raise BadOption(f"{runs} runs asked; at most {MAX_RUNS}: lower a COUNT")
    if not (0 <= study.settle < study.duration) and study.measure.statistic != "final":
        raise BadOption(
            f"--settle {study.settle:g} s must be shorter than --duration {study.duration:g} s"
        )
    fixed = dict(study.fixed)
    overlap = [n for n in names if n in fixed]
    if overlap:
        raise BadOption(f"{shown(overlap[0])} is both varied and --set; keep one")
    for vary in study.varies:  # both ends within the parameter's bounds (the scene says)
        for value in (vary.start, vary.stop):
            Simulation(
                study.target,
                values={**fixed, vary.name: value},
                integrator=study.integrator,
                timestep=study.timestep,
            )
    sim = Simulation(
        study.target, values=fixed, integrator=study.integrator, timestep=study.timestep
    )
    known = sim.readout_names()
    if study.measure.readout not in known:
        raise BadOption(
            f"unknown readout {shown(study.measure.readout)}; "
            f"see 'sandbox describe {study.target}' (e.g. {', '.join(known[:6])})"
        )
    total, _ = check_run(study.duration, RATE, sim.timestep)
    if total * runs > MAX_STEPS:
        raise BadOption(
            f"{runs} runs of {total:,} steps take {total * runs:.3g} steps (max {MAX_STEPS:,}); "
            "shorten --duration or lower a COUNT"
        )
    return total


def _first_hinge(sim: Simulation) -> int | None:
    """qpos address of the model's first hinge (the angle of the orders), None if none."""
    import mujoco

    model = sim.model
    for j in range(model.njnt):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            return int(model.jnt_qposadr[j])
    return None


def period(times: np.ndarray, values: np.ndarray) -> float:
    """Mean time between rises through the middle of the samples' range (linear
    interpolation between samples); NaN without two rises."""
    middle = 0.5 * (float(values.max()) + float(values.min()))
    a = values - middle
    up = np.nonzero((a[:-1] < 0.0) & (a[1:] >= 0.0))[0]
    if len(up) < 2:
        return math.nan
    at = times[up] - a[up] * (times[up + 1] - times[up]) / (a[up + 1] - a[up])
    return float(np.mean(np.diff(at)))


def onset(times: np.ndarray, values: np.ndarray) -> float:
    """The first time ``values`` leaves its first value by more than :data:`ONSET` of
    its largest departure and :data:`ONSET_FLOOR` (NaN when it never does)."""
    departure = np.abs(values - values[0])
    largest = float(departure.max()) if len(departure) else 0.0
    if not math.isfinite(largest) or largest <= ONSET_FLOOR:
        return math.nan
    return float(times[int(np.argmax(departure > max(ONSET * largest, ONSET_FLOOR)))])


def reduce(
    statistic: str,
    values: np.ndarray,
    angles: np.ndarray | None,
    times: np.ndarray | None = None,
) -> float:
    """One number from a run's samples (``angles``: the hinge's, for the orders;
    ``times``: their times, for the period)."""
    if len(values) == 0:
        return math.nan
    if statistic == "onset":
        return onset(times, values) if times is not None and len(times) == len(values) else math.nan
    if statistic == "period":
        return (
            period(times, values) if times is not None and len(times) == len(values) else math.nan
        )
    if statistic == "final":
        return float(values[-1])
    if statistic == "mean":
        return float(values.mean())
    if statistic == "max":
        return float(values.max())
    if statistic == "amplitude":
        return float(values.max() - values.min()) / 2.0
    order = int(statistic[-1])
    if angles is None or len(angles) < 8:
        return math.nan
    end = angles[-1]
    turn = np.abs(angles - end) <= 2 * math.pi * (1 + 1e-9)  # the last revolution
    if abs(angles[turn][0] - end) < 2 * math.pi * 0.9:  # less than a revolution sampled
        return math.nan
    from sandbox.scenes.compressor import fit_orders  # the course's orders, fitted once

    return float(fit_orders(angles[turn], values[turn], orders=max(order, 4))[order])


def run_one(study: Study, point: Mapping[str, float]) -> dict[str, Any]:
    """One run of ``study`` at ``point``: its row (see :data:`COLUMNS_AFTER`)."""
    import sandbox.scenes  # noqa: F401  (the registry, in a worker process)

    sim = Simulation(
        study.target,
        values={**dict(study.fixed), **point},
        integrator=study.integrator,
        timestep=study.timestep,
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


def bench_study(target: str, runs: int = 50, duration: float = 2.0) -> Study:
    """The study ``sandbox bench --sweep`` times: ``runs`` runs of ``duration`` s over the
    scene's first parameter, from its lowest to its highest value, measuring the maximum
    of its first readout."""
    from sandbox.scenes.base import as_scene

    sim = Simulation(target)
    scene = as_scene(sim.scene)
    if scene is None or not scene.params or not scene.readouts:
        raise BadOption(f"{shown(target)} has no parameter or readout of its own to study")
    p = scene.params[0]
    return Study(
        target,
        (Vary(p.name, float(p.min), float(p.max), runs),),
        Measure(scene.readouts[0].name, "max"),
        duration,
    )


def columns(study: Study) -> list[str]:
    """The output's columns: the varied parameters, then :data:`COLUMNS_AFTER`."""
    return [*(v.name for v in study.varies), *COLUMNS_AFTER]


def write(out: Path, study: Study, rows: Sequence[Mapping[str, Any]]) -> None:
    """The rows as CSV (dot decimals, empty cells for NaN) or JSON (NaN as null)."""
    names = columns(study)
    if out.suffix.lower() == ".json":

        def clean(v: Any) -> Any:
            return None if isinstance(v, float) and not math.isfinite(v) else v

        payload = {
            "target": study.target,
            "measure": study.measure.label,
            "duration": study.duration,
            "settle": study.settle,
            "columns": names,
            "rows": [[clean(r[n]) for n in names] for r in rows],
        }
        out.write_text(json.dumps(payload, indent=1), encoding="utf-8")
        return
    with out.open("w", newline="", encoding="utf-8") as f:
        write_csv(f, study, rows)


def write_csv(stream: TextIO, study: Study, rows: Sequence[Mapping[str, Any]]) -> None:
    """The rows as CSV on ``stream`` (dot decimals, empty cells for NaN): the columns of
    :func:`columns`, a contract shared by ``--out`` and the page's download."""
    names = columns(study)
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(names)
    for r in rows:
        writer.writerow([csv_cell(r[n]) for n in names])


def table(study: Study, rows: Sequence[Mapping[str, Any]]) -> Iterator[str]:
    """The rows as aligned text lines for a terminal."""
    names = columns(study)
    yield "  ".join(f"{n:>14}" for n in names)
    for r in rows:
        yield "  ".join(
            f"{r[n]:>14.6g}" if isinstance(r[n], float) else f"{r[n]!s:>14}" for n in names
        )


STAT_WORDS = {
    "final": "",
    "mean": "moyenne de ",
    "max": "maximum de ",
    "amplitude": "amplitude de ",
    "order1": "ordre 1 de ",
    "order2": "ordre 2 de ",
    "period": "période de ",
    "onset": "instant où change ",
}
"""The statistic in French, before the readout's words on a chart's axis."""


def _words(label: str, unit: str) -> str:
    from sandbox.physics.units import display_unit

    shown = display_unit(unit)
    return f"{label} [{shown}]" if shown else label


def plot(out: Path | IO[bytes], study: Study, rows: Sequence[Mapping[str, Any]]) -> None:
    """The study as a PNG for a slide, in French: the measure against the first varied
    parameter (one curve per value of the second), dots for the runs, the course's
    closed form dashed through them where the scene has one; decimal commas."""
    from sandbox.bench.plot import LOCK, comma_formatter, new_figure
    from sandbox.scenes.base import as_scene

    sim = Simulation(study.target, values=dict(study.fixed))
    scene = as_scene(sim.scene)
    params = {p.name: p for p in (scene.params if scene is not None else ())}
    infos = {i.name: i for i in sim.readout_infos()}
    first = study.varies[0].name
    p = params.get(first)
    x_words = _words(p.label or p.name, p.unit) if p is not None else first
    info = infos[study.measure.readout]
    y_words = STAT_WORDS[study.measure.statistic] + _words(info.label or info.name, info.unit)
    comma = comma_formatter()
    with LOCK:
        fig = new_figure(7.0, 4.5)
        ax = fig.add_subplot()
        groups: dict[float | None, list[Mapping[str, Any]]] = {}
        second = study.varies[1].name if len(study.varies) > 1 else None
        for r in rows:
            groups.setdefault(r[second] if second else None, []).append(r)
        q = params.get(second) if second else None
        from sandbox.physics.units import display_unit

        dashed = False
        for key, members in groups.items():
            xs = [r[first] for r in members]
            name = "simulation"
            if second and key is not None:
                words = (q.label or q.name) if q is not None else second
                unit = display_unit(q.unit) if q is not None else ""
                value = f"{key:g}".replace(".", ",").replace("-", "−")
                name = f"{words} = {value}{'' if unit == '°' else ' '}{unit}".rstrip()
            (line,) = ax.plot(xs, [r["measure"] for r in members], "o-", label=name)
            course = [r["closed_form"] for r in members]
            if any(math.isfinite(c) for c in course):
                label = None if dashed else "cours (tirets)"
                ax.plot(xs, course, "--", color=line.get_color(), label=label)
                dashed = True
        ax.set_xlabel(x_words)
        ax.set_ylabel(y_words)
        ax.xaxis.set_major_formatter(comma)
        ax.yaxis.set_major_formatter(comma)
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(out, dpi=150, format="png")
