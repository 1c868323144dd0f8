"""Rolling cylinder on an inclined plane (course 3.2 remark 1, 6.1.3, 6.2).

A cylinder of radius R (solid, or hollow down to ``inner_radius``), possibly with an
eccentric point mass, rolls or slips down a plane inclined at α = ``slope_deg``, with
Coulomb friction μ. A is the geometric contact point (under the axis C): V(A∈S) is the
velocity of the cylinder's material point at A (0 when rolling), V(A/R0) the velocity of
the geometric point, which follows the axis. Gravity and the contact only.

Contact settings (scenes/rolling_cylinder.xml), measured on this scene at 1 ms:

- One explicit pair per rolling body with the plane, every geom's contype/conaffinity 0:
  the plane-cylinder contact is the only one (the racers never touch each other).
- condim 3: sliding friction only, no spin or rolling resistance, as in the course.
- Elliptic cone, impratio 1e4, solreffriction (-0, -0.01): while slipping, MuJoCo's
  convex contact model trades a tangential residual for a separating normal one (the
  relaxation of Coulomb's law), about μ·(b_t V(A∈S) + tangential acceleration). With the
  usual pyramidal cone (which ignores solreffriction) and damping b_t = 2/solref the
  cylinder hopped off the plane on 86 % of the steps at μ = 0.05, α = 20°: N jumped
  between 0 and 2 m g cos α and mu_required between 0 and μ. An almost undamped friction
  row (b_t = 0.01 /s) removes the V(A∈S) term and impratio 1e4 makes friction stiff, so
  the creep while rolling stays below 1e-4 m/s after 2 s (impratio 100: ~4e-3 m/s).
- solimp (0.5, 0.5): half the normal load is carried by the constraint's softness, which
  absorbs the rest of that coupling (with dmin 0.99 the hops came back); solref (2 ms, 1),
  the stiffest MuJoCo allows at 1 ms, still keeps the static penetration to 6 µm.
- MuJoCo's default (solref 20 ms, solimp 0.9-0.95) sinks the cylinder 0.13 mm: the contact
  point is then R − p/2 from the axis, and a changes by −k/(1+k)·p/R (k = I/(mR²)):
  −4.5e-4 for R = 0.1 m, −1.8e-3 for R = 0.02 m. Here −1.5e-5 and −7.8e-5.
- margin 0, gap 0: a positive margin makes the contact act at a distance, so the cylinder
  would ride on a cushion of that thickness and roll on a radius R + margin/2.
- noslip_iterations 0: not needed (creep above), and it cannot cure the hops since it
  leaves the normal forces of the main solve unchanged.
- The cylinder starts at its static penetration (:func:`_settle`): dropped from contact at
  0 µm it slipped while N built up, and kept ~3 mm/s of slip near μ_min.

Remaining limit: slipping very fast with much friction (α = 60°, μ = 0.5, a thin tube),
the coupling still makes the cylinder hop (14 % of the steps over 3 s, when V(A∈S) passes
~8 m/s); x(t) and v(t) stay right.

Leaving the plane: with an eccentric mass N = m [g cos α − e (a sin β/R + v² cos β/R²)]
can reach 0 (physically right: the cylinder jumps). The ``contact`` readout turns 0 and the
references written for a cylinder on the plane (a_ref, N_ref) turn NaN ("—"), as they do
while an eccentric cylinder slips (its a_ref is written for rolling).

Modules: :mod:`.params` (the parameter table), :mod:`.course` (the closed forms),
:mod:`.model` (model edits, racers, start, end of a run), :mod:`.readouts` (readouts
and arrows).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.physics.page import Names, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.spec import Accuracy, Effects, Scene, Values
from sandbox.scenes.measures import energy_drift
from sandbox.scenes.rolling_cylinder.course import (
    G,
    acceleration,
    axis_inertia,
    eccentric_acceleration,
    eccentric_normal_force,
    mass_properties,
    mu_min,
    reference,
)
from sandbox.scenes.rolling_cylinder.model import RACERS, edit, initial_state, past_the_plane
from sandbox.scenes.rolling_cylinder.params import PARAMS
from sandbox.scenes.rolling_cylinder.readouts import ARROW_SCALE, ARROWS, READOUTS, SLIP_TOL

HOMOGENEOUS_TIMESTEP = 2e-3
"""RK4 step of a cylinder without an eccentric mass [s]. Its acceleration is constant
while it rolls, and T + V holds to 5.5e-6 of T at 1, 2 or 3 ms; what grows with the step
is the contact's softness (MuJoCo stiffens a contact only down to solref = 2 h): a
against the course's g sin α / (1 + I/(m R²)) within 1.5e-5 at 1 ms, 7.7e-5 at 2 ms,
1.8e-4 at 3 ms at the defaults (3.8e-5 at 60°, 1.0e-4 for a tube), past the four
figures the page writes only at 3 ms. Half the steps of 1 ms: a class of thirty spends
0.17 of a core on this scene's physics instead of 0.35."""


def default_timestep(v: Values, data: mujoco.MjData | None = None) -> float:
    """RK4 timestep [s]: :data:`HOMOGENEOUS_TIMESTEP` without an eccentric mass, 1 ms with
    one (its T + V swings with the rotation: 2 ms drifts 4.6e-3 of T with a heavy mass
    balanced on a thin cylinder)."""
    return HOMOGENEOUS_TIMESTEP if v["eccentric_mass"] <= 0.0 else 1e-3


