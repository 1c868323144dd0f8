"""MJCF geoms as shapes to draw: kinds, sizes, colours, poses and meshes, with no server.

The pure helpers (:func:`geom_shapes`, :func:`geom_pose`, :func:`capsule_mesh`,
:func:`mesh_arrays`) need no server and are tested on an inline MJCF; the
:class:`~sandbox.web.view3d.renderer.SceneRenderer` turns their output into nodes of one
client's scene. :func:`mechanism_size` sizes what is drawn around the mechanism (arrows,
markers, videos).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from sandbox.physics.picture import body_groups, carriers, geom_local_poses

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
            node = f"{body_frame(prefix, body, model)}/{i}_{name}"
            shapes.append(GeomShape(i, node, kind, size, rgba, True, mesh_id, body, local))
        else:
            shapes.append(GeomShape(i, f"{prefix}/{i}_{name}", kind, size, rgba, False, mesh_id))
    return shapes


def body_frame(prefix: str, body: int, model: mujoco.MjModel | None = None) -> str:
    """Scene-tree name of the frame that carries the geoms of a moving group (``body``:
    the group's root): under the frame of the group that carries it, when ``model`` says
    it is carried (:func:`~sandbox.physics.picture.carriers`: hanging there, it needs its
    orientation only, a message less a frame), else at the top of ``prefix``."""
    path = f"/body{body}"
    if model is not None:
        roots, _ = body_groups(model)
        index = {int(r): k for k, r in enumerate(roots)}
        carried = carriers(model)
        k = index.get(body)
        while k is not None and carried[k]:
            body = int(carried[k])
            path = f"/body{body}{path}"
            k = index.get(body)
    return f"{prefix}{path}"


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
