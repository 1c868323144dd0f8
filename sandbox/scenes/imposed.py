"""The imposed motions the scenes share: a shaft held at ``speed_rpm`` (its start through
the motor's first-order lag ``ramp_s`` where the scene has one), and a single joint
turning with it (the rotor, the wheel)."""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco

from sandbox.mechanics.imposed import Anchor, Motion, set_speed
from sandbox.physics.imposed import Imposed
from sandbox.physics.spec import Values

RPM = 2.0 * math.pi / 60.0


def held_speed(values: Values, anchor: Anchor, t: float) -> Motion:
    """The shaft at ``speed_rpm`` from the anchor: at once, or through the lag ``ramp_s``
    when the scene has one and it is positive (the free simulation's filtered set point)."""
    return set_speed(anchor, values["speed_rpm"] * RPM, values.get("ramp_s", 0.0), t)


def one_joint(joint: str) -> Callable[[mujoco.MjModel, mujoco.MjData, Values, Motion], None]:
    """The closure of a mechanism with one joint: its position, speed and acceleration are
    the input's (every other joint, if any, at rest)."""

    def place(model: mujoco.MjModel, data: mujoco.MjData, values: Values, motion: Motion) -> None:
        j = model.joint(joint).id
        q, dof = int(model.jnt_qposadr[j]), int(model.jnt_dofadr[j])
        data.qpos[q], data.qvel[dof], data.qacc_warmstart[dof] = motion

    return place


def spinning(joint: str, actuator: str, *, default: bool = False, **kw: object) -> Imposed:
    """A rotor turning about a fixed axis at ``speed_rpm`` (:func:`held_speed`)."""
    return Imposed(joint, actuator, one_joint(joint), held_speed, default=default, **kw)  # type: ignore[arg-type]
