"""MJCF geoms -> viser scene nodes, created once per model and posed every frame.

The pure helpers (:func:`geom_shapes`, :func:`geom_pose`, :func:`capsule_mesh`,
:func:`mesh_arrays`) need no server and are tested on an inline MJCF; the
:class:`SceneRenderer` turns their output into nodes of one client's scene.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import viser

from sandbox.physics.picture import Picture, body_groups, geom_local_poses
from sandbox.web import wire
from sandbox.web.label_layout import LABEL_EM, PX_PER_SCALE, Camera, Rect, label_size

_T = mujoco.mjtGeom
KINDS: dict[int, str] = {
    int(_T.mjGEOM_PLANE): "plane",
    int(_T.mjGEOM_BOX): "box",
    int(_T.mjGEOM_SPHERE): "sphere",
    int(_T.mjGEOM_CAPSULE): "capsule",
    int(_T.mjGEOM_CYLINDER): "cylinder",
    int(_T.mjGEOM_ELLIPSOID): "ellipsoid",
    int(_T.mjGEOM_MESH): "mesh",
}
"""MuJoCo geom types drawn in the browser (height fields and SDFs are not)."""

HIDDEN_GROUP = 3
"""Geoms in this group or above are hidden, as in MuJoCo's viewer defaults."""

_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)

READABLE_PX = 12.0
"""A geom's label that slid more than this on the screen [px] since the labels were last
laid out (a quarter of a second) turns too fast to be read, and would sweep over the
other labels: it is hidden until its body slows down (a rotor's masses at 3000 tr/min
show when paused)."""

MARKER = 0.02
"""Smallest radius a moving sphere is drawn with, as a fraction of the mechanism's size
(a rotor's 6 mm correction masses would be 2 px dots on a projector); the physics keeps
its own size."""


def mechanism_size(model: mujoco.MjModel, data: mujoco.MjData | None = None) -> float:
    """Size [m] of the mechanism: the diagonal of the box around the geoms of the bodies
    not welded to the world (the world's own geoms, such as a floor, are left out); the
    model's extent when nothing moves.

    Args:
        model: Compiled model.
        data: State giving the geoms' positions (default: the model's reference pose).
    """
    if data is None:
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
    low, high = np.full(3, np.inf), np.full(3, -np.inf)
    for g in range(model.ngeom):
        body = int(model.geom_bodyid[g])
        if int(model.body_weldid[body]) == 0:
            continue
        r = float(model.geom_rbound[g])
        if not math.isfinite(r) or r <= 0:
            r = float(np.max(model.geom_size[g]))
        p = np.asarray(data.geom_xpos[g], dtype=float)
        if not np.isfinite(p).all():
            continue
        low, high = np.minimum(low, p - r), np.maximum(high, p + r)
    if not np.isfinite(low).all():
        return float(model.stat.extent) or 1.0
    size = float(np.linalg.norm(high - low))
    return size if size > 0 else float(model.stat.extent) or 1.0


@dataclass(frozen=True)
class GeomShape:
    """What to draw for one geom, independent of its pose.

    Attributes:
        geom_id: Index in the model.
        name: Scene-tree name of the node.
        kind: One of :data:`KINDS` values.
        size: Kind-specific dimensions [m]: box (dx, dy, dz) full edges; sphere (r,);
            capsule (r, half_length); cylinder (r, height); ellipsoid (a, b, c) radii;
            plane (width, depth, cell); mesh (vertex count, face count, checksum) so
            that an edited mesh compares unequal (vertices come from the model).
        rgba: Colour and opacity in [0, 1].
        moving: False for geoms welded to the world (posed once).
        mesh_id: Mesh index for ``kind == "mesh"``, else -1.
        body: Root body of the rigid group carrying a moving geom (its node is a child of
            the group's frame: :func:`sandbox.physics.picture.body_groups`), else -1.
        local: Pose (x, y, z, w, qx, qy, qz) of a moving geom in its group's frame.
    """

    geom_id: int
    name: str
    kind: str
    size: tuple[float, ...]
    rgba: tuple[float, float, float, float]
    moving: bool
    mesh_id: int = -1
    body: int = -1
    local: tuple[float, ...] = ()

    @property
    def rgb255(self) -> tuple[int, int, int]:
        """Colour as 0-255 integers."""
        r, g, b, _ = self.rgba
        return (round(255 * r), round(255 * g), round(255 * b))

    @property
    def opacity(self) -> float | None:
        """Opacity for viser (None when opaque)."""
        return None if self.rgba[3] >= 1.0 else float(self.rgba[3])


