"""What a scene proposes to plot and to study: the presets of the page's "Tracé X–Y" and
"Étude paramétrique" folders, which show the course's laws in one click.

Scenes declare them (:attr:`~sandbox.physics.page.Page.xy_presets`,
:attr:`~sandbox.physics.page.Page.study_presets`); the web layer draws them without
knowing any scene. Names are readout and parameter names (contracts); labels are French.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

TIME = "time"
"""The X of a plot against simulated time."""


@dataclass(frozen=True)
class XYPreset:
    """One any-versus-any plot a scene proposes.

    Attributes:
        label: French name in the preset list (e.g. "Pilon et tamis sur un tour").
        x: Readout on the horizontal axis (:data:`TIME` for time). A turn counter (the
            crank angle ``theta``) is folded onto one revolution.
        ys: Readouts on the vertical axis (one to three, sharing a unit).
        refs: The course's value of a Y, as a readout name (Y -> readout), when it is not
            the readout ``<Y>_ref`` that the plot finds by itself.
        values: Parameter values set when the preset is chosen (e.g. a slow ramp of the
            speed so that ω sweeps its range); the simulation then starts again.
        hint: One French sentence saying what to look at.
    """

    label: str
    x: str
    ys: tuple[str, ...]
    refs: Mapping[str, str] = field(default_factory=dict)
    values: Mapping[str, float] = field(default_factory=dict)
    hint: str = ""


@dataclass(frozen=True)
class StudyPreset:
    """One parameter study a scene proposes (see :mod:`sandbox.sweep`).

    Attributes:
        label: French name in the preset list (e.g. "Palier A selon ω").
        vary: (parameter, start, stop, count) of the parameter on the horizontal axis.
        measure: Readout measured in each run.
        statistic: What is taken of its samples (:data:`sandbox.sweep.STATISTICS`).
        duration: Simulated seconds of each run.
        settle: Seconds before sampling starts.
        fixed: Other parameters' values for every run.
        family: Optional second parameter (name, start, stop, count): one curve each.
        hint: One French sentence naming the course's law the curve shows.
        x: What the chart puts on its horizontal axis instead of the varied parameter:
            (French words, function of a run's parameter values), e.g. ("Rapport R/L",
            R / L) when L varies.
        course: The closed form's key in the scene's reference when it is not the
            readout's own (e.g. ``flip_period`` for the period of ``spin_angle``).
    """

    label: str
    vary: tuple[str, float, float, int]
    measure: str
    statistic: str = "final"
    duration: float = 1.0
    settle: float = 0.0
    fixed: Mapping[str, float] = field(default_factory=dict)
    family: tuple[str, float, float, int] | None = None
    hint: str = ""
    x: tuple[str, Callable[[Mapping[str, float]], float]] | None = None
    course: str | None = None
