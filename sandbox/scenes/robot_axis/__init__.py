"""Axis y of a cartesian transfer robot (course sections 6.3 and 6.4): equivalent inertia,
kinetic-energy theorem with a flexible arm, reducer efficiency.

A motor (J_m) and its reducer (J_r, ratio k) turn two toothed pulleys (J_p, radius R_p); a
belt drives the carriage ch (M1) along y; the arm z (M2) hangs from the carriage on a spring
K_t and a damper μ_t; f_v is the viscous friction referred to the motor shaft.

Model: the rigid chain is ONE slide joint (y_ch): V_ch = R_p k ω_m ties the motor, the reducer
and the pulleys to it, so their inertia is an armature on that slide and the friction a
joint damping, and no constraint is needed. The arm is a second slide on the carriage
(y = y_2 − y_ch) with stiffness K_t and damping μ_t; ``flexible`` = 0 removes it (M2 rides on
the carriage). The motor applies C_m, by ``profile``: 0 a torque step, 1 a speed servo with a
filtered set point, 2 (default) the transfer robot's back-and-forth point-to-point moves (the
servo follows a trapezoidal speed profile, with a slow position loop), 3 a sinusoidal torque
(the arm's resonance). Commands 2 and 3 vary in time: the scene's per-step ``control`` sets
them from the time and the state. The carriage's slide has end stops (a joint limit at the
rail's ends, -0.05 and 2.05 m): the back-and-forth move never reaches them; a constant torque
or speed runs the carriage onto one, which then holds it (readout F_stop; the course has no
stop, so the theorem's residual and C_m_gap show the stop's share). The reducer's efficiency ρ (parameter ``eta``) is simulated in driving mode, the
motor always feeding the load: C_m − (J_m + J_r) ω̇_m − f_v ω_m = C_s / ρ, i.e. the chain is
pushed by ρ C_m with ρ (J_m + J_r) and ρ f_v upstream (see
:func:`sandbox.mechanics.robot_axis.chain_mass`). When the load drives the motor back
(braking, a lowered set point) the course's ρ no longer applies this way: C_m_ref, which
switches to the braking formula, then shows the gap. The generic T, P_ext, P_int and
P_acc are the mechanism's, not the simulated chain's (the scene's ``mechanism`` hook adds the
(1 − ρ) share of J_m + J_r, C_m ω_m and the reducer's loss): the kinetic-energy theorem reads
the course's machine for any ρ. Every reading is of one instant: C_m is the torque the
motor applies from it on (what MuJoCo applies in the step starting there), so that C_m ω_m
is the row's P_motor and P_ext; a speed servo's torque held over a step depends on the
timestep (the default move's peak: 4.98 N·m at 1 ms, 4.80 at 0.1 ms).

Modules: :mod:`.params` (the parameter table), :mod:`.course` (the course's axis, the
command's gains, the timestep), :mod:`.model` (model edits and commands),
:mod:`.readouts` (readouts, arrows and the mechanism's powers).
"""

from __future__ import annotations

import numpy as np

from sandbox.mechanics.robot_axis import step_response
from sandbox.physics.page import Names, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.spec import Accuracy, Effects, Scene, Series, Values
from sandbox.scenes.robot_axis.course import (
    axis_of,
    default_timestep,
    effects,
    flexible,
    position_gain,
    profile,
    reference,
    servo_gain,
)
from sandbox.scenes.robot_axis.model import (
    IMPOSED,
    MEMORY,
    control,
    drive,
    edit,
    initial_state,
    move_reference,
)
from sandbox.scenes.robot_axis.params import (
    BACK_AND_FORTH,
    DEFAULTS,
    LARGEST_TIMESTEP,
    PARAMS,
    POSITION_TIME,
    RAIL,
    RPM,
    SERVO_TIME,
    SINE,
    SPEED,
    STEP_ANGLE,
    TORQUE,
)
from sandbox.scenes.robot_axis.readouts import ARROW_SCALE, ARROWS, READOUTS, mechanism

BENCH_VALUES = {"profile": 0.0, "torque_Nm": 2.0}
"""The bench runs the torque step, whose motion has a closed form (:func:`step_response`)."""


def _v2_error(series: Series, v: Values) -> float:
    """max |V_2 − closed form| / max |closed form| over the run (torque step from rest)."""
    v = {**DEFAULTS, **v}
    ref = step_response(axis_of(v), np.asarray(series["time"]), v["torque_Nm"],
                        flexible=flexible(v), rho=v["eta"])["V_2"]  # fmt: skip
    return float(np.max(np.abs(np.asarray(series["V_2"]) - ref)) / np.max(np.abs(ref)))


def _theorem_drift(series: Series, v: Values) -> float:
    """Integrated theorem: |E_c(t) − E_c(0) − ∫ (P_motor + P_int_course − P_loss) dt| over
    max E_c, the powers integrated by trapezoids between samples."""
    t = np.asarray(series["time"])
    e = np.asarray(series["E_c"])
    p = np.asarray(series["P_motor"]) - np.asarray(series["P_loss"]) - np.asarray(series["P_diss"])
    work = np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))])
    return float(np.max(np.abs(e - e[0] - work)) / max(float(np.max(np.abs(e))), 1e-300))


