"""What one drawn frame shows, computed once from the drawn state: the pose of each rigid
group of moving bodies and the scene's arrows. Views only send it to their browsers.

A *group* is a body that moves on joints of its own (or a mocap body) together with the
bodies welded to it: one pose a frame moves all its geoms (the compressor's crank and its
counterweight, the balancer's wheel, tyre and hub). Arrows are evaluated once per frame
on the same snapshot as the frame's readouts, whatever the number of views.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import mujoco
import numpy as np

from sandbox.physics.snapshot import Snapshot


class ArrowSource(Protocol):
    """What a picture needs of an arrow (a scene's :class:`~sandbox.physics.page.Arrow`):
    its function of a snapshot and its scale [m per unit]."""

    @property
    def fn(self) -> Callable[[Snapshot], tuple[Any, Any]]: ...

    @property
    def scale(self) -> float: ...


_GROUPS: weakref.WeakKeyDictionary[Any, tuple[np.ndarray, np.ndarray]] = weakref.WeakKeyDictionary()


def body_groups(model: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray]:
    """(roots, group of each body) of a compiled model, cached per model.

    Returns:
        ``roots`` (G,) body ids that carry a group, in increasing order; ``group`` (nbody,)
        the root of each body's group, 0 for the world and what is welded to it.
    """
    found = _GROUPS.get(model)
    if found is not None:
        return found
    group = np.zeros(model.nbody, dtype=int)
    for b in range(1, model.nbody):  # parents come before their children
        own = int(model.body_jntnum[b]) > 0 or int(model.body_mocapid[b]) >= 0
        group[b] = b if own else group[int(model.body_parentid[b])]
    roots = np.unique(group[group > 0])
    found = (roots, group)
    _GROUPS[model] = found
    return found


_CARRIERS: weakref.WeakKeyDictionary[Any, np.ndarray] = weakref.WeakKeyDictionary()


def carriers(model: mujoco.MjModel) -> np.ndarray:
    """For each group of :func:`body_groups` (same order), the root of the moving group
    that carries it, or 0: a group whose every joint is a hinge or a ball turning about
    its root's origin keeps that origin fixed in its parent's group (the compressor's rod
    on its piston, a top's body on its ring), so a view can hang it there and send its
    orientation only. Cached per model."""
    found = _CARRIERS.get(model)
    if found is not None:
        return found
    roots, group = body_groups(model)
    turning = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_BALL))
    out = np.zeros(len(roots), dtype=int)
    for k, b in enumerate(roots):
        first, count = int(model.body_jntadr[b]), int(model.body_jntnum[b])
        joints = range(first, first + count)
        if count == 0 or int(model.body_mocapid[b]) >= 0:
            continue
        if not all(
            int(model.jnt_type[j]) in turning and not np.any(model.jnt_pos[j]) for j in joints
        ):
            continue
        out[k] = int(group[int(model.body_parentid[b])])
    _CARRIERS[model] = out
    return out


def geom_local_poses(model: mujoco.MjModel) -> np.ndarray:
    """Pose (x, y, z, w, qx, qy, qz) of every geom in its group's frame (in the world for
    the world's own geoms), from the model's reference configuration: a welded body keeps
    it whatever the joints do. Shape (ngeom, 7)."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    _, group = body_groups(model)
    out = np.zeros((model.ngeom, 7))
    inv, quat, pos = np.zeros(4), np.zeros(4), np.zeros(3)
    for g in range(model.ngeom):
        root = int(group[int(model.geom_bodyid[g])])
        mujoco.mju_mat2Quat(quat, np.asarray(data.geom_xmat[g], dtype=float))
        offset = np.asarray(data.geom_xpos[g], dtype=float) - data.xpos[root]
        mujoco.mju_negQuat(inv, np.asarray(data.xquat[root], dtype=float))
        mujoco.mju_rotVecQuat(pos, offset, inv)
        local = np.zeros(4)
        mujoco.mju_mulQuat(local, inv, quat)
        out[g, :3], out[g, 3:] = pos, local / np.linalg.norm(local)
    return out


@dataclass(frozen=True, eq=False)
class Picture:
    """The 3D content of one frame.

    Attributes:
        time: Simulated time drawn [s].
        model: The compiled model it was drawn from (a new one rebuilds the 3D nodes).
        roots: Bodies carrying a moving group (G,), as :func:`body_groups`.
        poses: World pose of each group's frame (G, 7): x, y, z [m], then w, qx, qy, qz.
        body_xpos: World position of every body's frame (nbody, 3) [m].
        body_xquat: World orientation (w, x, y, z) of every body's frame (nbody, 4).
        arrows: Start and end of each scene arrow (A, 2, 3) [m], the arrow's scale applied
            to its vector (NaN where the arrow's function gave no finite value).
        vectors: Each arrow's vector in world coordinates, in its own unit (A, 3).
        magnitudes: Norm of each arrow's vector, in the arrow's unit (A,).
        trail: The point a scene's trail follows [m] (3,), None without one.
    """

    time: float
    model: mujoco.MjModel
    roots: np.ndarray
    poses: np.ndarray
    body_xpos: np.ndarray
    body_xquat: np.ndarray
    arrows: np.ndarray
    vectors: np.ndarray
    magnitudes: np.ndarray
    trail: np.ndarray | None = None


_TWIN_DATA: weakref.WeakKeyDictionary[Any, mujoco.MjData] = weakref.WeakKeyDictionary()


def _posed(twin: mujoco.MjModel, data: mujoco.MjData) -> mujoco.MjData:
    """The twin's data at ``data``'s joint positions (its kinematics only)."""
    own = _TWIN_DATA.get(twin)
    if own is None:
        own = _TWIN_DATA[twin] = mujoco.MjData(twin)
    own.qpos[:] = data.qpos
    own.mocap_pos[:] = data.mocap_pos
    own.mocap_quat[:] = data.mocap_quat
    own.time = data.time
    mujoco.mj_kinematics(twin, own)
    return own


class TwinMismatch(ValueError):
    """A public twin whose moving groups differ from the simulated model's."""


def check_twin(model: mujoco.MjModel, twin: mujoco.MjModel) -> None:
    """Check that ``twin`` can be drawn with ``model``'s poses: the same bodies, moving
    on the same joints in the same groups (only shapes, masses and fixed offsets may
    differ, which is all a hidden parameter changes).

    Raises:
        TwinMismatch: naming what differs (never drawn then: the real shapes would leak).
    """
    if (twin.nbody, twin.njnt, twin.nq, twin.nmocap) != (
        model.nbody,
        model.njnt,
        model.nq,
        model.nmocap,
    ):
        raise TwinMismatch(
            f"public twin has {twin.nbody} bodies and {twin.njnt} joints, the model "
            f"{model.nbody} and {model.njnt}"
        )
    if not np.array_equal(body_groups(twin)[1], body_groups(model)[1]):
        raise TwinMismatch("public twin groups its bodies differently from the model")


def picture(
    snapshot: Snapshot,
    arrows: Sequence[ArrowSource] = (),
    *,
    trail: Callable[[Snapshot], Any] | None = None,
    shown: mujoco.MjModel | None = None,
) -> Picture:
    """Draw ``snapshot``: its groups' poses, ``arrows`` (after its forces were
    prepared when an arrow needs forces) and the point ``trail`` follows.

    Args:
        shown: A public twin of the model (:func:`check_twin`) whose shapes are drawn
            instead of the simulated ones, posed by the simulated motion: a challenge's
            hidden defect (a tilted disk, a heavy spot's place) then never reaches a
            browser, since the groups' poses do not depend on it.
    """
    model, data = snapshot.model, snapshot.data
    roots, _ = body_groups(model)
    if shown is not None:  # the twin posed by the simulated joints (its own fixed offsets)
        data = _posed(shown, data)
    poses = np.concatenate([data.xpos[roots], data.xquat[roots]], axis=1)
    ends = np.full((len(arrows), 2, 3), np.nan)
    vectors = np.full((len(arrows), 3), np.nan)
    for k, arrow in enumerate(arrows):
        origin, vector = arrow.fn(snapshot)
        o = np.asarray(origin, dtype=float)
        v = vectors[k] = np.asarray(vector, dtype=float)
        ends[k, 0], ends[k, 1] = o, o + arrow.scale * v
    sizes = np.sqrt((vectors * vectors).sum(axis=1))
    return Picture(
        float(data.time),
        model if shown is None else shown,
        roots,
        poses,
        np.array(data.xpos),
        np.array(data.xquat),
        ends,
        vectors,
        sizes,
        None if trail is None else np.asarray(trail(snapshot), dtype=float),
    )