def _rgba(model: mujoco.MjModel, i: int) -> tuple[float, float, float, float]:
    rgba = tuple(float(x) for x in model.geom_rgba[i])
    mat = int(model.geom_matid[i])
    if mat >= 0 and np.allclose(rgba, _DEFAULT_RGBA):
        rgba = tuple(float(x) for x in model.mat_rgba[mat])
    return rgba  # type: ignore[return-value]


def _size(kind: str, s: np.ndarray, extent: float) -> tuple[float, ...]:
    if kind == "box":
        return (2 * s[0], 2 * s[1], 2 * s[2])
    if kind == "sphere":
        return (s[0],)
    if kind == "capsule":
        return (s[0], s[1])
    if kind == "cylinder":
        return (s[0], 2 * s[1])
    if kind == "ellipsoid":
        return (s[0], s[1], s[2])
    if kind == "plane":  # size 0 means infinite: draw a few model extents
        width = 2 * s[0] if s[0] > 0 else 4 * extent
        depth = 2 * s[1] if s[1] > 0 else 4 * extent
        cell = s[2] if s[2] > 0 else max(width, depth) / 20
        return (width, depth, cell)
    return ()


def geom_shapes(model: mujoco.MjModel, *, prefix: str = "/model") -> list[GeomShape]:
    """Shapes of the visible geoms: drawn types, alpha > 0 and group < 3.

    Args:
        model: Compiled model.
        prefix: Scene-tree folder of the nodes.
    """
    shapes = []
    extent = float(model.stat.extent) or 1.0
    marker = MARKER * mechanism_size(model)
    _, groups = body_groups(model)
    locals_ = geom_local_poses(model)
    for i in range(model.ngeom):
        kind = KINDS.get(int(model.geom_type[i]))
        rgba = _rgba(model, i)
        if kind is None or rgba[3] <= 0.0 or int(model.geom_group[i]) >= HIDDEN_GROUP:
            continue
        body = int(groups[int(model.geom_bodyid[i])])
        moving = body != 0
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) or f"geom{i}"
        size = tuple(float(x) for x in _size(kind, model.geom_size[i], extent))
        mesh_id = int(model.geom_dataid[i]) if kind == "mesh" else -1
        if kind == "mesh":
            verts, faces = mesh_arrays(model, mesh_id)
            size = (float(len(verts)), float(len(faces)), float(np.abs(verts).sum()))
        if moving and kind == "sphere" and size[0] < marker:
            size = (marker,)
        if moving:
            local = tuple(float(x) for x in locals_[i])
            node = f"{body_frame(prefix, body)}/{i}_{name}"
            shapes.append(GeomShape(i, node, kind, size, rgba, True, mesh_id, body, local))
        else:
            shapes.append(GeomShape(i, f"{prefix}/{i}_{name}", kind, size, rgba, False, mesh_id))
    return shapes


def body_frame(prefix: str, body: int) -> str:
    """Scene-tree name of the frame that carries the geoms of a moving group (``body``:
    the group's root)."""
    return f"{prefix}/body{body}"


def mat_to_wxyz(mat: np.ndarray) -> np.ndarray:
    """Quaternion (w, x, y, z) of a row-major 3x3 rotation matrix (9 numbers)."""
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.asarray(mat, dtype=float).reshape(9))
    return quat


