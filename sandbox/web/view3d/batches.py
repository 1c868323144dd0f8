"""Moving geoms of one kind spread over several groups, drawn as one batched node whose
instances move in one message a frame (the engine's four pistons, its four rods), instead
of one pose message per group.

viser serialises each scene message in Python (about 35–40 µs of a worker's time on the
classroom benchmark): a mechanism of nine moving groups paid nine messages a frame where
the rotor pays one. A batched node (viser's ``add_batched_meshes_simple``) draws many
instances of one mesh, each with its pose, scale, colour and opacity, and moves them all
with one ``SceneNodeUpdateMessage``. Geoms of a kind that several groups carry are drawn
that way: boxes, cylinders, spheres and ellipsoids as scaled instances of one unit mesh;
capsules and meshes when they are the same size. A kind only one group carries keeps its
geoms under the group's frame (one pose a frame for all of them, as before).

Pure helpers: the unit meshes, which shapes are batched, and the instances' world poses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from sandbox.web.view3d.geoms import GeomShape, capsule_mesh

SEGMENTS = 32
"""Sides of a cylinder's mesh and meridians of a sphere's (viser's own primitives use
about as many)."""

SCALED = ("box", "cylinder", "sphere", "ellipsoid")
"""Kinds drawn as a unit mesh scaled per instance (one batch for every size)."""


MIN_SAVED = 4
"""Fewest pose messages a frame batching must save: posing a batch (the groups' moves,
the instances' poses, arrays on the wire) costs about what two pose messages cost
(measured on the robot axis: its carriage and arm as one batch took 86 µs a frame to
draw where their two poses took 60; the inline four's 8 groups as 2 batches, 150 against
176)."""


def unit_box() -> tuple[np.ndarray, np.ndarray]:
    """A cube of edge 1 centred on the origin, four vertices a face (flat shading)."""
    verts: list[list[float]] = []
    faces: list[tuple[int, int, int]] = []
    for axis in range(3):
        for sign in (-0.5, 0.5):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(verts)
            for a, b in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = sign, a, b
                verts.append(p)
            quad = [(base, base + 1, base + 2), (base, base + 2, base + 3)]
            faces += quad if sign > 0 else [(i, k, j) for i, j, k in quad]
    return np.array(verts, dtype=np.float32), np.array(faces, dtype=np.uint32)


def unit_cylinder(segments: int = SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """A cylinder of radius 1 and height 1 along z, centred: smooth sides, flat caps (the
    caps' rims are vertices of their own)."""
    angles = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    ring = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    verts: list[list[float]] = []
    faces: list[tuple[int, int, int]] = []
    for z in (-0.5, 0.5):  # side: two rings
        verts += [[x, y, z] for x, y in ring]
    for i in range(segments):
        j = (i + 1) % segments
        faces += [(i, j, segments + j), (i, segments + j, segments + i)]
    for z, up in ((-0.5, False), (0.5, True)):  # caps: a centre and a ring each
        centre = len(verts)
        verts.append([0.0, 0.0, z])
        verts += [[x, y, z] for x, y in ring]
        for i in range(segments):
            a, b = centre + 1 + i, centre + 1 + (i + 1) % segments
            faces.append((centre, a, b) if up else (centre, b, a))
    return np.array(verts, dtype=np.float32), np.array(faces, dtype=np.uint32)


def unit_sphere(segments: int = SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """A sphere of radius 1: ``segments`` meridians, half as many parallels."""
    rows = max(4, segments // 2)
    verts = [[0.0, 0.0, 1.0]]
    for r in range(1, rows):
        polar = math.pi * r / rows
        for m in range(segments):
            azimuth = 2 * math.pi * m / segments
            s = math.sin(polar)
            verts.append([s * math.cos(azimuth), s * math.sin(azimuth), math.cos(polar)])
    verts.append([0.0, 0.0, -1.0])
    bottom = len(verts) - 1
    faces = []
    for m in range(segments):
        faces.append((0, 1 + m, 1 + (m + 1) % segments))
    for r in range(rows - 2):
        a, b = 1 + r * segments, 1 + (r + 1) * segments
        for m in range(segments):
            n = (m + 1) % segments
            faces += [(a + m, b + m, b + n), (a + m, b + n, a + n)]
    last = 1 + (rows - 2) * segments
    for m in range(segments):
        faces.append((bottom, last + (m + 1) % segments, last + m))
    return np.array(verts, dtype=np.float32), np.array(faces, dtype=np.uint32)


def linear_colors(shapes: Sequence[GeomShape]) -> np.ndarray:
    """The instances' colours (N, 3) as viser's batched node wants them: 0-255 bytes of
    *linear* light. A single node's colour is read as sRGB, as the MJCF's rgba is, while
    the batch's bytes are taken as linear: sent as they are, every batched geom would be
    drawn paler than the same geom alone."""
    srgb = np.array([s.rgba[:3] for s in shapes], dtype=float).reshape(-1, 3)
    linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    return np.round(255 * np.clip(linear, 0.0, 1.0)).astype(np.uint8)


def batch_key(shape: GeomShape) -> tuple[object, ...]:
    """What the geoms of one batch have in common: the kind (a scaled unit mesh), or the
    kind and size (a capsule, a model's mesh)."""
    if shape.kind in SCALED:
        return (shape.kind,)
    return (shape.kind, shape.size, shape.mesh_id)


def instance_scale(shape: GeomShape) -> tuple[float, float, float]:
    """The unit mesh's scale along x, y, z that gives ``shape`` (1 for a capsule or mesh)."""
    size = shape.size
    if shape.kind == "box":
        return (size[0], size[1], size[2])
    if shape.kind == "cylinder":
        return (size[0], size[0], size[1])
    if shape.kind == "sphere":
        return (size[0], size[0], size[0])
    if shape.kind == "ellipsoid":
        return (size[0], size[1], size[2])
    return (1.0, 1.0, 1.0)


def unit_mesh(shape: GeomShape) -> tuple[np.ndarray, np.ndarray] | None:
    """The mesh every instance of ``shape``'s batch draws (None: a model's mesh, whose
    vertices come from the model)."""
    if shape.kind == "box":
        return unit_box()
    if shape.kind == "cylinder":
        return unit_cylinder()
    if shape.kind in ("sphere", "ellipsoid"):
        return unit_sphere()
    if shape.kind == "capsule":
        verts, faces = capsule_mesh(*shape.size)
        return np.asarray(verts, dtype=np.float32), np.asarray(faces, dtype=np.uint32)
    return None


@dataclass
class Batch:
    """Geoms drawn as the instances of one node.

    Attributes:
        key: What they have in common (:func:`batch_key`).
        shapes: The geoms, one instance each, in this order.
        groups: Index of each geom's group in the renderer's ``roots``.
        local: Each geom's pose in its group (N, 7).
    """

    key: tuple[object, ...]
    shapes: list[GeomShape]
    groups: np.ndarray
    local: np.ndarray


def batches(shapes: Sequence[GeomShape], roots: Sequence[int] | np.ndarray) -> list[Batch]:
    """The batches drawing the moving ``shapes`` of whole groups (``roots``: the groups'
    root bodies, in the renderer's order).

    A group is batched when each of its geoms shares its key with a geom of another
    batched group: then its frame has nothing left to pose. A group with a geom of its
    own kind, or a translucent one (instances are drawn in one pass: their depth order
    is not sorted), keeps all its geoms under its frame, since its pose is sent anyway.
    Batching is kept only when it saves :data:`MIN_SAVED` messages a frame or more (one
    batch message against at least one pose a group)."""
    index = {int(r): k for k, r in enumerate(roots)}
    by_group: dict[int, list[GeomShape]] = {}
    for shape in shapes:
        if shape.moving and shape.body in index:
            by_group.setdefault(shape.body, []).append(shape)
    kept = {b for b, group in by_group.items() if all(s.opacity is None for s in group)}
    while True:  # drop groups with a geom no other kept group shares, until none is left
        spans: dict[tuple[object, ...], set[int]] = {}
        for body in kept:
            for shape in by_group[body]:
                spans.setdefault(batch_key(shape), set()).add(body)
        alone = {b for b in kept if any(len(spans[batch_key(s)]) < 2 for s in by_group[b])}
        if not alone:
            break
        kept -= alone
    members: dict[tuple[object, ...], list[GeomShape]] = {}
    for body in sorted(kept):
        for shape in by_group[body]:
            members.setdefault(batch_key(shape), []).append(shape)
    if len(kept) - len(members) < MIN_SAVED:
        return []
    out = []
    for key, group in members.items():
        groups = np.array([index[s.body] for s in group], dtype=int)
        local = np.array([s.local for s in group], dtype=float).reshape(-1, 7)
        out.append(Batch(key, group, groups, local))
    return out


def instance_poses(batch: Batch, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World (positions (N, 3), wxyzs (N, 4)) of a batch's instances, as float32 for the
    wire, from the groups' world ``poses`` (G, 7: x, y, z, w, qx, qy, qz).

    One ``mju_mulPose`` per instance: for the handful a batch holds, 1.5 µs each, where
    numpy's vectorised products cost 20–50 µs in call overheads."""
    count = len(batch.shapes)
    positions, wxyzs = np.empty((count, 3)), np.empty((count, 4))
    local = batch.local
    for i, k in enumerate(batch.groups.tolist()):
        pose = poses[k]
        mujoco.mju_mulPose(positions[i], wxyzs[i], pose[:3], pose[3:], local[i, :3], local[i, 3:])
    return positions.astype(np.float32), wxyzs.astype(np.float32)
