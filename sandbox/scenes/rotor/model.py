"""Model of the unbalanced rotor: the defect and correction masses placed and the disk
tilted in the MJCF, the velocity servo's set point and the initial speed."""

from __future__ import annotations

import mujoco
import numpy as np

from sandbox.physics.spec import Values
from sandbox.scenes.rotor.course import disk_axis, mass_points, omega


def edit(spec: mujoco.MjSpec, values: Values) -> None:
    """Place the defect and correction masses and tilt the disk."""
    quat = np.zeros(4)
    mujoco.mju_quatZ2Vec(quat, disk_axis(values))
    disk = spec.geom("disk")
    disk.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT  # the XML gives a zaxis
    disk.quat = quat
    for name, mass, pos in mass_points(values):
        geom = spec.geom(name)
        geom.mass = mass
        geom.pos = pos
        geom.rgba[3] = 1.0 if mass > 0 else 0.0
    motor = spec.actuator("motor")  # a first-order set point: a start from rest
    if values["ramp_s"] > 0:
        motor.dyntype = mujoco.mjtDyn.mjDYN_FILTEREXACT
        motor.dynprm[0] = values["ramp_s"]
    else:
        motor.dyntype = mujoco.mjtDyn.mjDYN_NONE


def drive(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """The velocity servo holds the imposed speed."""
    data.ctrl[0] = omega(values)


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """Start already at the imposed speed (steady state), or at rest for a start."""
    data.qvel[0] = 0.0 if values["ramp_s"] > 0 else omega(values)
