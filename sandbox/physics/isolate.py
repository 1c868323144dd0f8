"""Isolating one solid: its dynamic torsor and every action on it, from MuJoCo's data.

A *solid* is a group of bodies welded together (one ``body_weldid``). The actions on it
are: the joint to its parent (motor torque shown apart), the joints to its children,
contacts and equality constraints (loop closures), and weight. Their sum equals the
solid's dynamic torsor {D} (PFD): :func:`balance` gives them all at the solid's centre
of mass with the PFD's residual, for the web panel to show.
Requires ``mj_forward`` and ``mj_rnePostConstraint`` at the current state.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from sandbox.mechanics import Torsor
from sandbox.physics.readouts import (
    Kinematics,
    _cross,
    _dof_wrenches,
    _gravity,
    _spatial_at_origin,
)

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


def actions(model: mujoco.MjModel, data: mujoco.MjData, solid: int) -> list[Action]:
    """Every action on the solid at O (see the module doc)."""
    out = []
    group = set(members(model, solid).tolist())
    parent = int(model.body_parentid[solid])
    joints = range(model.body_jntadr[solid], model.body_jntadr[solid] + model.body_jntnum[solid])
    kinds = ", ".join(JOINT_NAMES.get(int(model.jnt_type[j]), "liaison") for j in joints)
    r, m = _spatial_at_origin(model, data, solid, data.cfrc_int[solid])
    mr, mm = _dof_wrenches(model, data, data.qfrc_actuator, np.array([solid]))
    out.append(Action(f"{_name(model, parent)} → solide ({kinds})", r - mr, m - mm))
    if np.any(mr) or np.any(mm):
        out.append(Action("moteur", mr, mm))
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


def pfd_residual(dynamic: Action, acts: list[Action]) -> float:
    """|Σ R(actions) − R({D})| / |R({D})|: 0 when the PFD's resultant equation closes."""
    total = np.sum([a.resultant for a in acts], axis=0) if acts else np.zeros(3)
    gap = float(np.linalg.norm(total - dynamic.resultant))
    return gap / max(float(np.linalg.norm(dynamic.resultant)), 1e-300)


@dataclass(frozen=True)
class Balance:
    """The PFD of one isolated solid, every torsor reduced at its centre of mass G.

    Attributes:
        centre: G, world coordinates [m], shape (3,).
        dynamic: {D} of the solid (moment at G).
        actions: Every action on it, as :func:`actions` lists them (moments at G).
        residual: :func:`pfd_residual` (relative, 0 when the PFD closes).
    """

    centre: np.ndarray
    dynamic: Action
    actions: list[Action]
    residual: float


def balance(model: mujoco.MjModel, data: mujoco.MjData, solid: int) -> Balance:
    """{D} of the solid and the actions on it at G, with the PFD's residual."""
    g = centre_of_mass(model, data, solid)
    d = dynamic_torsor(model, data, solid)
    acts = actions(model, data, solid)
    return Balance(g, moved(d, g), [moved(a, g) for a in acts], pfd_residual(d, acts))