def geom_pose(data: mujoco.MjData, geom_id: int) -> tuple[np.ndarray, np.ndarray]:
    """World position [m] and orientation (w, x, y, z) of a geom."""
    return data.geom_xpos[geom_id].copy(), mat_to_wxyz(data.geom_xmat[geom_id])


def mesh_arrays(model: mujoco.MjModel, mesh_id: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) float32 [m] and triangles (F, 3) uint32 of a compiled mesh."""
    v0, nv = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
    f0, nf = int(model.mesh_faceadr[mesh_id]), int(model.mesh_facenum[mesh_id])
    verts = np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=np.float32)
    faces = np.asarray(model.mesh_face[f0 : f0 + nf], dtype=np.uint32)
    return verts, faces


def capsule_mesh(
    radius: float, half_length: float, *, segments: int = 24, rings: int = 6
) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of a capsule along z: a cylinder of ``2 half_length`` with two caps.

    Returns:
        Vertices (V, 3) float32 [m] and triangles (F, 3) uint32, outward facing.
    """
    # Latitude circles from the bottom pole to the top pole; the two equators are
    # shifted by -/+ half_length, which makes the cylindrical part.
    lat = []
    for k in range(1, rings + 1):  # bottom cap, pole excluded
        phi = -math.pi / 2 + math.pi / 2 * k / rings
        lat.append((phi, -half_length))
    for k in range(0, rings):  # top cap, pole excluded
        phi = math.pi / 2 * k / rings
        lat.append((phi, half_length))
    theta = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    verts = [(0.0, 0.0, -half_length - radius)]
    for phi, dz in lat:
        r, z = radius * math.cos(phi), radius * math.sin(phi) + dz
        verts += [(r * math.cos(t), r * math.sin(t), z) for t in theta]
    verts.append((0.0, 0.0, half_length + radius))
    faces = []
    n, top = len(lat), len(verts) - 1

    def ring(k: int, j: int) -> int:
        return 1 + k * segments + j % segments

    for j in range(segments):
        faces.append((0, ring(0, j + 1), ring(0, j)))
        faces.append((top, ring(n - 1, j), ring(n - 1, j + 1)))
        for k in range(n - 1):
            a, b = ring(k, j), ring(k, j + 1)
            c, d = ring(k + 1, j), ring(k + 1, j + 1)
            faces += [(a, b, d), (a, d, c)]
    return np.asarray(verts, dtype=np.float32), np.asarray(faces, dtype=np.uint32)


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
    one per geom, nor per welded body), and nothing for a still one.

    Args:
        scene: A viser ``SceneApi`` (``client.scene``, or ``server.scene`` for all).
        prefix: Scene-tree folder of the nodes.
    """

    def __init__(self, scene: viser.SceneApi, *, prefix: str = "/model") -> None:
        self.scene = scene
        self.prefix = prefix
        self.model: mujoco.MjModel | None = None
        self.nodes: dict[int, tuple[GeomShape, viser.SceneNodeHandle]] = {}
        self.bodies: dict[int, viser.FrameHandle] = {}
        self.labels: dict[int, tuple[str, viser.LabelHandle, int]] = {}  # geom: text, node, group
        self._sent = np.zeros((0, 7))  # last pose sent of each group of ``_roots``
        self._roots = np.zeros(0, dtype=int)
        self._turned = np.zeros(0)  # angle turned by each group since label_boxes [rad]
        self._move = 0.0  # POSE_MOVE times the mechanism's size [m]
        self.label_scale = LABEL_EM * 16 / PX_PER_SCALE  # viser's font_screen_scale
        self.messages = 0  # pose messages queued so far (the counted guard of the tests)

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
        if len(roots) == 0:
            return
        sent = self._sent
        ok = np.isfinite(poses).all(axis=1)
        moved = ~(np.abs(poses[:, :3] - sent[:, :3]).max(axis=1) <= self._move)  # NaN: never sent
        # |q·q'| = cos(θ/2) for the rotation θ between two orientations
        dots = np.abs((poses[:, 3:] * sent[:, 3:]).sum(axis=1))
        turned = ~(1.0 - dots <= 0.125 * POSE_MOVE**2)
        if self.labels:  # how far the labels rode: 2 acos|q·q'| per sent turn
            angle = 2.0 * np.arccos(np.fmin(dots, 1.0))  # dots >= 0; fmin(NaN, 1) = 1
            self._turned += np.where(turned & ok, angle, 0.0)
        for k in np.flatnonzero(ok & (moved | turned)):
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

    def world_pose(self, geom_id: int) -> tuple[np.ndarray, np.ndarray]:
        """Where the browser draws a geom: world position [m] and (w, x, y, z)."""
        shape, node = self.nodes[geom_id]
        if not shape.moving:
            return np.asarray(node.position, float), np.asarray(node.wxyz, float)
        frame = self.bodies[shape.body]
        quat = np.zeros(4)
        mujoco.mju_mulQuat(quat, np.asarray(frame.wxyz, float), np.asarray(shape.local[3:]))
        offset = np.zeros(3)
        mujoco.mju_rotVecQuat(offset, np.asarray(shape.local[:3]), np.asarray(frame.wxyz, float))
        return np.asarray(frame.position, float) + offset, quat

    def label_geoms(self, texts: dict[int, str]) -> None:
        """Labels riding on moving geoms (``texts``: geom -> words), children of their
        group's frame: they move with it and cost no message a frame. Labels of geoms no
        longer given are removed; a geom on no moving group gets none."""
        model = self.model
        for g in [g for g in self.labels if g not in texts]:
            self.labels.pop(g)[1].remove()
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
                f"{body_frame(self.prefix, root)}/label{g}",
                text,
                position=np.array(local[g, :3]),
                anchor="bottom-center",
                font_screen_scale=self.label_scale,
            )
            self.labels[g] = (text, label, root)

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
            frame = self.bodies.get(root)
            if frame is None:
                continue
            wxyz = np.asarray(frame.wxyz, dtype=float)
            local = np.asarray(label.position, dtype=float)
            world = np.zeros(3)
            mujoco.mju_rotVecQuat(world, local, wxyz)
            x, y, depth = camera.project(np.asarray(frame.position, dtype=float) + world)
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
        wanted = {s.geom_id: s for s in geom_shapes(model, prefix=self.prefix)}
        for gid in list(self.nodes):
            shape, node = self.nodes[gid]
            if wanted.get(gid) != shape:
                node.remove()
                del self.nodes[gid]
        moving = {s.body for s in wanted.values() if s.moving}
        for body in [b for b in self.bodies if b not in moving or b >= model.nbody]:
            self.bodies.pop(body).remove()
            for g in [g for g, (_, _, root) in self.labels.items() if root == body]:
                del self.labels[g]  # removed with its frame
        for body in sorted(moving - set(self.bodies)):
            self.bodies[body] = self.scene.add_frame(body_frame(self.prefix, body), show_axes=False)
        self._sent[:] = np.nan  # the new frames know no pose yet
        self._move = POSE_MOVE * mechanism_size(model)
        fresh = []
        data = None
        for gid, shape in wanted.items():
            if gid not in self.nodes:
                node = add_node(self.scene, model, shape)
                self.nodes[gid] = (shape, node)
                fresh.append(gid)
                if not shape.moving:  # posed once, where the world holds it
                    if data is None:
                        data = mujoco.MjData(model)
                        mujoco.mj_kinematics(model, data)
                    pos, wxyz = geom_pose(data, gid)
                    if np.isfinite(pos).all() and np.isfinite(wxyz).all():
                        node.position = pos
                        node.wxyz = wxyz
        return fresh

    def clear(self) -> None:
        """Remove every node."""
        for _, node in self.nodes.values():
            node.remove()
        for _, label, _ in self.labels.values():
            label.remove()
        for frame in self.bodies.values():
            frame.remove()
        self.nodes.clear()
        self.labels.clear()
        self.bodies.clear()
        self._sent = np.zeros((0, 7))
        self._roots = np.zeros(0, dtype=int)
        self.model = None