SCENE = Scene(
    name="robot_axis",
    title="Axe de robot : inertie équivalente et rendement",
    summary=(
        "The y axis of a transfer robot: a motor and reducer drive a carriage by a belt "
        "back and forth along its rail, and a flexible arm rings on it after each stop. The "
        "motor sees the chain as one equivalent inertia J_eq; the arm's mass M2 stays "
        "outside it unless the arm is rigid."
    ),
    mjcf="robot_axis.xml",
    params=PARAMS,
    # limits: the end stops of the rail, met only by the constant commands (a torque or a
    # speed set point runs the carriage to an end; the stop's force shows in F_stop, and as
    # the gap of the energy theorem and of C_m_ref, which the course does not model).
    effects=Effects(joint_damping=True, springs=True, actuation=True, limits=True),
    effects_for=effects,
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    control=control,
    initial_state=initial_state,
    reference=reference,
    mechanism=mechanism,
    imposed=IMPOSED,
    # RK4: the arm's oscillation (58.5 rad/s against the free chain) keeps its amplitude
    # with dt = 1 ms (0.06 rad per step); the step shrinks with the fastest eigenvalue
    # when K_t grows or M2 shrinks (default_timestep).
    integrator="rk4",
    timestep=1e-3,
    timestep_for=default_timestep,
    # Beyond 10 ms RK4 loses the arm's oscillation (0.6 rad per step: 1e-3 on V_2 at 10 ms)
    # and nears its stability limit on the speed servo (time constant 10 ms).
    max_timestep=1e-2,
    sections="6.3, 6.4",
    zero={"N·m": 1e-10, "W": 1e-9, "J": 1e-12, "N": 1e-7, "m": 5e-10},
    accuracy=Accuracy(
        key="V_2",
        readouts=("V_2", "E_c", "P_motor", "P_loss", "P_diss"),
        duration=1.0,
        error=_v2_error,
        invariant="kinetic-energy theorem, integrated (|ΔE_c − ∫ΣP dt| / max E_c)",
        drift=_theorem_drift,
        values=BENCH_VALUES,
        rate=2000.0,
        timesteps=(1e-4, 3e-4, 1e-3, 3e-3, 1e-2),
        drift_tol=1e-3,
    ),
    page=Page(
        plots=("y_ch", "omega_m", "deflection", "C_m"),
        study_presets=(
            StudyPreset(
                "Inertie équivalente selon le rapport de réduction k",
                ("k", 0.05, 1.0, 20),
                "J_eq",
                duration=0.01,
                hint="Ramenée à l'arbre moteur, l'inertie de la charge compte avec le carré "
                "du rapport de réduction : Jₑq = Jₘ + … + k²·(…).",
            ),
        ),
        xy_presets=(
            XYPreset(
                "Couple moteur au cours du mouvement",
                "time",
                ("C_m",),
                hint="Le couple que le moteur fournit ; en tirets, celui que donne le cours "
                "(inertie équivalente, frottement et rendement).",
            ),
            XYPreset(
                "Vitesse du chariot selon sa position",
                "y_ch",
                ("V_ch",),
                hint="Le profil de vitesse du chariot le long de sa course : accélération, "
                "palier, freinage.",
            ),
        ),
        arrows=ARROWS,
        body_frame="carriage",
        camera=((1.0, -0.2, 0.35), (0.0, 0.0, 1.0)),
        names=Names(solids={"carriage": "ch (chariot)", "arm": "2 (bras z)"}),
        # Round-off: at constant speed the carriage forces keep ~1e-9 N of the arm's last ringing
        # (peaks of 100 N during a start), the powers and the theorem's residual ~1e-13 W; the
        # arm's deflection decays to picometres in a pause: under half a nanometre it reads 0.
        overlay={
            "omega_m": "ωₘ",
            "C_m": "Couple moteur Cₘ",
            "deflection": "Déformation du bras",
            "energy_residual": "Écart au théorème",
        },
    ),
)

__all__ = [
    "ARROWS",
    "ARROW_SCALE",
    "BACK_AND_FORTH",
    "BENCH_VALUES",
    "DEFAULTS",
    "LARGEST_TIMESTEP",
    "MEMORY",
    "PARAMS",
    "POSITION_TIME",
    "RAIL",
    "READOUTS",
    "RPM",
    "SCENE",
    "SERVO_TIME",
    "SINE",
    "SPEED",
    "STEP_ANGLE",
    "TORQUE",
    "axis_of",
    "control",
    "default_timestep",
    "drive",
    "edit",
    "effects",
    "flexible",
    "initial_state",
    "mechanism",
    "move_reference",
    "position_gain",
    "profile",
    "reference",
    "servo_gain",
]
