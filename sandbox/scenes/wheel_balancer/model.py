"""The wheel balancer's model: the MJCF edits (point masses, tilted tyre, the soft bench's
elastic joints), the velocity servo and the initial state (already in the steady
vibration on soft supports).
"""

from __future__ import annotations

import mujoco
import numpy as np

from sandbox.physics.spec import Values
from sandbox.scenes.wheel_balancer.course import steady_whirl
from sandbox.scenes.wheel_balancer.geometry import (
    mass_points,
    springs,
    tube_inertia,
    tyre_axis,
    z_to,
)
from sandbox.scenes.wheel_balancer.params import (
    AXIS,
    RIM_INNER,
    RIM_MASS,
    RIM_OUTER,
    RIM_WIDTH,
    TYRE_INNER,
    TYRE_MASS,
    TYRE_OUTER,
    TYRE_WIDTH,
    omega,
    soft,
)


def edit(spec: mujoco.MjSpec, values: Values) -> None:
    """Place the point masses, tilt the tyre, set the tubes' inertias and, for the lab
    bench, hang the housing on four elastic joints."""
    hidden = int(round(values["mystery"])) > 0
    for name, mass, pos in mass_points(values):
        geom = spec.geom(name)
        geom.mass = mass
        geom.pos = pos
        shown = mass > 0 and not (name == "defect" and hidden)
        geom.rgba[3] = 1.0 if shown else 0.0
    for body_name, mass, tube in (
        ("rim", RIM_MASS, tube_inertia(RIM_MASS, RIM_OUTER, RIM_INNER, RIM_WIDTH)),
        ("tyre", TYRE_MASS, tube_inertia(TYRE_MASS, TYRE_OUTER, TYRE_INNER, TYRE_WIDTH)),
    ):
        body = spec.body(body_name)
        body.mass = mass
        body.inertia = np.diag(tube)
        body.ipos = np.zeros(3)
        body.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT  # the XML gives a zaxis
    spec.body("rim").quat = z_to(AXIS)
    spec.body("tyre").quat = z_to(tyre_axis(values))
    if soft(values):
        cradle = spec.body("cradle")
        k_t, c_t, k_r, c_r = springs()
        for name, kind, axis, k, c in (
            ("support_y", mujoco.mjtJoint.mjJNT_SLIDE, (0, 1, 0), k_t, c_t),
            ("support_z", mujoco.mjtJoint.mjJNT_SLIDE, (0, 0, 1), k_t, c_t),
            ("support_tilt_y", mujoco.mjtJoint.mjJNT_HINGE, (0, 1, 0), k_r, c_r),
            ("support_tilt_z", mujoco.mjtJoint.mjJNT_HINGE, (0, 0, 1), k_r, c_r),
        ):
            joint = cradle.add_joint(name=name, type=kind, axis=axis)
            joint.stiffness = [k, 0.0, 0.0]  # MuJoCo 4: linear term first
            joint.damping = [c, 0.0, 0.0]


def drive(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """The velocity servo holds the imposed speed."""
    data.ctrl[0] = omega(values)


def _dof(model: mujoco.MjModel, name: str) -> int:
    return int(model.jnt_dofadr[model.joint(name).id])


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """Start at the imposed speed; on soft supports, already in the steady vibration of
    the closed form (no start-up transient to wait for)."""
    w = omega(values)
    data.qvel[_dof(model, "spin")] = w
    if not soft(values):
        return
    whirl = steady_whirl(values)
    spin = np.array([w, 0.0, 0.0])
    dd, dphi = np.cross(spin, whirl.d), np.cross(spin, whirl.phi)
    for name, pos, vel in (
        ("support_y", whirl.d[1], dd[1]),
        ("support_z", whirl.d[2], dd[2]),
        ("support_tilt_y", whirl.phi[1], dphi[1]),
        ("support_tilt_z", whirl.phi[2], dphi[2]),
    ):
        j = model.joint(name).id
        data.qpos[model.jnt_qposadr[j]] = pos
        data.qvel[model.jnt_dofadr[j]] = vel