def _accel_error(series, values) -> float:
    """max |a − a_ref| / max |a_ref| over the run (NaN references, off the plane, skipped)."""
    ref = np.asarray(series["a_ref"], dtype=float)
    ok = np.isfinite(ref)
    if not ok.any():
        return math.nan
    gap = np.abs(np.asarray(series["a"], dtype=float)[ok] - ref[ok])
    return float(np.max(gap) / max(float(np.max(np.abs(ref[ok]))), 1e-300))


ACCURACY_VALUES = {"eccentric_mass": 0.5, "eccentric_radius": 0.07, "slope_deg": 10.0, "mu": 1.0}
"""The benchmark's cylinder: 0.5 kg at 70 mm from the axis, rolling down 10° (μ = 1) until
it leaves the plane at 1.86 s. A homogeneous cylinder keeps T + V to 1e-3 with any
integrator at 1 ms; this one separates them."""


SCENE = Scene(
    name="rolling_cylinder",
    title="Cylindre qui roule : V(A∈S) et V(A), frottement, énergie",
    summary=(
        "A cylinder rolls (or slips) down an inclined plane. The material point at the "
        "contact is at rest while the geometric contact point runs with the axis."
    ),
    mjcf="rolling_cylinder.xml",
    params=PARAMS,
    effects=Effects(gravity=True, contacts=True, actuation=False),
    readouts=READOUTS,
    edit=edit,
    initial_state=initial_state,
    reference=reference,
    # RK4 at 1 ms (sandbox bench, measured on the eccentric cylinder of ACCURACY_VALUES):
    # the contact solve sets velocities and forces, so every integrator gives the same
    # acceleration at 1 ms, but a first-order position update puts x half a step ahead of
    # v, and with an eccentric mass V swings fast with the rotation: T + V drifts by 1.1 %
    # of T with implicitfast at 1 ms (0.5 % needs 0.4 ms, 2.5 times the cost), 8e-5 with
    # RK4 at 1 ms, 3.5 times implicitfast's stepping cost (but half of a web session's CPU
    # is readouts: 111x -> 59x real time). RK4 keeps T + V within 1.1e-3 of T at every
    # corner of the sliders (tests/scenes/test_rolling_cylinder.py); implicitfast misses
    # 0.5 % at 8 of those 384 corners. 1 ms, because MuJoCo stiffens a contact only down to
    # solref = 2 h: at 3 ms the rolling error grows to 1.8e-4, and at 2 ms a heavy mass
    # balanced on top of a thin cylinder already drifts 4.6e-3. Without an eccentric mass
    # the step is 2 ms (default_timestep): see HOMOGENEOUS_TIMESTEP.
    integrator="rk4",
    timestep=HOMOGENEOUS_TIMESTEP,  # at the defaults (no eccentric mass)
    timestep_for=default_timestep,
    # Beyond 20 ms the contact softens (penetration 2.5 mm, acceleration -0.8 %; -22 % at
    # 0.1 s): nothing explodes, so such timesteps are refused rather than detected.
    max_timestep=0.02,
    sections="3.2, 6.1.3, 6.2",
    run_ended=past_the_plane,
    # Round-off: an absent eccentric mass is a 1e-9 kg point, which leaves 1e-9 N·m in
    # V(A) ∧ m V(G) where the course has 0 (δ in A is a few N·m).
    zero={"N": 1e-9, "N·m": 1e-8, "W": 1e-9, "J": 1e-12, "kg·m/s": 1e-12, "kg·m²/s": 1e-12},
    accuracy=Accuracy(
        key="a",
        readouts=("a", "a_ref", "T", "V"),
        duration=1.8,  # it leaves the plane at 1.86 s
        values=ACCURACY_VALUES,
        error=_accel_error,
        invariant="T + V (rolling, eccentric mass)",
        drift=energy_drift(),
        settle=0.01,
        drift_tol=5e-3,  # the course's energy theorem while rolling, to 0.5 %
    ),
    page=Page(
        overlay={"v": "v", "a": "a", "contact": "Contact"},
        plots=("v", "slip_velocity", "mu_required"),
        study_presets=(
            StudyPreset(
                "Accélération selon la pente, de part et d'autre du glissement",
                ("slope_deg", 2.0, 60.0, 30),
                "a",
                duration=0.3,
                hint="Tant que μ suffit, le cylindre roule : a = g·sin α / (1 + I/(m·R²)). "
                "Au-delà de tan α = 3μ (cylindre plein), il glisse : a = g·(sin α − μ·cos α).",
            ),
        ),
        xy_presets=(
            XYPreset(
                "Vitesse selon la distance parcourue",
                "x",
                ("v",),
                hint="Sous accélération constante, v² croît comme x : la courbe est une "
                "demi-parabole couchée.",
            ),
            XYPreset(
                "Accélération au cours du temps",
                "time",
                ("a",),
                hint="L'accélération du centre ; en tirets, celle du cours (roulement sans "
                "glissement ou glissement selon μ).",
            ),
        ),
        arrows=ARROWS,
        body_frame="cylinder",
        camera=((0.1, -1.0, 0.25), (0.0, 0.0, 1.0)),
        look_at=((0.5, 0.0, -0.15), 1.3),
        leaves_view=True,
        names=Names(solids={"cylinder": "cylindre", "eccentric": "masse excentrée"}),
    ),
)

__all__ = [
    "ACCURACY_VALUES",
    "ARROWS",
    "ARROW_SCALE",
    "G",
    "PARAMS",
    "RACERS",
    "READOUTS",
    "SCENE",
    "SLIP_TOL",
    "acceleration",
    "axis_inertia",
    "eccentric_acceleration",
    "eccentric_normal_force",
    "edit",
    "initial_state",
    "mass_properties",
    "mu_min",
    "past_the_plane",
    "reference",
]
