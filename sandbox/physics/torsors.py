"""Torsors of the mechanism at the world origin O: kinetic {C}, dynamic {D}, weight, motors,
applied loads and the frame's action on the mechanism (joints, contacts, constraints).

Pure functions of (model, data), on the world axes, relative to R0 (Galilean); the
dynamic and support torsors need ``mj_rnePostConstraint``.
"""

from __future__ import annotations

from collections.abc import Iterable

import mujoco
import numpy as np

from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.kinematics import Kinematics, Pair, ensure_kinematics, select_bodies
from sandbox.physics.mechanism import (
    JointGroups,
    gravity_vector,
    joint_groups,
    mechanism_bodies,
    structure,
)


def _sum_at_o(linear: np.ndarray, own: np.ndarray, points: np.ndarray) -> Pair:
    """Σ over bodies of torsors known at their centres G (rows): the resultant Σ ``linear``
    and the moment at O, Σ (``own`` + OG ∧ ``linear``), with OG the rows of ``points``."""
    return linear.sum(0), (own + _cross(points, linear)).sum(0)


def kinetic_torsor(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    bodies: Iterable[int] | None = None,
    *,
    kin: Kinematics | None = None,
) -> Pair:
    """{C} at O: (Σ m v_G, Σ I_G ω + OG ∧ m v_G)."""
    k = ensure_kinematics(model, data, kin)
    if bodies is None:
        return _sum_at_o(k.momentum_b, k.i_omega_b, k.xipos_b)
    b = select_bodies(k, bodies)
    return _sum_at_o(model.body_mass[b][:, None] * k.v_g[b], k.i_omega[b], data.xipos[b])


def dynamic_torsor(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    bodies: Iterable[int] | None = None,
    *,
    kin: Kinematics | None = None,
) -> Pair:
    """{D} at O: (Σ m a_G, Σ I_G α + ω ∧ I_G ω + OG ∧ m a_G)."""
    k = ensure_kinematics(model, data, kin)
    if bodies is None:
        return _sum_at_o(k.mass_b[:, None] * k.a_g_b, k.delta_g_b, k.xipos_b)
    b = select_bodies(k, bodies)
    return _sum_at_o(model.body_mass[b][:, None] * k.a_g[b], k.delta_g[b], data.xipos[b])


def gravity_torsor(
    model: mujoco.MjModel, data: mujoco.MjData, bodies: Iterable[int] | None = None
) -> Pair:
    """Weight of the mechanism at O (zero when weight is neglected)."""
    b = mechanism_bodies(model) if bodies is None else np.asarray(list(bodies), dtype=int)
    w = model.body_mass[b][:, None] * gravity_vector(model)
    return w.sum(0), _cross(data.xipos[b], w).sum(0)


def _frame_children(model: mujoco.MjModel) -> np.ndarray:
    """Mechanism bodies whose parent is welded to the world (they touch the frame)."""
    return structure(model).children


def dof_wrenches(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    force: np.ndarray,
    bodies: np.ndarray,
    *,
    groups: JointGroups | None = None,
) -> Pair:
    """Wrench at O of generalised forces ``force`` (nv,) in the joints of ``bodies``.

    Hinge: a torque along its axis; slide: a force along its axis through its anchor; ball:
    a torque in body axes; free: a world-axis force at the body origin and a body-axis
    torque. Vectorised over the joints of each type (``groups``: their cached indices).
    """
    g = groups if groups is not None else joint_groups(model, bodies)
    r, m = np.zeros(3), np.zeros(3)
    if g.hinge is not None:
        j, dof, _ = g.hinge
        m += force[dof] @ data.xaxis[j]
    if g.slide is not None:
        j, dof, _ = g.slide
        f = force[dof][:, None] * data.xaxis[j]
        r += f.sum(0)
        m += _cross(data.xanchor[j], f).sum(0)
    if g.ball is not None:
        _, _, body = g.ball
        rot = data.xmat[body].reshape(-1, 3, 3)
        m += np.einsum("bij,bj->i", rot, force[g.ball_dofs])
    if g.free is not None:
        _, _, body = g.free
        rot = data.xmat[body].reshape(-1, 3, 3)
        dofs = g.free_dofs
        f = force[dofs[:, :3]]
        r += f.sum(0)
        m += _cross(data.xpos[body], f).sum(0) + np.einsum("bij,bj->i", rot, force[dofs[:, 3:]])
    return r, m


def joint_drive(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Generalised forces that motors and qfrc_applied pass on to the bodies (nv,).

    A joint's armature models a motor rotor spinning with it: its inertial torque
    armature·q̈ stays inside the motor, so the bodies receive the rest.
    """
    return data.qfrc_actuator + data.qfrc_applied - model.dof_armature * data.qacc


def actuator_torsor(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """Motors (and qfrc_applied) acting in joints between the frame and the mechanism."""
    return dof_wrenches(model, data, joint_drive(model, data), _frame_children(model))


def applied_torsor(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """xfrc_applied (force at G, torque) on mechanism bodies, at O."""
    if not data.xfrc_applied.any():  # the usual case: no applied load
        return np.zeros(3), np.zeros(3)
    b = mechanism_bodies(model)
    f = data.xfrc_applied[b, :3]
    return f.sum(0), (data.xfrc_applied[b, 3:] + _cross(data.xipos[b], f)).sum(0)


def spatial_at_origin(
    model: mujoco.MjModel, data: mujoco.MjData, body: int, wrench: np.ndarray
) -> Pair:
    """Com-based spatial force [torque at c; force] of ``body`` reduced at O."""
    c = data.subtree_com[model.body_rootid[body]]
    return wrench[3:].copy(), wrench[:3] + _cross(c, wrench[3:])


def support_torsor(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """Action of the frame on the mechanism at O: joints, contacts, equality constraints.

    Joints: ``cfrc_int`` of each body hanging from the frame is the wrench its parent
    transmits, motors and qfrc_applied included, so those are removed. Contacts and
    connect/weld constraints: MuJoCo gathers their forces with ``xfrc_applied`` in
    ``cfrc_ext``; summed over the mechanism, the pairs between two moving bodies cancel
    (mutual actions), leaving the frame's share. Requires mj_rnePostConstraint.
    """
    st = structure(model)
    bodies, n = st.support_bodies, st.n_jointed
    wrench = np.concatenate([data.cfrc_int[bodies[:n]], data.cfrc_ext[bodies[n:]]])
    c = data.subtree_com[st.support_roots]
    r = wrench[:, 3:].sum(0)
    m = (wrench[:, :3] + _cross(c, wrench[:, 3:])).sum(0)
    drive = joint_drive(model, data)
    ar, am = dof_wrenches(model, data, drive, st.children, groups=st.children_joints)
    xr, xm = applied_torsor(model, data)
    return r - ar - xr, m - am - xm
