"""A parameter study, checked whole before its first run: what varies (one or two
parameters over a grid of values, the others fixed), the readout measured and what is
taken of it, for how long, on what scene; and the step budget it may take.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass

import numpy as np

from sandbox.errors import BadOption, shown
from sandbox.physics.limits import MAX_MODEL_BYTES
from sandbox.physics.model import Source
from sandbox.physics.simulation import Simulation
from sandbox.runner import MAX_STEPS, check_run
from sandbox.scenes import resolve
from sandbox.sweep.reduction import STATISTICS

MAX_RUNS = 1000
"""Most runs one study may ask for."""

RATE = 1000.0
"""Samples per simulated second taken after the settling time (at most one a step)."""

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
    motion: str | None = None
    """How a scene with an imposed input computes it ("imposed", "free"; None: its default)."""
    max_bytes: float = MAX_MODEL_BYTES
    """What an MJCF file may take to compile [bytes] (``--max-memory`` on the command line)."""
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

    @property
    def source(self) -> Source:
        """The scene or MJCF file ``target`` names (resolved against the course's registry),
        an MJCF file allowed :attr:`max_bytes` to compile."""
        return resolve(self.target, max_bytes=self.max_bytes)


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
                study.source,
                values={**fixed, vary.name: value},
                integrator=study.integrator,
                timestep=study.timestep,
                motion=study.motion,
            )
    sim = Simulation(
        study.source,
        values=fixed,
        integrator=study.integrator,
        timestep=study.timestep,
        motion=study.motion,
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


def bench_study(target: str, runs: int = 50, duration: float = 2.0) -> Study:
    """The study ``sandbox bench --sweep`` times: ``runs`` runs of ``duration`` s over the
    scene's first parameter, from its lowest to its highest value, measuring the maximum
    of its first readout."""
    sim = Simulation(resolve(target))
    scene = sim.scene
    if scene is None or not scene.params or not scene.readouts:
        raise BadOption(f"{shown(target)} has no parameter or readout of its own to study")
    p = scene.params[0]
    return Study(
        target,
        (Vary(p.name, float(p.min), float(p.max), runs),),
        Measure(scene.readouts[0].name, "max"),
        duration,
    )
