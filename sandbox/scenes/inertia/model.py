"""The inertia scene's model: the solid's geoms added to the MJCF (a mesh for the hollow
cylinder), the mass properties MuJoCo integrates from them, and the launch of the free spin.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from sandbox.mechanics.inertia import principal_axes
from sandbox.physics.spec import Values
from sandbox.scenes.inertia.course import frame_offset, parts
from sandbox.scenes.inertia.params import LAUNCH, RPM, TUBE_SIDES, choice_index


def tube_mesh(outer: float, length: float, inner: float) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) [m], triangles (m, 3)) of a closed tube along z, centred at 0, with
    :data:`TUBE_SIDES`-gon walls and outward normals (MuJoCo's exact mesh inertia needs a
    closed, consistently oriented surface)."""
    n = TUBE_SIDES
    ang = 2 * np.pi * np.arange(n) / n

    def ring(radius: float, z: float) -> np.ndarray:
        return np.stack([radius * np.cos(ang), radius * np.sin(ang), np.full(n, z)], axis=1)

    vertices = np.concatenate(
        [ring(outer, -length / 2), ring(outer, length / 2), ring(inner, -length / 2)]
        + [ring(inner, length / 2)]
    )
    i = np.arange(n)
    j = (i + 1) % n
    ob, ot, ib, it = i, n + i, 2 * n + i, 3 * n + i
    obj, otj, ibj, itj = j, n + j, 2 * n + j, 3 * n + j
    faces = np.concatenate(
        [
            np.stack([ob, obj, otj], 1), np.stack([ob, otj, ot], 1),  # outer wall
            np.stack([ib, itj, ibj], 1), np.stack([ib, it, itj], 1),  # inner wall
            np.stack([ot, otj, itj], 1), np.stack([ot, itj, it], 1),  # top
            np.stack([ob, ibj, obj], 1), np.stack([ob, ib, ibj], 1),  # bottom
        ]
    )  # fmt: skip
    return vertices, faces


def edit(spec: mujoco.MjSpec, values: Values) -> None:
    """Add the solid's geoms to the body, shifted so that its origin is at G; each gets
    its share of the chosen mass (uniform density)."""
    items = parts(values)
    density = values["mass"] / sum(p.volume for p in items)
    offset = frame_offset(values)
    body = spec.body("solid")
    extent = max(float(np.linalg.norm(p.centre)) + max(p.size) for p in items)
    for k, name in enumerate(("axis_x", "axis_y", "axis_z")):  # R_S's axes, drawn from O
        marker = spec.geom(name)
        marker.pos = 0.6 * extent * np.eye(3)[k] - offset
        marker.size = [extent / 80.0, 0.6 * extent, 0.0]
    kinds = {
        "box": mujoco.mjtGeom.mjGEOM_BOX,
        "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
        "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
        "tube": mujoco.mjtGeom.mjGEOM_MESH,
    }
    colours = ((0.8, 0.7, 0.5, 0.45), (0.65, 0.67, 0.72, 0.5), (0.75, 0.55, 0.35, 0.5))  # see G
    for n, p in enumerate(items):
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, p.rotation().ravel())
        if p.kind == "box":
            size = [s / 2 for s in p.size]
        elif p.kind == "cylinder":
            size = [p.size[0], p.size[1] / 2, 0.0]
        else:
            size = [p.size[0], 0.0, 0.0]
        geom = body.add_geom(
            name=f"part{n}",
            type=kinds[p.kind],
            size=size,
            pos=list(np.asarray(p.centre) - offset),
            quat=list(quat),
            mass=density * p.volume,  # the exact share, also for the tube's polygons
            rgba=list(colours[n % len(colours)]),
        )
        if p.kind == "tube":
            vertices, faces = tube_mesh(p.size[0], p.size[1], p.size[2])
            mesh = spec.add_mesh(
                name=f"tube{n}",
                uservert=vertices.ravel().tolist(),
                userface=faces.ravel().tolist(),
            )
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
            geom.meshname = mesh.name


@dataclass(frozen=True)
class Simulated:
    """Mass properties of the simulated body in R_S: m [kg], G [m], I_G [kg·m²], and the
    principal moments (ascending) and axes (columns) at G."""

    mass: float
    com: np.ndarray
    inertia_G: np.ndarray
    moments: np.ndarray
    axes: np.ndarray


_SIMULATED: weakref.WeakKeyDictionary[Any, Simulated] = weakref.WeakKeyDictionary()


def simulated(model: mujoco.MjModel, values: Values) -> Simulated:
    """MuJoCo's mass, centre and inertia of the solid, in its own frame (memoised).

    Entries below 1e-12 of the largest moment are round-off of MuJoCo's diagonalisation
    (a cylinder's axis read back from a quaternion): they are set to 0, so that a symmetric
    solid keeps its axes of symmetry as principal axes.
    """
    found = _SIMULATED.get(model)
    if found is None:
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "solid")
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[b])
        r = rot.reshape(3, 3)
        i_g = r @ np.diag(model.body_inertia[b]) @ r.T
        i_g = 0.5 * (i_g + i_g.T)
        i_g[np.abs(i_g) < 1e-12 * float(np.max(np.abs(i_g)))] = 0.0
        moments, axes = principal_axes(i_g)
        com = frame_offset(values) + model.body_ipos[b]  # O G = O (body origin) + MuJoCo's
        found = Simulated(float(model.body_mass[b]), com, i_g, moments, axes)
        _SIMULATED[model] = found
    return found


def launch_omega(sim: Simulated, values: Values) -> np.ndarray:
    """Launch rotation in R_S [rad/s]: ω₀ (cos ε e_k + sin ε e_(k+1)) on the principal axes."""
    k = choice_index(values, "spin_axis")
    eps = math.radians(values["perturbation_deg"])
    w = values["spin_rpm"] * RPM
    return w * (math.cos(eps) * sim.axes[:, k] + math.sin(eps) * sim.axes[:, (k + 1) % 3])


def _launch(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """Give the solid its launch rotation about G (G at rest) and remember the values."""
    sim = simulated(model, values)
    mujoco.mj_kinematics(model, data)
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "solid")
    w_local = launch_omega(sim, values)
    w_world = data.xmat[b].reshape(3, 3) @ w_local
    data.qvel[3:6] = w_local  # a free joint's rotation is in the body frame
    data.qvel[0:3] = np.cross(w_world, data.xpos[b] - data.xipos[b])  # V(O) = ω ∧ GO
    data.userdata[: len(LAUNCH)] = [values[n] for n in LAUNCH]


def drive(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """No motor: the solid turns freely. A new solid or launch parameter relaunches it."""
    if any(data.userdata[i] != values[n] for i, n in enumerate(LAUNCH)):
        _launch(model, data, values)


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """Solid frame on R₀, launched about the chosen principal axis."""
    data.qpos[:] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    _launch(model, data, values)
