"""Isolating one solid: its dynamic torsor and every action on it, from MuJoCo's data.

A *solid* is a group of bodies welded together (one ``body_weldid``). The actions on it
are: the joint to its parent (the torque a motor passes on to the solid shown apart: its
torque less what its own rotor takes, a joint's armature), the joints to its children,
contacts and equality constraints (loop closures), and weight. Their sum equals the
solid's dynamic torsor {D} (PFD): :func:`balance` gives them all at the solid's centre
of mass with the PFD's residual, for the web panel to show.
Requires ``mj_forward`` and ``mj_rnePostConstraint`` at the current state.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from sandbox.mechanics import Torsor
from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.kinematics import Kinematics
from sandbox.physics.mechanism import gravity_vector as _gravity
from sandbox.physics.torsors import dof_wrenches as _dof_wrenches
from sandbox.physics.torsors import joint_drive as _joint_drive
from sandbox.physics.torsors import spatial_at_origin as _spatial_at_origin

JOINT_NAMES = {
    int(mujoco.mjtJoint.mjJNT_HINGE): "pivot",
    int(mujoco.mjtJoint.mjJNT_SLIDE): "glissière",
    int(mujoco.mjtJoint.mjJNT_BALL): "rotule",
    int(mujoco.mjtJoint.mjJNT_FREE): "libre",
}


@dataclass(frozen=True)
class Action:
    """One action on the isolated solid: resultant [N] and moment at O [N·m], world axes."""

    label: str
    resultant: np.ndarray
    moment: np.ndarray


def _name(model: mujoco.MjModel, body: int) -> str:
    if body == 0 or model.body_weldid[body] == 0:
        return "0 (bâti)"
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or f"corps {body}"


def solids(model: mujoco.MjModel) -> list[int]:
    """Root body of every moving solid (a body with its own joint)."""
    return [b for b in range(1, model.nbody) if model.body_weldid[b] == b]


def members(model: mujoco.MjModel, solid: int) -> np.ndarray:
    """Bodies welded into ``solid``."""
    return np.flatnonzero(model.body_weldid == solid)


def dynamic_torsor(model: mujoco.MjModel, data: mujoco.MjData, solid: int) -> Action:
    """{D} of the solid at O: Σ m a_G and Σ δ_G + OG ∧ m a_G over its bodies."""
    k = Kinematics(model, data)
    b = members(model, solid)
    ma = model.body_mass[b][:, None] * k.a_g[b]
    moment = (k.delta_g[b] + _cross(data.xipos[b], ma)).sum(0)
    return Action("{D}", ma.sum(0), moment)


def _parent_actions(
    model: mujoco.MjModel, data: mujoco.MjData, solid: int
) -> tuple[Action, Action]:
    """The joint to the solid's parent at O, and the motor's share passed on through it
    (its torque less what its own rotor takes, armature·q̈, C_act = C_mot + J·θ''): the
    joint then keeps its reactions only, and a frictionless joint's moment about its own
    axis is 0."""
    parent = int(model.body_parentid[solid])
    joints = range(model.body_jntadr[solid], model.body_jntadr[solid] + model.body_jntnum[solid])
    kinds = ", ".join(JOINT_NAMES.get(int(model.jnt_type[j]), "liaison") for j in joints)
    r, m = _spatial_at_origin(model, data, solid, data.cfrc_int[solid])
    mr, mm = _dof_wrenches(model, data, _joint_drive(model, data), np.array([solid]))
    joint = Action(f"{_name(model, parent)} → solide ({kinds})", r - mr, m - mm)
    return joint, Action("moteur", mr, mm)


def joint_action(model: mujoco.MjModel, data: mujoco.MjData, solid: int) -> Action:
    """The action of the solid's parent on it through their joint, at O, the motor's
    torque apart (the first of :func:`actions`, without computing the others)."""
    return _parent_actions(model, data, solid)[0]


def actions(model: mujoco.MjModel, data: mujoco.MjData, solid: int) -> list[Action]:
    """Every action on the solid at O (see the module doc)."""
    group = set(members(model, solid).tolist())
    joint, motor = _parent_actions(model, data, solid)
    out = [joint]
    if np.any(motor.resultant) or np.any(motor.moment):
        out.append(motor)
    for child in range(1, model.nbody):
        if model.body_weldid[child] == child and int(model.body_parentid[child]) in group:
            r, m = _spatial_at_origin(model, data, child, data.cfrc_int[child])
            out.append(Action(f"{_name(model, child)} → solide", -r, -m))
    ext_r, ext_m = np.zeros(3), np.zeros(3)
    for body in group:
        r, m = _spatial_at_origin(model, data, body, data.cfrc_ext[body])
        ext_r, ext_m = ext_r + r, ext_m + m
    if np.any(np.abs(ext_r) > 0) or np.any(np.abs(ext_m) > 0):
        out.append(Action("fermeture de boucle, contacts", ext_r, ext_m))
    g = _gravity(model)
    if np.any(g):
        b = np.array(sorted(group))
        w = model.body_mass[b][:, None] * g
        out.append(Action("poids", w.sum(0), _cross(data.xipos[b], w).sum(0)))
    return out


def centre_of_mass(model: mujoco.MjModel, data: mujoco.MjData, solid: int) -> np.ndarray:
    """G of the solid (its welded bodies), world coordinates [m], shape (3,)."""
    b = members(model, solid)
    mass = model.body_mass[b]
    return (mass[:, None] * data.xipos[b]).sum(0) / max(float(mass.sum()), 1e-300)


def moved(action: Action, point: np.ndarray) -> Action:
    """The same action with its moment at ``point`` (M_P = M_O + R ∧ OP) [N·m]."""
    t = Torsor(action.resultant, action.moment, np.zeros(3)).at(point)
    return Action(action.label, t.resultant, t.moment)


def _largest(vectors: list[np.ndarray]) -> float:
    return max((float(np.linalg.norm(v)) for v in vectors), default=0.0)


def pfd_gap(dynamic: Action, acts: list[Action]) -> tuple[float, float]:
    """(‖Σ R − R{D}‖ [N], ‖Σ M − M{D}‖ [N·m]): the PFD's absolute gaps (moments at the
    same point for every torsor)."""
    total_r = np.sum([a.resultant for a in acts], axis=0) if acts else np.zeros(3)
    total_m = np.sum([a.moment for a in acts], axis=0) if acts else np.zeros(3)
    return (
        float(np.linalg.norm(total_r - dynamic.resultant)),
        float(np.linalg.norm(total_m - dynamic.moment)),
    )


def pfd_residual(dynamic: Action, acts: list[Action], length: float = 1.0) -> float:
    """The PFD's relative gap: the absolute gaps (:func:`pfd_gap`, the moment's over
    ``length`` [m], a size of the mechanism) over the largest torsor they are gaps between
    (an action's or {D}'s resultant, or moment over ``length``); 0 when all are 0. Never
    over a round-off: divided by {D}, which is 0 for a solid at constant speed, the
    engine's read 3×10²⁸⁶; divided by moments that are all round-off (a piston's, at
    its centre of mass), 2×10⁻⁴."""
    gap_r, gap_m = pfd_gap(dynamic, acts)
    scale = max(
        _largest([dynamic.resultant, *(a.resultant for a in acts)]),
        _largest([dynamic.moment, *(a.moment for a in acts)]) / length,
    )
    return max(gap_r, gap_m / length) / scale if scale > 0 else 0.0


@dataclass(frozen=True)
class Balance:
    """The PFD of one isolated solid, every torsor reduced at one point (its centre of
    mass G unless another is asked for).

    Attributes:
        centre: G, world coordinates [m], shape (3,).
        point: Where the moments are reduced, world coordinates [m], shape (3,).
        dynamic: {D} of the solid (moment at ``point``).
        actions: Every action on it, as :func:`actions` lists them (moments at ``point``).
        residual: :func:`pfd_residual` (relative to the largest torsor, 0 when it closes).
        gap: :func:`pfd_gap` (‖ΔR‖ [N], ‖ΔM‖ [N·m]).
        axes: The solid's own basis B1, columns = its unit vectors in world, (3, 3).
    """

    centre: np.ndarray
    dynamic: Action
    actions: list[Action]
    residual: float
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gap: tuple[float, float] = (0.0, 0.0)
    axes: np.ndarray = field(default_factory=lambda: np.eye(3))


def balance(
    model: mujoco.MjModel, data: mujoco.MjData, solid: int, point: np.ndarray | None = None
) -> Balance:
    """{D} of the solid and the actions on it at ``point`` (default: its centre of mass),
    with the PFD's gaps."""
    g = centre_of_mass(model, data, solid)
    at = g if point is None else np.asarray(point, dtype=float)
    d = dynamic_torsor(model, data, solid)
    acts = actions(model, data, solid)
    d_at, acts_at = moved(d, at), [moved(a, at) for a in acts]
    return Balance(
        g,
        d_at,
        acts_at,
        pfd_residual(d_at, acts_at, float(model.stat.extent) or 1.0),
        point=at,
        gap=pfd_gap(d_at, acts_at),
        axes=np.asarray(data.xmat[solid], dtype=float).reshape(3, 3).copy(),
    )
