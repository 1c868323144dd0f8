"""The inertia scene's spec (course 5.2–5.7, A.3), with its accuracy test (the period of the
intermediate-axis flip, T and |σ_G| kept) and its timestep.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.physics.page import Names, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.spec import (
    Accuracy,
    Effects,
    Scene,
    Series,
    Values,
    per_revolution_timestep,
)
from sandbox.scenes.inertia.course import flip_period, intermediate_place, reference
from sandbox.scenes.inertia.model import drive, edit, initial_state
from sandbox.scenes.inertia.params import PARAMS, RPM
from sandbox.scenes.inertia.readouts import ARROWS, AXIS_READOUTS, READOUTS
from sandbox.scenes.measures import relative_drift


def flip_times(time: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Times [s] the angle rises through 90° (linear interpolation between samples)."""
    t, a = np.asarray(time, dtype=float), np.asarray(angle, dtype=float) - 90.0
    up = np.nonzero((a[:-1] < 0.0) & (a[1:] >= 0.0))[0]
    return t[up] - a[up] * (t[up + 1] - t[up]) / (a[up + 1] - a[up])


def period_error(series: Series, values: Values) -> float:
    """|measured flip period − Euler's closed form| / closed form (inf without two flips)."""
    times = flip_times(series["time"], series["spin_angle"])
    if len(times) < 2:
        return math.inf
    measured = float(np.mean(np.diff(times)))
    return abs(measured - flip_period(values)) / flip_period(values)


def invariants_drift(series: Series, values: Values) -> float:
    """Largest relative drift of T and |σ_G| over the run."""
    return max(relative_drift("T")(series, values), relative_drift("sigma_G")(series, values))


STEP_ANGLE = 0.13
"""Rotation per step [rad] the default timestep allows (12.6 rad/s × 10 ms at 120 rpm):
faster launches shrink the step to keep this angle, so the accuracy per revolution stays
the one ``sandbox bench`` measured at 120 rpm."""
TIMESTEP = 1e-2


def timestep_for(values: Values, data: mujoco.MjData | None = None) -> float:
    """Default timestep [s]: at most ``STEP_ANGLE`` of rotation per step."""
    return per_revolution_timestep(STEP_ANGLE, values["spin_rpm"] * RPM, largest=TIMESTEP)


SCENE = Scene(
    name="inertia",
    title="Matrice d'inertie d'un solide : point, base, axes principaux",
    summary=(
        "A solid from the course (block, cylinder, sphere, rod, crankshaft) with its inertia "
        "matrix at a chosen point and basis, against the formulary. Launched about a "
        "principal axis it spins freely: steadily about the smallest and largest moments, "
        "with a flip about the intermediate one."
    ),
    mjcf="inertia.xml",
    params=PARAMS,
    effects=Effects(gravity=False, contacts=False, actuation=False),
    readouts=READOUTS + AXIS_READOUTS,
    edit=edit,
    drive=drive,
    initial_state=initial_state,
    reference=reference,
    # sandbox bench (120 rpm, 8 s, two flips): every integrator gets the flip period within
    # 1e-3, but only RK4 keeps T and |σ_G| (drift 2e-7 at 10 ms; Euler and the implicit ones
    # lose 1 to 40 %). RK4 at 10 ms is on the Pareto front, 2100 × real time.
    integrator="rk4",
    timestep=TIMESTEP,
    timestep_for=timestep_for,
    sections="5.2–5.7, A.3",
    # Round-off: torque-free, {D} and the powers are 0 in the course; RK4 leaves 1e-17 N·m
    # and 1e-16 W, and G at rest keeps m·V(G) at 1e-17 kg·m/s.
    zero={
        "kg·m²": 1e-15,
        "kg·m²/s": 1e-15,
        "kg·m/s": 1e-14,
        "N": 1e-12,
        "N·m": 1e-12,
        "W": 1e-12,
        "": 1e-12,  # a component of a principal axis that symmetry makes 0
    },
    accuracy=Accuracy(
        key="spin_angle",
        readouts=("spin_angle", "T", "sigma_G"),
        duration=8.0,
        error=period_error,
        invariant="T and |σ_G| (torque-free motion)",
        drift=invariants_drift,
        rate=1000.0,
        timesteps=(5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2, 5e-2),
        drift_tol=1e-4,
    ),
    page=Page(
        # G stays at the origin; the drawn basis and arrows reach ~0.4 m from it
        look_at=((0.0, 0.0, 0.0), 0.8),
        overlay={"spin_angle": "Angle entre ω et l'axe", "omega": "ω", "sigma_G": "σ en G"},
        plots=("spin_angle", "omega"),
        study_presets=(
            StudyPreset(
                "Période du basculement selon la place de l'inertie intermédiaire",
                ("b", 0.12, 0.28, 9),
                "spin_angle",
                statistic="period",
                duration=20.0,
                course="flip_period",
                hint="Lancé autour de son axe intermédiaire, le pavé bascule périodiquement ; "
                "la période (Euler) est la plus courte quand I₂ est à mi-chemin de I₁ et I₃.",
                x=("Place de I₂ entre I₁ et I₃ : (I₂ − I₁)/(I₃ − I₁)", intermediate_place),
            ),
        ),
        xy_presets=(
            XYPreset(
                "Angle de l'axe de rotation au cours du temps",
                "time",
                ("spin_angle",),
                hint="Lancé autour de l'axe d'inertie intermédiaire, le solide bascule "
                "périodiquement ; autour des deux autres, l'angle reste petit.",
            ),
            XYPreset(
                "Composantes de l'axe principal choisi",
                "time",
                ("axis_x", "axis_y", "axis_z"),
                hint="Les composantes dans R₀ de l'axe principal autour duquel le solide est "
                "lancé.",
            ),
        ),
        arrows=ARROWS,
        body_frame="solid",
        names=Names(solids={"solid": "S"}),
    ),
)
