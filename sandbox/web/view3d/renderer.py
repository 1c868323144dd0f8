"""MJCF geoms -> viser scene nodes, created once per model and posed every frame.

The pure helpers (:func:`~sandbox.web.view3d.geoms.geom_shapes`,
:func:`~sandbox.web.view3d.geoms.geom_pose`, :func:`~sandbox.web.view3d.geoms.capsule_mesh`,
:func:`~sandbox.web.view3d.geoms.mesh_arrays`) need no server and are tested on an inline
MJCF (:mod:`sandbox.web.view3d.geoms`); the :class:`SceneRenderer` turns their output into
nodes of one client's scene.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np
import viser

from sandbox.physics.picture import Picture, body_groups, carriers, geom_local_poses
from sandbox.web.client import wire
from sandbox.web.view3d.batches import (
    Batch,
    batches,
    instance_poses,
    instance_scale,
    linear_colors,
    unit_mesh,
)
from sandbox.web.view3d.geoms import (
    GeomShape,
    body_frame,
    capsule_mesh,
    geom_pose,
    geom_shapes,
    mechanism_size,
    mesh_arrays,
)
from sandbox.web.view3d.label_layout import LABEL_EM, PX_PER_SCALE, Camera, Rect, label_size

READABLE_PX = 12.0
"""A geom's label that slid more than this on the screen [px] since the labels were last
laid out (a quarter of a second) turns too fast to be read, and would sweep over the
other labels: it is hidden until its body slows down (a rotor's masses at 3000 tr/min
show when paused)."""


def add_node(
    scene: viser.SceneApi, model: mujoco.MjModel, shape: GeomShape
) -> viser.SceneNodeHandle:
    """Create the viser node of one geom in ``scene`` (a viser ``SceneApi``)."""
    color, opacity, name = shape.rgb255, shape.opacity, shape.name
    common: dict[str, Any] = {"opacity": opacity} if opacity is not None else {}
    if shape.moving:
        common.update(position=shape.local[:3], wxyz=shape.local[3:])
    if shape.kind == "box":
        return scene.add_box(name, color=color, dimensions=_triple(shape.size), **common)
    if shape.kind == "sphere":
        return scene.add_icosphere(name, radius=shape.size[0], color=color, **common)
    if shape.kind == "ellipsoid":
        return scene.add_icosphere(
            name, radius=1.0, color=color, scale=_triple(shape.size), **common
        )
    if shape.kind == "cylinder":
        r, h = shape.size
        return scene.add_cylinder(name, radius=r, height=h, color=color, **common)
    if shape.kind == "capsule":
        verts, faces = capsule_mesh(*shape.size)
        return scene.add_mesh_simple(name, verts, faces, color=color, **common)
    if shape.kind == "mesh":
        verts, faces = mesh_arrays(model, shape.mesh_id)
        return scene.add_mesh_simple(name, verts, faces, color=color, flat_shading=True, **common)
    if shape.kind == "plane":
        width, depth, cell = shape.size
        return scene.add_grid(
            name,
            width=width,
            height=depth,
            plane="xy",
            cell_size=cell,
            section_size=cell * 5,
            plane_color=color,
            plane_opacity=shape.rgba[3] * 0.5,
            **{k: v for k, v in common.items() if k in ("position", "wxyz")},
        )
    raise ValueError(f"cannot draw geom kind {shape.kind!r}")


def _in_carriers(poses: np.ndarray, carrier: np.ndarray) -> np.ndarray:
    """``poses`` (G, 7: x, y, z, w, qx, qy, qz in the world) with each carried group's
    pose expressed in its carrier's frame (``carrier``: the carrier's index, -1 for none):
    q = q_c⁻¹ q_k, p = q_c⁻¹ (p_k − p_c) q_c."""
    if len(carrier) != len(poses) or not (carrier >= 0).any():
        return poses
    out = poses.copy()
    inv, pos, quat = np.zeros(4), np.zeros(3), np.zeros(4)
    for k in np.flatnonzero(carrier >= 0):
        c = poses[int(carrier[k])]
        mujoco.mju_negQuat(inv, c[3:])
        mujoco.mju_rotVecQuat(pos, poses[k, :3] - c[:3], inv)
        mujoco.mju_mulQuat(quat, inv, poses[k, 3:])
        out[k, :3], out[k, 3:] = pos, quat
    return out


def add_batch(
    scene: viser.SceneApi, model: mujoco.MjModel, name: str, batch: Batch
) -> viser.SceneNodeHandle:
    """Create the node drawing a batch's geoms (:mod:`sandbox.web.view3d.batches`) in
    ``scene``, its instances at their pose in their group (sent again on the first frame)."""
    first = batch.shapes[0]
    arrays = unit_mesh(first)
    if arrays is None:
        verts, faces = mesh_arrays(model, first.mesh_id)
        arrays = (np.asarray(verts, np.float32), np.asarray(faces, np.uint32))
    return scene.add_batched_meshes_simple(
        name,
        arrays[0],
        arrays[1],
        batched_wxyzs=batch.local[:, 3:].astype(np.float32),
        batched_positions=batch.local[:, :3].astype(np.float32),
        batched_scales=np.array([instance_scale(s) for s in batch.shapes], np.float32),
        batched_colors=linear_colors(batch.shapes),
        lod="off",
        flat_shading=first.kind in ("box", "mesh"),
    )


def _triple(size: tuple[float, ...]) -> tuple[float, float, float]:
    x, y, z = size
    return (x, y, z)


POSE_MOVE = 1e-4
"""Smallest move of a group worth a message, as a fraction of the mechanism's size (a
tenth of a pixel when it spans a 1000-pixel view), in position or in angle [rad]."""


class SceneRenderer:
    """Keeps one client's scene nodes in step with a model and its drawn pictures.

    Moving geoms are children of their group's frame, placed once at their pose in the
    group; every frame then sends a position and an orientation per group that moved (not
    one per geom, nor per welded body), and nothing for a still one. A group turning about
    a point of another (:func:`~sandbox.physics.picture.carriers`: a rod on its piston)
    hangs under that group's frame: its pose is sent in it, so its position never changes
    and only its orientation is sent.

    Opaque geoms of one kind that several groups carry (the engine's four pistons and four
    rods: :mod:`sandbox.web.view3d.batches`) are the instances of one batched node, posed
    in the world by one message a frame for all of them; a group whose geoms are all
    batched sends no pose of its own, unless a label rides on it or a group it carries
    needs its frame.

    Args:
        scene: A viser ``SceneApi`` (``client.scene``, or ``server.scene`` for all).
        prefix: Scene-tree folder of the nodes.
    """

    def __init__(self, scene: viser.SceneApi, *, prefix: str = "/model") -> None:
        self.scene = scene
        self.prefix = prefix
        self.model: mujoco.MjModel | None = None
        self.nodes: dict[int, tuple[GeomShape, viser.SceneNodeHandle]] = {}
        self._fixed: dict[int, np.ndarray] = {}  # a fixed node's pose as last set (x, wxyz)
        self.bodies: dict[int, viser.FrameHandle] = {}
        self._paths: dict[int, str] = {}  # scene-tree name of each group's frame
        self.labels: dict[int, tuple[str, viser.LabelHandle, int]] = {}  # geom: text, node, group
        self._sent = np.zeros((0, 7))  # last pose sent of each group of ``_roots``
        self._roots = np.zeros(0, dtype=int)
        self._carrier = np.zeros(0, dtype=int)  # index in _roots of each group's carrier, -1
        self._world = np.zeros((0, 7))  # the groups' last world poses drawn
        self._turned = np.zeros(0)  # angle turned by each group since label_boxes [rad]
        self._move = 0.0  # POSE_MOVE times the mechanism's size [m]
        self.label_scale = LABEL_EM * 16 / PX_PER_SCALE  # viser's font_screen_scale
        self.messages = 0  # pose messages queued so far (the counted guard of the tests)
        self.batched: dict[int, GeomShape] = {}  # geoms drawn as instances of a batch
        self._batches: list[tuple[Batch, viser.SceneNodeHandle]] = []
        self._bsent = np.zeros((0, 7))  # world pose of each group last sent in the batches
        self._framed = np.zeros(0, dtype=bool)  # groups whose frame holds something
        self._reframe = True  # labels or nodes changed: which frames to pose is recomputed

    def sync(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Draw ``data`` (its bodies' poses up to date): rebuild the nodes if the model
        object changed, then pose the groups that moved."""
        roots, _ = body_groups(model)
        poses = np.concatenate([data.xpos[roots], data.xquat[roots]], axis=1)
        self.show(model, roots, poses)

    def draw(self, picture: Picture) -> None:
        """Draw a frame's picture (:func:`sandbox.physics.picture.picture`)."""
        self.show(picture.model, picture.roots, picture.poses)

    def show(self, model: mujoco.MjModel, roots: np.ndarray, poses: np.ndarray) -> None:
        """Rebuild changed nodes when the model object changed, then send the pose of each
        group (``roots``: their root bodies; ``poses``: x, y, z, w, qx, qy, qz) that moved
        by more than :data:`POSE_MOVE`."""
        if model is not self.model:
            self._rebuild(model)
            self.model = model
        if roots.shape != self._roots.shape or (roots != self._roots).any():
            self._roots = roots.copy()
            self._sent = np.full((len(roots), 7), np.nan)
            self._turned = np.zeros(len(roots))
            index = {int(r): k for k, r in enumerate(roots)}
            carried = carriers(model) if len(roots) == len(body_groups(model)[0]) else None
            self._carrier = np.array(
                [index.get(int(c), -1) if carried is not None and c else -1
                 for c in (carried if carried is not None else np.zeros(len(roots)))],
                dtype=int,
            )  # fmt: skip
            self._bsent = np.full((len(roots), 7), np.nan)
            self._reframe = True
        if len(roots) == 0:
            return
        if self._reframe:
            self._frames_to_pose()
        self._world = poses
        if self._batches:
            self._pose_batches(poses)
        poses = _in_carriers(poses, np.where(self._framed, self._carrier, -1))
        sent = self._sent
        ok = np.isfinite(poses).all(axis=1)
        moved = ~(np.abs(poses[:, :3] - sent[:, :3]).max(axis=1) <= self._move)  # NaN: never sent
        # |q·q'| = cos(θ/2) for the rotation θ between two orientations
        dots = np.abs((poses[:, 3:] * sent[:, 3:]).sum(axis=1))
        turned = ~(1.0 - dots <= 0.125 * POSE_MOVE**2)
        if self.labels:  # how far the labels rode: 2 acos|q·q'| per sent turn
            angle = 2.0 * np.arccos(np.fmin(dots, 1.0))  # dots >= 0; fmin(NaN, 1) = 1
            self._turned += np.where(turned & ok, angle, 0.0)
        for k in np.flatnonzero(ok & (moved | turned) & self._framed):
            frame = self.bodies.get(int(roots[k]))
            if frame is None:
                continue
            if moved[k]:
                wire.set_position(frame, poses[k, :3])
                sent[k, :3] = poses[k, :3]
                self.messages += 1
            if turned[k]:
                wire.set_orientation(frame, poses[k, 3:])
                sent[k, 3:] = poses[k, 3:]
                self.messages += 1

    def _frames_to_pose(self) -> None:
        """Which groups' frames hold something (a geom's node, a label, or a carried group
        whose frame does): only those are posed. A frame that now needs its pose gets it
        on this frame."""
        roots = self._roots
        holding = {s.body for s, _ in self.nodes.values() if s.moving}
        holding |= {root for _, _, root in self.labels.values()}
        framed = np.array([int(r) in holding for r in roots], dtype=bool)
        if len(self._carrier) == len(roots):
            for k in np.flatnonzero(framed):  # a carrier chain is short: walk it up
                c = int(self._carrier[k])
                while c >= 0 and not framed[c]:
                    framed[c] = True
                    c = int(self._carrier[c])
        if len(self._framed) == len(framed):
            self._sent[framed & ~self._framed] = np.nan
        self._framed = framed
        self._reframe = False

    def _pose_batches(self, poses: np.ndarray) -> None:
        """Send the instances' world poses of each batch one of whose groups moved by more
        than :data:`POSE_MOVE` (``poses``: the groups' world poses)."""
        sent = self._bsent
        ok = np.isfinite(poses).all(axis=1)
        moved = ~(np.abs(poses[:, :3] - sent[:, :3]).max(axis=1) <= self._move)
        dots = np.abs((poses[:, 3:] * sent[:, 3:]).sum(axis=1))
        changed = ok & (moved | ~(1.0 - dots <= 0.125 * POSE_MOVE**2))
        if not changed.any():
            return
        for batch, node in self._batches:
            groups = batch.groups
            if not changed[groups].any() or not ok[groups].all():
                continue
            positions, wxyzs = instance_poses(batch, poses)
            wire.set_props(node, batched_positions=positions, batched_wxyzs=wxyzs)
            self.messages += 1
        sent[changed] = poses[changed]

    def _frame_world(self, root: int) -> tuple[np.ndarray, np.ndarray]:
        """World position and (w, x, y, z) of a group's frame, as last drawn."""
        hits = np.flatnonzero(self._roots == root)
        if hits.size and len(self._world) == len(self._roots):
            pose = self._world[int(hits[0])]
            return np.asarray(pose[:3], float), np.asarray(pose[3:], float)
        frame = self.bodies[root]
        return np.asarray(frame.position, float), np.asarray(frame.wxyz, float)

    def world_pose(self, geom_id: int) -> tuple[np.ndarray, np.ndarray]:
        """Where the browser draws a geom: world position [m] and (w, x, y, z)."""
        if geom_id in self.batched:
            shape, node = self.batched[geom_id], None
        else:
            shape, node = self.nodes[geom_id]
        if node is not None and not shape.moving:
            return np.asarray(node.position, float), np.asarray(node.wxyz, float)
        position, wxyz = self._frame_world(shape.body)
        quat = np.zeros(4)
        mujoco.mju_mulQuat(quat, wxyz, np.asarray(shape.local[3:]))
        offset = np.zeros(3)
        mujoco.mju_rotVecQuat(offset, np.asarray(shape.local[:3]), wxyz)
        return position + offset, quat

    def label_geoms(self, texts: dict[int, str]) -> None:
        """Labels riding on moving geoms (``texts``: geom -> words), children of their
        group's frame: they move with it and cost no message a frame. Labels of geoms no
        longer given are removed; a geom on no moving group gets none."""
        model = self.model
        for g in [g for g in self.labels if g not in texts]:
            self.labels.pop(g)[1].remove()
            self._reframe = True
        if model is None:
            return
        _, groups = body_groups(model)
        local = geom_local_poses(model)
        for g, text in texts.items():
            if not 0 <= g < model.ngeom:
                continue
            root = int(groups[int(model.geom_bodyid[g])])
            if root not in self.bodies:
                continue
            old = self.labels.get(g)
            if old is not None and old[2] == root:
                if old[0] != text:
                    old[1].text = text
                    self.labels[g] = (text, old[1], root)
                continue
            if old is not None:
                old[1].remove()
            label = self.scene.add_label(
                f"{self._paths.get(root) or body_frame(self.prefix, root)}/label{g}",
                text,
                position=np.array(local[g, :3]),
                anchor="bottom-center",
                font_screen_scale=self.label_scale,
            )
            self.labels[g] = (text, label, root)
            self._reframe = True

    def set_label_scale(self, scale: float) -> None:
        """Size of the geoms' labels (viser's ``font_screen_scale``: 12 px per unit),
        following the page's text size."""
        if not (math.isfinite(scale) and scale > 0) or scale == self.label_scale:
            return
        self.label_scale = float(scale)
        for _, label, _ in self.labels.values():
            label.font_screen_scale = self.label_scale

    def label_boxes(self, camera: Camera, em: float) -> list[Rect]:
        """Where the geoms' labels are on the screen [px] until the next layout: each
        label's box where its group now holds it, grown by how far it slid since the last
        call. A label that slid more than :data:`READABLE_PX` is hidden (and has no box):
        its body turns too fast for it to be read."""
        boxes: list[Rect] = []
        index = {int(root): k for k, root in enumerate(self._roots)}
        for text, label, root in self.labels.values():
            if self.bodies.get(root) is None:
                continue
            position, wxyz = self._frame_world(root)
            local = np.asarray(label.position, dtype=float)
            world = np.zeros(3)
            mujoco.mju_rotVecQuat(world, local, wxyz)
            x, y, depth = camera.project(position + world)
            if not math.isfinite(x):
                continue
            k = index.get(int(root))
            turned = float(self._turned[k]) if k is not None else 0.0
            slid = turned * float(np.linalg.norm(local)) * camera.focal / depth
            readable = slid <= READABLE_PX
            if label.visible != readable:
                label.visible = readable
                self.messages += 1
            if readable:
                width, height = label_size(text, em)
                half = width / 2 + slid
                boxes.append((x - half, y - height - slid, x + half, y + slid))
        self._turned[:] = 0.0
        return boxes

    def _rebuild(self, model: mujoco.MjModel) -> list[int]:
        """Keep nodes whose shape is unchanged, replace the others; returns new ids."""
        shapes = geom_shapes(model, prefix=self.prefix)
        paths = {b: body_frame(self.prefix, b, model) for b in {s.body for s in shapes if s.moving}}
        if any(self._paths.get(b, paths[b]) != paths[b] for b in paths if b in self.bodies):
            self.clear()  # a group hangs elsewhere now: every node made again
        self._set_batches(model, batches(shapes, body_groups(model)[0]))
        wanted = {s.geom_id: s for s in shapes if s.geom_id not in self.batched}
        for gid in list(self.nodes):
            shape, node = self.nodes[gid]
            if wanted.get(gid) != shape:
                node.remove()
                del self.nodes[gid]
                self._fixed.pop(gid, None)
        moving = {s.body for s in shapes if s.moving}  # batched groups too: labels hang there
        gone = [b for b in self.bodies if b not in moving or b >= model.nbody]
        for body in sorted(gone, key=lambda b: -self._paths.get(b, "").count("/")):
            frame = self.bodies.pop(body)  # what hangs under it first: it goes with it
            self._paths.pop(body, None)
            frame.remove()
            for g in [g for g, (_, _, root) in self.labels.items() if root == body]:
                del self.labels[g]  # removed with its frame
        for body in sorted(moving - set(self.bodies)):  # a carrier before what it carries
            self._paths[body] = paths[body]
            self.bodies[body] = self.scene.add_frame(paths[body], show_axes=False)
        self._sent[:] = np.nan  # the new frames know no pose yet
        self._bsent[:] = np.nan
        self._reframe = True
        self._move = POSE_MOVE * mechanism_size(model)
        fresh = []
        data = None
        for gid, shape in wanted.items():
            if gid not in self.nodes:
                self.nodes[gid] = (shape, add_node(self.scene, model, shape))
                fresh.append(gid)
            if shape.moving:
                continue
            # posed where the world holds it, again at each rebuild: a kept node's shape is
            # the same, yet its fixed body may sit elsewhere now (the engine cut to two
            # cylinders: its sleeves' bodies move in)
            if data is None:
                data = mujoco.MjData(model)
                mujoco.mj_kinematics(model, data)
            pos, wxyz = geom_pose(data, gid)
            pose = np.concatenate([pos, wxyz])
            posed = self._fixed.get(gid)
            if np.isfinite(pose).all() and (posed is None or not np.allclose(posed, pose)):
                node = self.nodes[gid][1]
                node.position = pos
                node.wxyz = wxyz
                self._fixed[gid] = pose
        return fresh

    def _set_batches(self, model: mujoco.MjModel, wanted: list[Batch]) -> None:
        """Draw ``wanted`` batches: kept when they are the same geoms as drawn, else every
        batch node is made again (a model edit is rare; a batch is one message)."""
        if [(b.key, b.shapes) for b in wanted] == [(b.key, b.shapes) for b, _ in self._batches]:
            self._batches = [(b, node) for b, (_, node) in zip(wanted, self._batches, strict=True)]
            return  # the same nodes; the groups' indices may have moved
        for _, node in self._batches:
            node.remove()
        self._batches = [
            (b, add_batch(self.scene, model, f"{self.prefix}/batch{k}", b))
            for k, b in enumerate(wanted)
        ]
        self.batched = {s.geom_id: s for b in wanted for s in b.shapes}

    def clear(self) -> None:
        """Remove every node."""
        for _, node in self._batches:
            node.remove()
        self._batches = []
        self.batched = {}
        for _, node in self.nodes.values():
            node.remove()
        for _, label, _ in self.labels.values():
            label.remove()
        for frame in self.bodies.values():
            frame.remove()
        self.nodes.clear()
        self._fixed.clear()
        self.labels.clear()
        self.bodies.clear()
        self._paths.clear()
        self._sent = np.zeros((0, 7))
        self._bsent = np.zeros((0, 7))
        self._roots = np.zeros(0, dtype=int)
        self._framed = np.zeros(0, dtype=bool)
        self.model = None
