"""Model of the robot axis: masses, armature, damping, the arm's spring and the motor's
command and efficiency in the MJCF; the constant and time-varying commands, the state each
step starts from kept in ``userdata``, and the start at rest."""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco

from sandbox.mechanics.imposed import Anchor, Motion, follow
from sandbox.mechanics.robot_axis import back_and_forth, back_and_forth_motion
from sandbox.physics.imposed import Imposed
from sandbox.physics.spec import Values
from sandbox.scenes.imposed import one_joint
from sandbox.scenes.robot_axis.course import axis_of, flexible, profile, servo_gain
from sandbox.scenes.robot_axis.params import (
    BACK_AND_FORTH,
    POSITION_TIME,
    RPM,
    SINE,
    SPEED,
    TORQUE,
)


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


MEMORY = 7
"""``userdata`` numbers once kept per state (two states) for readings averaged over the
last step; the readings are now of one instant (the torque applied from it on) and
nothing writes them, but the slots stay reserved: the states of recordings made before
keep their size, and the imposed motion's anchor follows them."""


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """At rest, arm unloaded, filtered set point at 0."""
    data.qpos[:] = 0.0
    data.qvel[:] = 0.0
    if model.na:
        data.act[:] = 0.0


def _reference_motion(v: Values) -> Callable[[float], Motion]:
    """The back-and-forth move's (position, speed, acceleration) of the carriage at t."""
    r = v["R_p"] * v["k"]
    args = (v["stroke"], v["speed_rpm"] * RPM * r, v["accel_s"], v["pause_s"])
    return lambda t: back_and_forth_motion(t, *args)


def imposed_law(v: Values, anchor: Anchor, t: float) -> Motion:
    """The carriage on the back-and-forth move (:func:`move_reference`), joined from where
    it was without a jump (the free simulation's servo lags it a little) within the
    position loop's time constant."""
    return follow(anchor, _reference_motion(v), POSITION_TIME, t)


def imposed_refusal(v: Values) -> tuple[str, str] | None:
    """Why the carriage's motion cannot be imposed at these values, or None."""
    if flexible(v):
        return (
            "the flexible arm vibrates on its spring: its motion must be simulated "
            "(set flexible=0 for a rigid arm)",
            "Le bras souple vibre sur son ressort : son mouvement doit être simulé (choisissez "
            "le bras rigide pour imposer le mouvement).",
        )
    if profile(v) != BACK_AND_FORTH:
        return (
            "only the back-and-forth move (profile=2) imposes the carriage's motion; the "
            "other commands give a torque or run the carriage onto its stops",
            "Seul le va-et-vient impose le mouvement du chariot ; les autres commandes "
            "donnent un couple ou amènent le chariot en butée : mouvement simulé.",
        )
    return None


IMPOSED = Imposed(
    "carriage",
    "motor",
    one_joint("carriage"),
    imposed_law,
    unavailable=imposed_refusal,
    slot=2 * MEMORY,
    held_at=None,  # a carriage on its slide: nothing turns to be read at an angle
)
"""The rigid arm's carriage on the trapezoidal speed profile (course 6.3): the torque the
motor must give, by inverse dynamics (free by default: the flexible arm's vibration is
the scene's first lesson)."""
