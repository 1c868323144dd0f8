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
the course's machine for any ρ. C_m is the motor torque averaged over the step the
integrator took (the servo's torque at the start of a step is its largest), so it does not
depend on the timestep.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import mujoco
import numpy as np

from sandbox.mechanics.robot_axis import (
    RobotAxis,
    back_and_forth,
    equivalent_inertia,
    free_axis_frequency,
    motor_torque,
    state_matrices,
    step_response,
)
from sandbox.physics.snapshot import Snapshot
from sandbox.scenes.base import (
    Accuracy,
    Arrow,
    Effects,
    Param,
    Scene,
    SceneReadout,
    Series,
    Values,
    per_revolution_timestep,
)
from sandbox.scenes.presets import StudyPreset, XYPreset

RPM = 2 * math.pi / 60
SERVO_TIME = 0.01
"""Time constant [s] of the speed servo on the rigid chain: K_v = J_eq / SERVO_TIME."""
POSITION_TIME = 0.1
"""Time constant [s] of the position loop of the back-and-forth move (K_p = 1 / it), ten
times the speed servo's: it only removes the servo's lag from the carriage's position."""
RAIL = (-0.05, 2.05)
"""Travel of the carriage's centre between its two end stops [m] (a 2.2 m rail, the
carriage 0.24 m long): the slide's range in robot_axis.xml."""
TORQUE, SPEED, BACK_AND_FORTH, SINE = 0, 1, 2, 3
"""Values of the parameter ``profile``."""
STEP_ANGLE = 0.3
"""Largest |λ| dt of the model's eigenvalues [-]: RK4 keeps the arm's oscillation within
1e-5 per period (the arm turns 0.06 rad per step at the default 1 ms)."""
LARGEST_TIMESTEP = 1e-3


def _p(name: str, unit: str, default: float, lo: float, hi: float, doc: str, **kw: Any) -> Param:
    return Param(name, unit, default, lo, hi, doc, **kw)


DRIVE, ARM, CHAIN, INERTIAS = "Entraînement", "Bras flexible", "Transmission", "Inerties"
MOVE, SINE_GROUP = "Aller-retour", "Couple sinusoïdal"

PARAMS = (
    _p("profile", "", 2, 0, 3, "0: constant motor torque from rest; 1: speed set point reached through a first-order filter; 2: back-and-forth point-to-point moves (trapezoidal speed profile); 3: sinusoidal motor torque.", step=1, label="Commande du moteur", hint="Couple constant, consigne de vitesse filtrée, allers-retours d'un bout à l'autre de la course, ou couple sinusoïdal.", group=DRIVE, choices=("Couple constant", "Consigne de vitesse", "Aller-retour", "Couple sinusoïdal")),
    _p("torque_Nm", "N·m", 1.0, -20.0, 20.0, "Motor torque C_m of the constant-torque command.", live=True, step=0.05, label="Couple moteur Cₘ", hint="Couple que le moteur applique à son arbre quand la commande est un couple constant.", group=DRIVE),
    _p("speed_rpm", "rpm", 500.0, -3000.0, 3000.0, "Motor speed set point of the speed command; top motor speed of the back-and-forth move (its magnitude).", live=True, step=10.0, label="Consigne de vitesse du moteur ωₘ", hint="Vitesse de l'arbre moteur visée par l'asservissement, ou vitesse de croisière des allers-retours.", group=DRIVE),
    _p("ramp_s", "s", 0.1, 0.0, 2.0, "Time constant of the speed set point's first-order filter (0: a step).", step=0.01, label="Temps de montée de la consigne τ", hint="Constante de temps du filtre du premier ordre appliqué à la consigne de vitesse (0 : un échelon).", group=DRIVE),
    _p("stroke", "m", 1.5, 0.0, 2.0, "Distance of one move of the back-and-forth command, from the rail's start.", live=True, step=0.01, label="Course d'un déplacement L", hint="Distance que le chariot parcourt à chaque aller, puis à chaque retour, depuis le début du rail.", group=MOVE),
    _p("accel_s", "s", 0.05, 0.0, 2.0, "Time of the back-and-forth move to reach the top speed from rest (trapezoidal profile; 0: a speed step).", live=True, step=0.01, label="Durée d'accélération tₐ", hint="Durée de la rampe de vitesse au départ et à l'arrivée de chaque déplacement.", group=MOVE),
    _p("pause_s", "s", 1.0, 0.0, 10.0, "Standstill at each end of the back-and-forth move.", live=True, step=0.1, label="Pause à chaque extrémité", hint="Durée de l'arrêt du chariot à chaque bout de sa course, pendant laquelle le bras oscille librement.", group=MOVE),
    _p("sine_Nm", "N·m", 1.0, 0.0, 20.0, "Amplitude C_0 of the sinusoidal motor torque C_m = C_0 sin(2π f t).", live=True, step=0.05, label="Amplitude du couple sinusoïdal C₀", hint="Amplitude du couple moteur qui varie sinusoïdalement avec le temps.", group=SINE_GROUP),
    _p("sine_Hz", "Hz", 2.0, 0.1, 50.0, "Frequency f of the sinusoidal motor torque.", live=True, step=0.01, label="Fréquence du couple sinusoïdal f", hint="Nombre de périodes du couple sinusoïdal par seconde ; le bras résonne vers 9,3 Hz.", group=SINE_GROUP),
    _p("flexible", "", 1, 0, 1, "1: the arm is a mass on a spring and a damper; 0: the arm is rigid (M2 moves with the carriage).", step=1, label="Modèle du bras", hint="Bras souple (masse M₂ sur un ressort et un amortisseur) ou rigide (M₂ comptée dans l'inertie équivalente).", group=ARM, choices=("Bras rigide", "Bras flexible")),
    _p("M2", "kg", 46.0, 0.5, 500.0, "Equivalent mass of the flexible parts (arm z).", step=0.5, label="Masse des parties flexibles M₂", hint="Masse équivalente du bras z, qui oscille par rapport au chariot.", group=ARM),
    _p("K_t", "N/m", 124000.0, 1000.0, 1e7, "Equivalent stiffness of the arm.", step=1000.0, label="Raideur équivalente du bras Kₜ", hint="Raideur du ressort qui relie le bras au chariot.", group=ARM, advanced=True),
    _p("mu_t", "N·s/m", 64.0, 0.0, 5000.0, "Equivalent internal damping of the arm.", step=1.0, label="Amortissement interne du bras μₜ", hint="Coefficient de l'amortisseur qui relie le bras au chariot.", group=ARM, advanced=True),
    _p("eta", "", 1.0, 0.3, 1.0, "Efficiency of the reducer (1: no loss), simulated with the motor driving the load.", step=0.01, label="Rendement du réducteur ρ", hint="Rapport de la puissance sortant du réducteur à celle qui y entre, quand le moteur entraîne la charge.", group=CHAIN),
    _p("k", "", 0.2, 0.02, 1.0, "Reduction ratio k = ω_p / ω_m.", step=0.01, label="Rapport de réduction k", hint="Rapport de la vitesse des poulies à celle du moteur.", group=CHAIN, advanced=True),
    _p("R_p", "m", 0.020, 0.005, 0.1, "Pitch radius of a toothed pulley.", step=0.001, label="Rayon primitif des poulies Rₚ", hint="Rayon primitif d'une poulie crantée : la courroie avance de Rₚ par radian de poulie.", group=CHAIN, advanced=True),
    _p("M1", "kg", 136.0, 1.0, 1000.0, "Equivalent mass of the rigid parts (carriage ch).", step=1.0, label="Masse des parties rigides M₁", hint="Masse équivalente du chariot et des pièces qui le suivent rigidement.", group=CHAIN, advanced=True),
    _p("f_v", "N·m·s/rad", 0.0171, 0.0, 1.0, "Viscous friction referred to the motor shaft.", step=0.0001, label="Frottement visqueux ramené au moteur fᵥ", hint="Coefficient du couple de frottement visqueux ramené sur l'arbre moteur, proportionnel à ωₘ.", group=CHAIN, advanced=True),
    _p("J_m", "kg·m²", 4.2e-4, 1e-6, 1e-2, "Inertia of the motor shaft.", step=1e-6, label="Moment d'inertie de l'arbre moteur Jₘ", hint="Moment d'inertie du rotor du moteur autour de son axe.", group=INERTIAS, advanced=True, log=True),
    _p("J_r", "kg·m²", 1.2e-4, 0.0, 1e-2, "Inertia of the reducer referred to the motor shaft.", step=1e-6, label="Moment d'inertie du réducteur Jᵣ", hint="Moment d'inertie du réducteur ramené sur l'arbre moteur.", group=INERTIAS, advanced=True, log=True),
    _p("J_p", "kg·m²", 6e-5, 0.0, 1e-2, "Inertia of one pulley (there are two).", step=1e-6, label="Moment d'inertie d'une poulie Jₚ", hint="Moment d'inertie d'une des deux poulies crantées autour de son axe.", group=INERTIAS, advanced=True, log=True),
)  # fmt: skip


def axis_of(v: Values) -> RobotAxis:
    """The course's data record for the parameter values (J_r = J_p = 0 allowed here)."""
    tiny = 1e-300  # RobotAxis wants > 0; an inertia of 0 is a valid choice of the sliders
    return RobotAxis(
        J_m=v["J_m"], J_r=max(v["J_r"], tiny), J_p=max(v["J_p"], tiny), R_p=v["R_p"],
        k=v["k"], M1=v["M1"], M2=v["M2"], K_t=v["K_t"], mu_t=v["mu_t"], f_v=v["f_v"],
    )  # fmt: skip


def effects(v: Values) -> Effects:
    """Friction f_v and the end stops always; the arm's spring and damper only when it is
    flexible."""
    return Effects(joint_damping=True, springs=flexible(v), actuation=True, limits=True)


def flexible(v: Values) -> bool:
    """True for the flexible arm (parameter ``flexible`` = 1)."""
    return v["flexible"] >= 0.5


def profile(v: Values) -> int:
    """The command: TORQUE, SPEED, BACK_AND_FORTH or SINE."""
    return int(round(v["profile"]))


def servo_gain(v: Values) -> float:
    """K_v [N·m·s/rad] of the speed servo (0 for the torque commands)."""
    if profile(v) in (TORQUE, SINE):
        return 0.0
    return equivalent_inertia(axis_of(v), flexible=False) / SERVO_TIME


def position_gain(v: Values) -> float:
    """K_p [1/s] of the back-and-forth move's position loop (0 for the other commands)."""
    return 1.0 / POSITION_TIME if profile(v) == BACK_AND_FORTH else 0.0


def default_timestep(v: Values, data: mujoco.MjData | None = None) -> float:
    """RK4 step [s] turning the model's fastest eigenvalue by at most STEP_ANGLE (1 ms at
    the course's numbers: the arm against the free chain is 58.5 rad/s). It depends on
    the parameters only: computed once for each set of values (a session asks after every
    frame's steps, and an eigenvalue problem costs a tenth of a millisecond)."""
    return _default_timestep(tuple(sorted({**DEFAULTS, **v}.items())))


@functools.lru_cache(maxsize=64)
def _default_timestep(items: tuple[tuple[str, float], ...]) -> float:
    v = dict(items)
    a, _ = state_matrices(
        axis_of(v), flexible=flexible(v), rho=v["eta"], servo_gain=servo_gain(v),
        position_gain=position_gain(v),
    )  # fmt: skip
    fastest = float(np.max(np.abs(np.linalg.eigvals(a))))
    return per_revolution_timestep(STEP_ANGLE, fastest, largest=LARGEST_TIMESTEP)


# -- model --------------------------------------------------------------------------------------
def edit(spec: mujoco.MjSpec, v: Values) -> None:
    """Masses, armature, damping, the arm's spring, the motor's command and efficiency."""
    axis, rho = axis_of(v), v["eta"]
    r = axis.ratio
    chain = spec.joint("carriage")
    chain.armature = (rho * (v["J_m"] + v["J_r"]) + 2 * v["J_p"] * v["k"] ** 2) / r**2
    chain.damping[0] = rho * v["f_v"] / r**2
    spec.body("carriage").mass = v["M1"]
    spec.body("arm").mass = v["M2"]
    arm = spec.joint("arm")
    arm.stiffness[0] = v["K_t"]
    arm.damping[0] = v["mu_t"]
    if not flexible(v):
        spec.delete(arm)
    spec.nuserdata = max(spec.nuserdata, 2 * MEMORY)
    motor = spec.actuator("motor")
    motor.gear[0] = rho / r  # C_m [N·m] -> ρ C_m / (R_p k) [N] on the carriage
    kv = servo_gain(v)
    # Speed servo C_m = K_v (ω_c − ω_m) + f_v ω_c: the friction feedforward makes the
    # steady speed the set point itself (the actuator's velocity is ρ ω_m).
    motor.gainprm[0] = kv + v["f_v"] if kv > 0 else 1.0
    motor.biastype = mujoco.mjtBias.mjBIAS_AFFINE
    motor.biasprm[:3] = [0.0, 0.0, -kv / rho]
    if profile(v) == SPEED and v["ramp_s"] > 0:
        motor.dyntype = mujoco.mjtDyn.mjDYN_FILTEREXACT
        motor.dynprm[0] = v["ramp_s"]
    else:
        motor.dyntype = mujoco.mjtDyn.mjDYN_NONE


def drive(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """The constant torque C_m [N·m] or speed set point [rad/s] (the time-varying
    commands are :func:`control`'s)."""
    if profile(v) == TORQUE:
        data.ctrl[0] = v["torque_Nm"]
    elif profile(v) == SPEED:
        data.ctrl[0] = v["speed_rpm"] * RPM


def move_reference(v: Values, t: float) -> tuple[float, float]:
    """(position [m], speed [m/s]) of the carriage that the back-and-forth move asks for
    at time ``t`` [s] (:func:`sandbox.mechanics.robot_axis.back_and_forth`)."""
    r = v["R_p"] * v["k"]
    return back_and_forth(t, v["stroke"], v["speed_rpm"] * RPM * r, v["accel_s"], v["pause_s"])


def control(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """The time-varying commands, before every step (a pure function of the time and the
    state: a reset or a replay repeats them).

    Back-and-forth: the speed servo's set point is the trapezoid's speed plus a position
    loop, ω_c = V_ref / (R_p k) + K_p (y_ref − y_ch) / (R_p k), the correction kept within
    the top speed (a stroke changed mid-move brings the carriage back at that speed).
    Sinusoidal torque: C_m = C_0 sin(2π f t).
    """
    command, t = profile(v), float(data.time)
    if command == BACK_AND_FORTH:
        r = v["R_p"] * v["k"]
        y_ref, v_ref = move_reference(v, t)
        top = abs(v["speed_rpm"]) * RPM
        correction = (y_ref - float(data.qpos[0])) / (POSITION_TIME * r)
        data.ctrl[0] = v_ref / r + min(max(correction, -top), top)
    elif command == SINE:
        data.ctrl[0] = v["sine_Nm"] * math.sin(2.0 * math.pi * v["sine_Hz"] * t)
    _remember(model, data)


MEMORY = 7
"""Numbers kept per state in ``userdata`` (two states): time, y_ch, V_ch, y, v, the
command held over the step that starts there, and the set point filter's state."""


def _remember(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Keep the state a step starts from and its command in ``userdata``: slot 1 the
    current one, slot 0 the one before, so that a reading after a step knows the step
    that led to it (:func:`_last_step`). Called by :func:`control` before every step and
    after the last: a new time shifts slot 1 into slot 0; the same time (the call before
    the next step, a command changed by a slider) only refreshes slot 1. A deterministic
    function of the trajectory: a replay or a reset rebuilds the same numbers."""
    u = data.userdata
    if u.size < 2 * MEMORY:
        return
    t = float(data.time)
    if u[MEMORY] != t:
        u[:MEMORY] = u[MEMORY : 2 * MEMORY]
    y, dy = (float(data.qpos[1]), float(data.qvel[1])) if model.nv > 1 else (0.0, 0.0)
    act = float(data.act[0]) if model.na else 0.0
    u[MEMORY : 2 * MEMORY] = (
        t,
        float(data.qpos[0]),
        float(data.qvel[0]),
        y,
        dy,
        float(data.ctrl[0]),
        act,
    )


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """At rest, arm unloaded, filtered set point at 0."""
    data.qpos[:] = 0.0
    data.qvel[:] = 0.0
    if model.na:
        data.act[:] = 0.0


# -- state --------------------------------------------------------------------------------------
def _state(s: Snapshot) -> dict[str, float]:
    """ω_m, ω̇_m, V_ch, a_ch, y, v, V_2, V̇_2 and C_m of the snapshot (cached per snapshot)."""
    cached = s.cache.get("robot_axis")
    if cached is not None:
        return cached
    m, d, v = s.model, s.data, s.values
    r = v["R_p"] * v["k"]
    v_ch, a_ch = float(d.qvel[0]), float(d.qacc[0])
    y = dy = ddy = 0.0
    if m.nv > 1:
        y, dy, ddy = float(d.qpos[1]), float(d.qvel[1]), float(d.qacc[1])
    out = {
        "omega_m": v_ch / r,
        "omega_m_dot": a_ch / r,
        "V_ch": v_ch,
        "a_ch": a_ch,
        "y": y,
        "v": dy,
        "V_2": v_ch + dy,
        "V_2_dot": a_ch + ddy,
        "C_m": float(d.actuator_force[0]),
    }
    s.cache["robot_axis"] = out
    return out


def _last_step(s: Snapshot) -> dict[str, float] | None:
    """Averages over the step that led to the snapshot, from the state it started from
    (:func:`_remember`), as the integrator weighs them, so that the step's own equations
    of motion hold for them: the motor torque C_m (the actuator's force is affine in the
    command and the velocity; RK4 weighs its four stages, whose mean velocity is
    Δy_ch/Δt; semi-implicit Euler holds the force of the step's start), ω_m, ω̇_m =
    Δω_m/Δt, the arm's v = Δy/Δt and its y from the arm's own momentum balance
    (M2 ΔV_2/Δt = −K_t y − μ_t v). None before the first step, after a jump in time, or
    when the snapshot is not the state a step left (cached per snapshot)."""
    if "robot_axis_step" in s.cache:
        return s.cache["robot_axis_step"]
    m, d, v = s.model, s.data, s.values
    u, t1 = d.userdata, float(d.time)
    out = None
    if u.size >= 2 * MEMORY and u[MEMORY] == t1:
        t0, x0, v0, y0, dy0, ctrl, act = (float(x) for x in u[:MEMORY])
        h = t1 - t0
        if 0.0 < h <= 2.0 * float(m.opt.timestep):
            integrator = int(m.opt.integrator)
            rk4 = integrator == int(mujoco.mjtIntegrator.mjINT_RK4)
            euler = integrator == int(mujoco.mjtIntegrator.mjINT_EULER)
            x1, v1 = float(d.qpos[0]), float(d.qvel[0])
            command = ctrl
            if m.na and int(m.actuator_dyntype[0]) == int(mujoco.mjtDyn.mjDYN_FILTEREXACT):
                command = _filter_mean(act, ctrl, float(m.actuator_dynprm[0, 0]), h) if rk4 else act
            gear = float(m.actuator_gear[0, 0])
            speed = v0 if euler else (x1 - x0) / h
            bias = m.actuator_biasprm[0]
            torque = float(m.actuator_gainprm[0, 0]) * command + float(bias[0])
            torque += float(bias[1]) * gear * x0 + float(bias[2]) * gear * speed
            r = v["R_p"] * v["k"]
            out = {
                "C_m": torque,
                "omega_m": (x1 - x0) / h / r,
                "omega_m_dot": (v1 - v0) / h / r,
                "y": 0.0,
                "v": 0.0,
            }
            if m.nv > 1 and v["K_t"] > 0:
                y1, dy1 = float(d.qpos[1]), float(d.qvel[1])
                arm_v = (y1 - y0) / h
                arm_y = -(v["M2"] * ((v1 + dy1) - (v0 + dy0)) / h + v["mu_t"] * arm_v) / v["K_t"]
                out["y"], out["v"] = arm_y, arm_v
    s.cache["robot_axis_step"] = out
    return out


def _filter_mean(act: float, command: float, tau: float, h: float) -> float:
    """The set point filter's state as RK4 weighs it over a step of ``h`` from ``act``
    towards ``command`` (time constant ``tau``): (a₁ + 2 a₂ + 2 a₃ + a₄) / 6."""
    a1 = act
    a2 = act + 0.5 * h * (command - a1) / tau
    a3 = act + 0.5 * h * (command - a2) / tau
    a4 = act + h * (command - a3) / tau
    return (a1 + 2.0 * a2 + 2.0 * a3 + a4) / 6.0


def _c_m(s: Snapshot) -> float:
    """C_m averaged over the last step (the torque at its start otherwise)."""
    step = _last_step(s)
    return step["C_m"] if step is not None else _state(s)["C_m"]


def _loss(s: Snapshot) -> float:
    """Power lost in the simulated reducer [W]: (1 − ρ) C_in ω_m, C_in = C_m − (J_m + J_r) ω̇_m
    − f_v ω_m the torque entering it (driving mode; negative while the load drives back)."""
    st, v = _state(s), s.values
    c_in = st["C_m"] - (v["J_m"] + v["J_r"]) * st["omega_m_dot"] - v["f_v"] * st["omega_m"]
    return (1.0 - v["eta"]) * c_in * st["omega_m"]


def _c_m_ref(s: Snapshot) -> float:
    """Course 6.3 (with 6.4's ρ): J_eq ω̇_m + f_v ω_m − R_p k (K_t y + μ_t v), from the
    simulated motion averaged over the last step as C_m is (the state at the snapshot
    before any step); ρ divides the reducer's output torque when driving and multiplies
    it when braking."""
    st, v = _last_step(s) or _state(s), s.values
    return float(
        motor_torque(
            axis_of(v), st["omega_m"], st["omega_m_dot"], y=st["y"], v=st["v"],
            flexible=flexible(v), rho=v["eta"],
        )
    )  # fmt: skip


def mechanism(s: Snapshot, out: dict[str, float]) -> None:
    """The generic T, P_acc, P_ext and P_int of the mechanism (course 6.4), from those of
    the simulated chain, which carries the motor's side scaled by ρ (ρ (J_m + J_r),
    ρ f_v, ρ C_m): T and dT/dt get back the (1 − ρ) (J_m + J_r) share of the motor and
    reducer, P_ext is C_m ω_m, and P_int gets the friction's (1 − ρ) f_v ω_m² share and
    the reducer's loss. dT/dt − P_ext − P_int is unchanged (the frame's power: 0 with
    perfect joints). Nothing changes for ρ = 1."""
    v = s.values
    lost = 1.0 - v["eta"]
    if lost == 0.0:
        return
    st = _state(s)
    w, j = st["omega_m"], v["J_m"] + v["J_r"]
    if "T" in out:
        out["T"] += 0.5 * lost * j * w * w
    if "P_acc" in out:
        out["P_acc"] += lost * j * w * st["omega_m_dot"]
    if "P_ext" in out:
        out["P_ext"] += lost * st["C_m"] * w
    if "P_int" in out:
        out["P_int"] -= lost * v["f_v"] * w * w + _loss(s)


def _kinetic(s: Snapshot) -> float:
    """E_c = ½ J_eq ω_m² + ½ M2 V_2² (rigid arm: ½ J_eq ω_m², M2 in J_eq) [J]."""
    st, v = _state(s), s.values
    flex = flexible(v)
    t = 0.5 * equivalent_inertia(axis_of(v), flexible=flex) * st["omega_m"] ** 2
    return t + 0.5 * v["M2"] * st["V_2"] ** 2 if flex else t


def _residual(s: Snapshot) -> float:
    """dE_c/dt − (C_m ω_m − f_v ω_m² − K_t y v − μ_t v² − P_loss) [W] (course 6.3)."""
    st, v = _state(s), s.values
    flex = flexible(v)
    rate = equivalent_inertia(axis_of(v), flexible=flex) * st["omega_m"] * st["omega_m_dot"]
    if flex:
        rate += v["M2"] * st["V_2"] * st["V_2_dot"]
    p = st["C_m"] * st["omega_m"] - v["f_v"] * st["omega_m"] ** 2
    p -= v["K_t"] * st["y"] * st["v"] + v["mu_t"] * st["v"] ** 2
    return rate - (p - _loss(s))


def _arm_force(s: Snapshot) -> float:
    """Force of the arm on the carriage along y [N]: K_t y + μ_t v (0 for a rigid arm)."""
    st, v = _state(s), s.values
    return v["K_t"] * st["y"] + v["mu_t"] * st["v"] if s.model.nv > 1 else 0.0


def _belt_force(s: Snapshot) -> float:
    """Force of the belt on the carriage along y [N]: M1 a_ch minus the arm's and the end
    stops' forces (rigid arm: (M1 + M2) a_ch, the arm riding on the carriage)."""
    st, v = _state(s), s.values
    mass = v["M1"] if s.model.nv > 1 else v["M1"] + v["M2"]
    return mass * st["a_ch"] - _arm_force(s) - _stop_force(s)


def _stop_force(s: Snapshot) -> float:
    """Force of the end stops on the carriage along y [N] (0 away from them): the slide's
    limit force, the only constraint of the model."""
    return float(s.data.qfrc_constraint[0])


def _swing(s: Snapshot) -> float:
    """Amplitude [m] of the arm's oscillation against the free chain: √(y² + (v/ω)²) with
    ω = √(K_t (1/M2 + (R_p k)²/J_eq)) (the envelope of a free oscillation y = A cos ωt)."""
    st, v = _state(s), s.values
    if s.model.nv < 2:
        return 0.0
    omega = free_axis_frequency(axis_of(v))
    return math.hypot(st["y"], st["v"] / omega)


def _dissipated(s: Snapshot) -> float:
    """f_v ω_m² + μ_t v² + K_t y v [W]: minus the course's P_int (friction, arm)."""
    st, v = _state(s), s.values
    return v["f_v"] * st["omega_m"] ** 2 + v["mu_t"] * st["v"] ** 2 + v["K_t"] * st["y"] * st["v"]


def _j_eq(s: Snapshot) -> float:
    """Inertia the simulated chain presents to the motor shaft [kg·m²], read from the compiled
    model: (R_p k)² × (armature + M1, + M2 when the arm is welded to the carriage) / ρ. With
    ρ = 1 it is the course's J_eq; a lossy reducer makes the motor feel J_m + J_r + (the rest)/ρ."""
    m, v = s.model, s.values
    carriage = s.body_id("carriage")
    bodies = m.body_mass[carriage] if m.nv > 1 else m.body_subtreemass[carriage]
    return (v["R_p"] * v["k"]) ** 2 * float(m.dof_armature[0] + bodies) / v["eta"]


def reference(v: Values) -> dict[str, float]:
    """The course's J_eq (6.3, no efficiency): 2.7208e-3 kg·m², 3.4568e-3 for a rigid arm."""
    return {"J_eq": equivalent_inertia(axis_of(v), flexible=flexible(v))}


READOUTS = (
    SceneReadout("J_eq", "kg·m²", "Equivalent inertia the simulated chain presents to the motor (course 6.3; M2 included for a rigid arm; the reducer's share divided by its efficiency).", _j_eq, label="Inertie équivalente Jₑq", hint="Inertie d'un volant sur l'arbre moteur qui aurait la même énergie cinétique que la chaîne rigide (bras exclu s'il est souple)."),
    SceneReadout("omega_m", "rad/s", "Motor speed ω_m = V_ch / (R_p k).", lambda s: _state(s)["omega_m"], label="Vitesse du moteur ωₘ", hint="Vitesse de rotation de l'arbre moteur, liée à celle du chariot par Vch = Rₚ·k·ωₘ."),
    SceneReadout("V_ch", "m/s", "Speed of the carriage along y.", lambda s: _state(s)["V_ch"], label="Vitesse du chariot Vch", hint="Vitesse du chariot le long de l'axe y, entraîné par la courroie."),
    SceneReadout("V_2", "m/s", "Speed of the arm's mass M2 along y.", lambda s: _state(s)["V_2"], label="Vitesse des parties flexibles V₂", hint="Vitesse de la masse M₂ du bras, qui oscille autour de celle du chariot si le bras est souple."),
    SceneReadout("deflection", "m", "Deflection of the arm y_2 - y_ch.", lambda s: _state(s)["y"], label="Déformation du bras y₂ − ych", hint="Écart entre la position de la masse M₂ du bras et celle du chariot, nul pour un bras rigide."),
    SceneReadout("arm_swing", "m", "Amplitude of the arm's oscillation: √(y² + (v/ω)²), ω the arm's frequency against the free chain.", _swing, label="Amplitude d'oscillation du bras", hint="Enveloppe de la déformation du bras, calculée à partir de sa déformation et de sa vitesse par rapport au chariot."),
    SceneReadout("C_m", "N·m", "Torque the motor applies to its shaft, averaged over the last step (the work it does in the step over the angle it turns, to second order): it does not depend on the timestep, where the servo's torque at the start of a step does.", _c_m, label="Couple moteur appliqué Cₘ", hint="Couple que le moteur applique à son arbre, moyenné sur le dernier pas de calcul."),
    SceneReadout("C_m_ref", "N·m", "Course value J_eq ω̇_m + f_v ω_m − R_p k (K_t y + μ_t v) from the simulated motion (efficiency ρ on the reducer's output torque).", _c_m_ref, label="Couple moteur selon le cours", hint="Couple Jₑq·ω̇ₘ + fᵥ·ωₘ − Rₚ·k·(Kₜ·y + μₜ·v) calculé avec l'accélération et la déformation simulées, rendement compris."),
    SceneReadout("C_m_gap", "N·m", "C_m minus C_m_ref, both over the last step: non-zero where the simulated mechanism leaves the course's model (an end stop, the load driving the motor back through a lossy reducer).", lambda s: _c_m(s) - _c_m_ref(s), label="Écart au couple du cours", hint="Différence entre le couple appliqué et celui du cours, qui révèle un modèle différent."),
    SceneReadout("P_motor", "W", "Power of the motor C_m ω_m at the snapshot (the torque applied from it on).", lambda s: _state(s)["C_m"] * _state(s)["omega_m"], label="Puissance du moteur", hint="Puissance que le moteur fournit à son arbre à cet instant : le couple qu'il applique à cet instant multiplié par sa vitesse."),
    SceneReadout("P_loss", "W", "Power lost in the reducer (1 − ρ) × the power entering it (motor driving).", _loss, label="Puissance perdue dans le réducteur", hint="Puissance dissipée par le réducteur, une part 1 − ρ de la puissance qui y entre."),
    SceneReadout("E_c", "J", "Kinetic energy of the course: ½ J_eq ω_m² + ½ M2 V_2², J_eq the course's (6.3, efficiency aside: the kinetic energy does not depend on it; the generic T equals it).", _kinetic, label="Énergie cinétique de la chaîne Ec", hint="Énergie cinétique ½·Jₑq·ωₘ² + ½·M₂·V₂² de toute la chaîne, écrite avec l'inertie équivalente."),
    SceneReadout("energy_residual", "W", "Kinetic-energy theorem residual dE_c/dt − (C_m ω_m + P_int − P_loss) (course 6.3).", _residual, label="Écart au théorème de l'énergie cinétique", hint="Différence entre la dérivée de Ec et la somme des puissances du cours, nulle si le modèle simulé est celui du cours."),
    SceneReadout("F_belt", "N", "Force of the belt on the carriage along y.", _belt_force, label="Effort de la courroie sur le chariot", hint="Effort de la courroie sur le chariot le long de y, qui l'accélère et retient le bras."),
    SceneReadout("F_arm", "N", "Force of the arm on the carriage along y: K_t y + μ_t v.", _arm_force, label="Effort du bras sur le chariot", hint="Effort du ressort et de l'amortisseur du bras sur le chariot le long de y."),
    SceneReadout("P_diss", "W", "f_v ω_m² + μ_t v² + K_t y v: minus the course's inter-effort power.", _dissipated, label="Puissance des frottements et du bras", hint="Puissance fᵥ·ωₘ² + μₜ·v² + Kₜ·y·v, l'opposé de la puissance des inter-efforts du cours."),
    SceneReadout("y_ch", "m", "Position of the carriage's centre along the rail (end stops at -0.05 and 2.05 m).", lambda s: float(s.data.qpos[0]), label="Position du chariot ych", hint="Position du centre du chariot le long du rail, dont les butées sont à −0,05 m et 2,05 m."),
    SceneReadout("F_stop", "N", "Force of the end stops on the carriage along y (0 away from them; outside the course's model).", _stop_force, label="Effort des butées sur le chariot", hint="Effort qu'une butée de fin de rail exerce sur le chariot quand il l'atteint, absent du modèle du cours."),
)  # fmt: skip

ARROW_SCALE = 1e-3
"""Metres of arrow per newton."""


def _carriage_point(s: Snapshot, offset: tuple[float, float, float]) -> np.ndarray:
    """A point of the carriage [m]: C on its top (0, 0, 0.07), B the arm's attachment
    (0.14, 0, 0), offsets from the carriage's centre."""
    return np.asarray(s.data.xpos[s.body_id("carriage")]) + np.array(offset)


ARROWS = (
    Arrow("F_belt", "Courroie sur chariot", (220, 120, 30), lambda s: (_carriage_point(s, (0.0, 0.0, 0.07)), np.array([0.0, _belt_force(s), 0.0])), ARROW_SCALE, unit="N", point="C", hint="Effort de la courroie sur le chariot, au point C (orange)."),
    Arrow("F_arm", "Bras sur chariot", (60, 160, 80), lambda s: (_carriage_point(s, (0.14, 0.0, 0.0)), np.array([0.0, _arm_force(s), 0.0])), ARROW_SCALE, unit="N", point="B", hint="Effort du bras sur le chariot, à son attache B (vert)."),
)  # fmt: skip

DEFAULTS = {p.name: p.default for p in PARAMS}
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
    # RK4: the arm's oscillation (58.5 rad/s against the free chain) keeps its amplitude
    # with dt = 1 ms (0.06 rad per step); the step shrinks with the fastest eigenvalue
    # when K_t grows or M2 shrinks (default_timestep).
    integrator="rk4",
    timestep=1e-3,
    timestep_for=default_timestep,
    # Beyond 10 ms RK4 loses the arm's oscillation (0.6 rad per step: 1e-3 on V_2 at 10 ms)
    # and nears its stability limit on the speed servo (time constant 10 ms).
    max_timestep=1e-2,
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
    sections="6.3, 6.4",
    camera=((1.0, -0.2, 0.35), (0.0, 0.0, 1.0)),
    extra={"solid_names": {"carriage": "ch (chariot)", "arm": "2 (bras z)"}},
    # Round-off: at constant speed the carriage forces keep ~1e-9 N of the arm's last ringing
    # (peaks of 100 N during a start), the powers and the theorem's residual ~1e-13 W; the
    # arm's deflection decays to picometres in a pause: under half a nanometre it reads 0.
    overlay={
        "omega_m": "ωₘ",
        "C_m": "Couple moteur Cₘ",
        "deflection": "Déformation du bras",
        "energy_residual": "Écart au théorème",
    },
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
)
