"""The mechanism's structure: which bodies move and how their joints are grouped.

The *mechanism* is every body not welded to the world (``model.body_weldid != 0``). Its
index arrays depend on the compiled model only, so they are computed once per model and
shared (read-only) by every readout row.
"""

from __future__ import annotations

import weakref
from typing import Any

import mujoco
import numpy as np


class Structure:
    """Model-constant index arrays of the mechanism (body tree and joints): computed once
    per compiled model, since every readout row would otherwise rebuild them."""

    def __init__(self, model: mujoco.MjModel) -> None:
        weld, parent = model.body_weldid, model.body_parentid
        self.bodies = _frozen(np.flatnonzero(weld != 0))
        b = self.bodies
        self.children = _frozen(b[weld[parent[b]] == 0])
        jointed = self.children[model.body_jntnum[self.children] > 0]
        self.support_bodies = _frozen(np.concatenate([jointed, b]))
        self.support_roots = _frozen(model.body_rootid[self.support_bodies])
        self.n_jointed = len(jointed)
        self.children_joints = JointGroups(model, self.children)
        kind = model.jnt_type
        scalar = (kind == mujoco.mjtJoint.mjJNT_HINGE) | (kind == mujoco.mjtJoint.mjJNT_SLIDE)
        self.scalar_joints = _frozen(np.flatnonzero(scalar))  # those a spring may act in
        self.scalar_qpos = _frozen(model.jnt_qposadr[self.scalar_joints])


class JointGroups:
    """The joints of some bodies, grouped by type, as index arrays."""

    def __init__(self, model: mujoco.MjModel, bodies: np.ndarray) -> None:
        kinds: dict[int, list[tuple[int, int, int]]] = {}
        for body in bodies:
            start = int(model.body_jntadr[body])
            for j in range(start, start + int(model.body_jntnum[body])):
                kind = int(model.jnt_type[j])
                kinds.setdefault(kind, []).append((j, int(model.jnt_dofadr[j]), int(body)))

        def cols(kind: mujoco.mjtJoint) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
            rows = kinds.get(int(kind))
            if not rows:
                return None
            a = np.array(rows, dtype=int)
            return _frozen(a[:, 0]), _frozen(a[:, 1]), _frozen(a[:, 2])

        self.hinge = cols(mujoco.mjtJoint.mjJNT_HINGE)
        self.slide = cols(mujoco.mjtJoint.mjJNT_SLIDE)
        self.ball = cols(mujoco.mjtJoint.mjJNT_BALL)
        self.free = cols(mujoco.mjtJoint.mjJNT_FREE)
        if self.ball is not None:
            self.ball_dofs = _frozen(self.ball[1][:, None] + np.arange(3))
        if self.free is not None:
            self.free_dofs = _frozen(self.free[1][:, None] + np.arange(6))


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


_STRUCTURES: weakref.WeakKeyDictionary[Any, Structure] = weakref.WeakKeyDictionary()
_GROUPS: weakref.WeakKeyDictionary[Any, dict[bytes, JointGroups]] = weakref.WeakKeyDictionary()


def structure(model: mujoco.MjModel) -> Structure:
    """The mechanism's :class:`Structure` for ``model`` (built once per compiled model)."""
    found = _STRUCTURES.get(model)
    if found is None:
        found = _STRUCTURES[model] = Structure(model)
    return found


def joint_groups(model: mujoco.MjModel, bodies: np.ndarray) -> JointGroups:
    """The joints of ``bodies`` grouped by type (built once per model and set of bodies)."""
    cache = _GROUPS.get(model)
    if cache is None:
        cache = _GROUPS[model] = {}
    key = np.asarray(bodies, dtype=int).tobytes()
    found = cache.get(key)
    if found is None:
        found = cache[key] = JointGroups(model, np.asarray(bodies, dtype=int))
    return found


def mechanism_bodies(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the bodies not welded to the world (read-only, shared)."""
    return structure(model).bodies


def gravity_vector(model: mujoco.MjModel) -> np.ndarray:
    """Gravity g [m/s²] of the model, world axes (zero when weight is neglected)."""
    if model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY:
        return np.zeros(3)
    return np.array(model.opt.gravity)
