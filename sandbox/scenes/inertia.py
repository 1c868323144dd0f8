"""Inertia matrix of a solid (course 5.2–5.7, formulary A.3): read it, move it, spin it.

The user picks a solid (the square-based block of 5.4, the shapes of 5.6, the rod and the
three-cylinder crankshaft of 5.7, the micro-compressor's parts), a point and a basis. The
readouts give the matrix there with the course's signs, I = [[A, −F, −E], [−F, B, −D],
[−E, −D, C]], computed from the simulated model (MuJoCo's mass, G and principal inertia,
which it integrates from the geoms), next to the course's closed form; the principal
moments at G and Huygens' transport terms. The solid floats on a free joint, weight
neglected: launched about one of its principal axes at G it spins freely (Euler's
torque-free motion), steadily about the smallest and the largest moments, while about the
intermediate one a small perturbation grows into a flip and back, with the period of
:func:`~sandbox.mechanics.inertia.torque_free_period`.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import BadParameter
from sandbox.mechanics.inertia import (
    MassProperties,
    block,
    change_basis,
    coefficients,
    combine,
    cylinder,
    hollow_cylinder,
    huygens,
    principal_axes,
    rod,
    rotation_matrix,
    sphere,
    torque_free_period,
)
from sandbox.physics.snapshot import Snapshot
from sandbox.scenes.base import (
    Accuracy,
    Arrow,
    Effects,
    Param,
    Scene,
    SceneReadout,
    Series,
    Values,
    per_revolution_timestep,
)
from sandbox.scenes.measures import relative_drift
from sandbox.scenes.presets import StudyPreset, XYPreset

RPM = 2 * math.pi / 60
SOLIDS = (
    "Pavé à base carrée (5.4)",
    "Pavé de côtés a, b, c (5.6.1)",
    "Cylindre plein (5.6.2)",
    "Sphère pleine (5.6.3)",
    "Bielle assimilée à une tige (5.7)",
    "Vilebrequin en trois cylindres (5.7)",
    "Cylindre creux (5.6.2)",
)
SQUARE_BLOCK, BLOCK, CYLINDER, SPHERE, ROD, CRANKSHAFT, HOLLOW = range(7)
POINTS = ("O, origine du paramétrage", "G, centre de gravité", "Point P de coordonnées x, y, z")
AXES = (
    "Axe principal 1, plus petit moment I₁",
    "Axe principal 2, moment intermédiaire I₂",
    "Axe principal 3, plus grand moment I₃",
)
ROD_SLENDERNESS = 100.0
"""The rod is simulated as a cylinder of radius L / 100 (MuJoCo needs a volume): its
moments differ from the thin rod's m L²/3 by 3/(4·100²) = 7.5e-5, and its own-axis moment
m r²/2 is 1.5e-4 of m L²/3."""
TUBE_SIDES = 256
"""The hollow cylinder is simulated as a mesh (MuJoCo has no tube primitive) whose
circles are 256-gons: its mass is set, and its moments come within 1e-4 of the circle's."""
CRANK_RADIUS = 0.015
"""OA of the micro-compressor's crank [m] (the compressor scene's R)."""
CRANKSHAFT_PARTS = (
    # (name, radius [m], length [m], centre in R_S [m], own axis in R_S)
    ("journal", 0.008, 0.030, (0.0, 0.0, -0.020), (0.0, 0.0, 1.0)),
    ("web", 0.005, CRANK_RADIUS, (CRANK_RADIUS / 2, 0.0, 0.0), (1.0, 0.0, 0.0)),
    ("pin", 0.005, 0.012, (CRANK_RADIUS, 0.0, 0.011), (0.0, 0.0, 1.0)),
)
"""The 5.7 crankshaft as three cylinders of one material, touching without overlapping: the journal
on the axis (O, z) below the web, the web along x from O to A, the crank pin along z at A.
O is on the axis in the web's mid-plane: (O, x, z) is a plane of symmetry, so D = F = 0,
and the pin, above the plane z = 0 and off the axis, makes E = ∫ x·z dm positive (the
compressor's E₁)."""

SOLID, SIZES, POINT, SPIN = "Solide", "Dimensions", "Point et base", "Rotation libre"
PARAMS = (
    Param(
        "solid",
        "",
        1.0,
        0.0,
        float(len(SOLIDS) - 1),
        (
            "Solid: 0 square-based block (5.4), 1 block a, b, c (5.6.1), 2 solid cylinder, "
            "3 sphere, 4 rod (5.7), 5 three-cylinder crankshaft (5.7), 6 hollow cylinder."
        ),
        step=1.0,
        label="Solide étudié",
        hint=(
            "Solide dont on lit la matrice d'inertie, choisi parmi les exemples des paragraphes "
            "5.4, 5.6 et 5.7 du cours."
        ),
        group=SOLID,
        choices=SOLIDS,
    ),
    Param(
        "mass",
        "kg",
        1.0,
        0.01,
        100.0,
        "Mass m of the solid (uniform density).",
        step=0.01,
        label="Masse m",
        hint="Masse du solide, de masse volumique uniforme.",
        group=SOLID,
    ),
    Param(
        "a",
        "m",
        0.1,
        0.005,
        1.0,
        (
            "First dimension: side a of the block's base or edge a, radius R of the cylinder "
            "and the sphere."
        ),
        step=0.005,
        label="Dimension a",
        hint="Côté a de la base du pavé ou arête selon x, rayon R du cylindre et de la sphère.",
        group=SIZES,
    ),
    Param(
        "b",
        "m",
        0.2,
        0.005,
        1.0,
        (
            "Second dimension: height b of the 5.4 block or edge b, height h of the cylinder, "
            "length L of the rod."
        ),
        step=0.005,
        label="Dimension b",
        hint=(
            "Hauteur b du pavé à base carrée ou arête selon y, hauteur h du cylindre, longueur L"
            " de la bielle."
        ),
        group=SIZES,
    ),
    Param(
        "c",
        "m",
        0.3,
        0.005,
        1.0,
        "Third dimension: edge c along z of the 5.6.1 block.",
        step=0.005,
        label="Dimension c",
        hint=(
            "Arête c selon z du pavé du paragraphe 5.6.1 ; les autres solides ne s'en servent pas."
        ),
        group=SIZES,
        advanced=True,
    ),
    Param(
        "hole_ratio",
        "",
        0.6,
        0.05,
        0.95,
        "Inner radius of the hollow cylinder over its outer radius a.",
        step=0.01,
        label="Rapport des rayons du cylindre creux r/R",
        hint=(
            "Rayon intérieur r du cylindre creux divisé par son rayon extérieur R = a ; les "
            "autres solides ne s'en servent pas."
        ),
        group=SIZES,
        advanced=True,
    ),
    Param(
        "point",
        "",
        0.0,
        0.0,
        2.0,
        (
            "Point of the matrix: 0 the origin O of the course's parametrisation, 1 the centre of "
            "mass G, 2 the point P (point_x, point_y, point_z)."
        ),
        live=True,
        step=1.0,
        label="Point de calcul de la matrice",
        hint=(
            "Point où la matrice est calculée : l'origine O du paramétrage du cours (A pour la "
            "bielle), le centre de gravité G ou un point P."
        ),
        group=POINT,
        choices=POINTS,
    ),
    Param(
        "point_x",
        "m",
        0.0,
        -1.0,
        1.0,
        "x of the point P in the solid's frame.",
        live=True,
        step=0.005,
        label="Abscisse x du point P",
        hint="Coordonnée x du point P dans le repère du solide, depuis son origine O.",
        group=POINT,
        advanced=True,
    ),
    Param(
        "point_y",
        "m",
        0.0,
        -1.0,
        1.0,
        "y of the point P in the solid's frame.",
        live=True,
        step=0.005,
        label="Ordonnée y du point P",
        hint="Coordonnée y du point P dans le repère du solide, depuis son origine O.",
        group=POINT,
        advanced=True,
    ),
    Param(
        "point_z",
        "m",
        0.0,
        -1.0,
        1.0,
        "z of the point P in the solid's frame.",
        live=True,
        step=0.005,
        label="Cote z du point P",
        hint="Coordonnée z du point P dans le repère du solide, depuis son origine O.",
        group=POINT,
        advanced=True,
    ),
    Param(
        "basis_z_deg",
        "deg",
        0.0,
        -180.0,
        180.0,
        "Basis of the matrix: first rotation of the solid's basis, about z.",
        live=True,
        step=1.0,
        label="Rotation de la base autour de z ψ",
        hint=(
            "Première rotation qui amène la base du solide sur la base de calcul, autour de son "
            "axe z."
        ),
        group=POINT,
    ),
    Param(
        "basis_y_deg",
        "deg",
        0.0,
        -90.0,
        90.0,
        "Basis of the matrix: second rotation, about the new y.",
        live=True,
        step=1.0,
        label="Rotation de la base autour de y θ",
        hint="Deuxième rotation de la base de calcul, autour du nouvel axe y.",
        group=POINT,
    ),
    Param(
        "basis_x_deg",
        "deg",
        0.0,
        -180.0,
        180.0,
        "Basis of the matrix: third rotation, about the new x.",
        live=True,
        step=1.0,
        label="Rotation de la base autour de x φ",
        hint="Troisième rotation de la base de calcul, autour du nouvel axe x.",
        group=POINT,
    ),
    Param(
        "spin_axis",
        "",
        1.0,
        0.0,
        2.0,
        (
            "Principal axis at G the solid is launched about: 0 the smallest moment, 1 the "
            "intermediate, 2 the largest."
        ),
        live=True,
        step=1.0,
        label="Axe principal de lancement",
        hint=(
            "Axe principal d'inertie en G autour duquel le solide est lancé, repéré par son "
            "moment principal."
        ),
        group=SPIN,
        choices=AXES,
    ),
    Param(
        "spin_rpm",
        "rpm",
        120.0,
        0.0,
        3000.0,
        (
            "Rotation speed given at launch (at reset and whenever a spin parameter or the solid "
            "changes)."
        ),
        live=True,
        step=10.0,
        label="Vitesse de lancement ω₀",
        hint=(
            "Vitesse de rotation donnée au solide au lancement, puis il tourne librement sans "
            "aucun couple."
        ),
        group=SPIN,
    ),
    Param(
        "perturbation_deg",
        "deg",
        1.0,
        0.0,
        30.0,
        "Angle between the launch rotation and the principal axis, towards the next axis.",
        live=True,
        step=0.1,
        label="Écart de lancement à l'axe ε",
        hint=(
            "Petit angle entre la rotation de lancement et l'axe principal choisi, vers l'axe "
            "principal suivant."
        ),
        group=SPIN,
    ),
)

SHAPE = ("solid", "mass", "a", "b", "c", "hole_ratio")
"""Parameters that shape the solid (a change rebuilds the model)."""
LAUNCH = (*SHAPE, "spin_axis", "spin_rpm", "perturbation_deg")
"""Parameters of a launch, stored in ``userdata`` (a change relaunches the spin)."""


def _choice(values: Values, name: str) -> int:
    return int(round(values[name]))


# -- geometry and closed forms --------------------------------------------------------------
@dataclass(frozen=True)
class Part:
    """A box, cylinder, tube or sphere of the solid, in its frame R_S (origin O).

    Attributes:
        kind: "box", "cylinder", "tube" or "sphere".
        size: Edges (box), (radius, length) (cylinder), (outer radius, length, inner
            radius) (tube) or (radius,) (sphere) [m].
        centre: Centre of the part in R_S [m].
        axis: Own z axis of the part in R_S (a cylinder's axis).
    """

    kind: str
    size: tuple[float, ...]
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)

    @property
    def volume(self) -> float:
        """Volume [m³]."""
        if self.kind == "box":
            return float(np.prod(self.size))
        if self.kind == "cylinder":
            return math.pi * self.size[0] ** 2 * self.size[1]
        if self.kind == "tube":
            return math.pi * (self.size[0] ** 2 - self.size[2] ** 2) * self.size[1]
        return 4.0 / 3.0 * math.pi * self.size[0] ** 3

    def rotation(self) -> np.ndarray:
        """Rotation whose columns are the part's own axes in R_S (own z along ``axis``)."""
        z = np.asarray(self.axis, dtype=float)
        if np.allclose(z, [0.0, 0.0, 1.0]):
            return np.eye(3)
        turn = np.cross([0.0, 0.0, 1.0], z)
        return rotation_matrix(turn, math.acos(float(np.clip(z[2], -1.0, 1.0))))


def parts(values: Values) -> tuple[Part, ...]:
    """The geometry of the chosen solid in its frame R_S."""
    solid, a, b, c = _choice(values, "solid"), values["a"], values["b"], values["c"]
    if solid == SQUARE_BLOCK:  # 5.4: base a × a in the plane (O, x, y), height b along z
        return (Part("box", (a, a, b), (0.0, 0.0, b / 2)),)
    if solid == BLOCK:
        return (Part("box", (a, b, c)),)
    if solid == CYLINDER:
        return (Part("cylinder", (a, b)),)
    if solid == SPHERE:
        return (Part("sphere", (a,)),)
    if solid == ROD:  # 5.7: the rod AB = L y, from A = O
        return (Part("cylinder", (b / ROD_SLENDERNESS, b), (0.0, b / 2, 0.0), (0.0, 1.0, 0.0)),)
    if solid == CRANKSHAFT:
        return tuple(Part("cylinder", (r, h), c0, ax) for _, r, h, c0, ax in CRANKSHAFT_PARTS)
    if solid == HOLLOW:  # 5.6.2: R = a, h = b, hole of radius r = hole_ratio × a
        return (Part("tube", (a, b, values["hole_ratio"] * a)),)
    raise BadParameter(f"solid = {solid!r} is not a solid; lower solid to 0..{len(SOLIDS) - 1}")


def course_inertia(values: Values) -> MassProperties:
    """Mass, G and inertia at G in R_S from the course's formulary (5.4–5.7).

    The rod is the course's thin rod (``rod``: no moment about its own axis), not the thin
    cylinder the simulation needs.
    """
    return _course_inertia(tuple(float(values[n]) for n in SHAPE))


@lru_cache(maxsize=32)
def _course_inertia(shape: tuple[float, ...]) -> MassProperties:
    values = dict(zip(SHAPE, shape, strict=True))
    solid, mass = _choice(values, "solid"), values["mass"]
    if solid == ROD:
        length = values["b"]
        frame = rotation_matrix([1.0, 0.0, 0.0], -math.pi / 2)  # own z -> y
        return MassProperties.of_shape(rod(mass, length), mass, [0, length / 2, 0], frame)
    items = parts(values)
    density = mass / sum(p.volume for p in items)
    shapes = []
    for p in items:
        m = density * p.volume
        if p.kind == "box":
            i = block(m, *p.size)
        elif p.kind == "cylinder":
            i = cylinder(m, *p.size)
        elif p.kind == "tube":  # 5.6.2: the full cylinder minus the hole
            i = hollow_cylinder(m, p.size[0], p.size[2], p.size[1])
        else:
            i = sphere(m, p.size[0])
        shapes.append(MassProperties.of_shape(i, m, p.centre, p.rotation()))
    return combine(shapes)


def frame_offset(values: Values) -> np.ndarray:
    """O G from the shapes' volumes [m]: where the body's origin sits in R_S.

    The free joint's origin is put at G (the geoms and the axes of R_S are shifted by −OG):
    there the linear and angular equations uncouple, and G stays exactly at rest, whereas
    an origin at O would let the integrator's error on the rotation of O about G move G
    (2e-5 of ω·OG within 5 s at 3000 rpm). MuJoCo's own centre of mass, added to it, is
    what the readouts use.
    """
    items = parts(values)
    volumes = np.array([p.volume for p in items])
    centres = np.array([p.centre for p in items], dtype=float)
    return np.asarray(volumes @ centres / volumes.sum())


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


# -- the solid as simulated (MuJoCo's mass properties) ---------------------------------------
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


def basis(values: Values) -> np.ndarray:
    """The chosen basis: its vectors (columns) in R_S, R = Rz(ψ) Ry(θ) Rx(φ)."""
    return _basis(values["basis_z_deg"], values["basis_y_deg"], values["basis_x_deg"])


@lru_cache(maxsize=64)
def _basis(psi_deg: float, theta_deg: float, phi_deg: float) -> np.ndarray:
    rz = rotation_matrix([0, 0, 1], math.radians(psi_deg))
    ry = rotation_matrix([0, 1, 0], math.radians(theta_deg))
    rx = rotation_matrix([1, 0, 0], math.radians(phi_deg))
    out = rz @ ry @ rx
    out.flags.writeable = False  # shared by every call with these angles
    return out


def point(values: Values, com: np.ndarray) -> np.ndarray:
    """The chosen point in R_S [m]: O, G or P."""
    choice = _choice(values, "point")
    if choice == 1:
        return np.asarray(com, dtype=float)
    if choice == 2:
        return np.array([values["point_x"], values["point_y"], values["point_z"]])
    return np.zeros(3)


def matrix_at(mass: float, com: np.ndarray, inertia_G: np.ndarray, values: Values) -> np.ndarray:
    """I at the chosen point in the chosen basis (Huygens from G, then Rᵀ I R)."""
    at = huygens(inertia_G, mass, point(values, com) - com)
    return change_basis(at, basis(values))


def huygens_terms(mass: float, com: np.ndarray, values: Values) -> np.ndarray:
    """Diagonal of I_P^H = m [b²+c², a²+c², a²+b²] with GP = (a, b, c) in the chosen basis."""
    a, b, c = basis(values).T @ (point(values, com) - com)
    return mass * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def launch_omega(sim: Simulated, values: Values) -> np.ndarray:
    """Launch rotation in R_S [rad/s]: ω₀ (cos ε e_k + sin ε e_(k+1)) on the principal axes."""
    k = _choice(values, "spin_axis")
    eps = math.radians(values["perturbation_deg"])
    w = values["spin_rpm"] * RPM
    return w * (math.cos(eps) * sim.axes[:, k] + math.sin(eps) * sim.axes[:, (k + 1) % 3])


def flip_period(values: Values) -> float:
    """Course/Euler period [s] of the launched motion (nan if the moments are not distinct
    or the launch is exactly on an axis)."""
    props = course_inertia(values)
    moments, axes = principal_axes(props.inertia_G)
    k = _choice(values, "spin_axis")
    eps = math.radians(values["perturbation_deg"])
    w = values["spin_rpm"] * RPM
    omega = np.zeros(3)
    omega[k], omega[(k + 1) % 3] = w * math.cos(eps), w * math.sin(eps)
    spread = moments[2] - moments[0]
    if eps == 0 or w == 0 or min(np.diff(moments)) < 1e-6 * spread or spread <= 0:
        return math.nan
    return torque_free_period(moments, omega)


def intermediate_place(values: Values) -> float:
    """(I₂ − I₁)/(I₃ − I₁) of the solid's principal moments at G: where the intermediate
    moment sits between the two others (0 or 1: two equal moments)."""
    moments, _ = principal_axes(course_inertia(values).inertia_G)
    spread = float(moments[2] - moments[0])
    return float(moments[1] - moments[0]) / spread if spread > 0 else math.nan


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


def reference(values: Values) -> dict[str, float]:
    """The course's matrix at the chosen point and basis, principal moments at G, Huygens'
    terms, and the period of the torque-free motion."""
    props = course_inertia(values)
    i = matrix_at(props.mass, props.com, props.inertia_G, values)
    out = {n: x + 0.0 for n, x in zip("ABCDEF", coefficients(i), strict=True)}  # no −0
    moments, _ = principal_axes(props.inertia_G)
    out.update({f"I_{k + 1}": float(moments[k]) for k in range(3)})
    terms = huygens_terms(props.mass, props.com, values)
    out.update({f"huygens_{n}": float(t) for n, t in zip("ABC", terms, strict=True)})
    out["flip_period"] = flip_period(values)
    return out


# -- readouts ----------------------------------------------------------------------------------
def _matrix(s: Snapshot) -> np.ndarray:
    found = s.cache.get("inertia_matrix")
    if found is None:
        sim = simulated(s.model, s.values)
        found = s.cache["inertia_matrix"] = matrix_at(sim.mass, sim.com, sim.inertia_G, s.values)
    return found


def _coefficient(k: int):
    return lambda s: coefficients(_matrix(s))[k] + 0.0  # + 0.0: no "−0" for a product


def _gap(s: Snapshot) -> float:
    """Largest |I_sim − I_course| over the largest |I_course| (at the chosen point, basis)."""
    props = course_inertia(s.values)
    ref = matrix_at(props.mass, props.com, props.inertia_G, s.values)
    return float(np.max(np.abs(_matrix(s) - ref)) / np.max(np.abs(ref)))


def _huygens_terms(s: Snapshot) -> np.ndarray:
    found = s.cache.get("inertia_huygens")
    if found is None:
        sim = simulated(s.model, s.values)
        found = s.cache["inertia_huygens"] = huygens_terms(sim.mass, sim.com, s.values)
    return found


def _omega_local(s: Snapshot) -> np.ndarray:
    return np.asarray(s.data.qvel[3:6], dtype=float)


def _spin_angle(s: Snapshot) -> float:
    """Angle [deg] between ω and the launch principal axis e_k (0 to 180: a flip reads 180)."""
    w = _omega_local(s)
    norm = float(np.linalg.norm(w))
    if norm == 0.0:
        return 0.0
    e = simulated(s.model, s.values).axes[:, _choice(s.values, "spin_axis")]
    return math.degrees(math.acos(float(np.clip(w @ e / norm, -1.0, 1.0))))


def _sigma_world(s: Snapshot) -> np.ndarray:
    """σ_G = I_G ω in R₀ [kg·m²/s]."""
    b = s.body_id("solid")
    r = s.data.xmat[b].reshape(3, 3)
    return r @ (simulated(s.model, s.values).inertia_G @ _omega_local(s))


def _omega_world(s: Snapshot) -> np.ndarray:
    b = s.body_id("solid")
    return s.data.xmat[b].reshape(3, 3) @ _omega_local(s)


def _principal(k: int):
    return lambda s: float(simulated(s.model, s.values).moments[k])


def _huygens(k: int):
    def fn(s: Snapshot) -> float:
        return float(_huygens_terms(s)[k])

    return fn


_AXIS_WORDS = ("x", "y", "z")
READOUTS = (
    *(
        SceneReadout(
            n,
            "kg·m²",
            f"Moment of inertia {n} about the chosen {ax} axis through the chosen point.",
            _coefficient(k),
            label=f"Moment d'inertie {n}",
            hint=f"Moment d'inertie {n} autour de l'axe {ax} de la base choisie, passant par le "
            "point choisi, calculé sur le modèle simulé.",
        )
        for k, (n, ax) in enumerate(zip("ABC", _AXIS_WORDS, strict=True))
    ),
    *(
        SceneReadout(
            n,
            "kg·m²",
            f"Product of inertia {n} = ∫ {w} dm at the chosen point, in the chosen basis.",
            _coefficient(k + 3),
            label=f"Produit d'inertie {n}",
            hint=f"Produit d'inertie {n} = ∫ {w} dm au point choisi et dans la base choisie ; "
            f"la matrice porte −{n}.",
        )
        for k, (n, w) in enumerate(zip("DEF", ("y·z", "x·z", "x·y"), strict=True))
    ),
    *(
        SceneReadout(
            f"I_{k + 1}",
            "kg·m²",
            f"Principal moment of inertia {k + 1} at G (ascending order).",
            _principal(k),
            label=f"Moment principal en G I{sub}",
            hint=f"Moment principal d'inertie en G numéro {k + 1}, les trois étant rangés du "
            "plus petit au plus grand.",
        )
        for k, sub in enumerate("₁₂₃")
    ),
    *(
        SceneReadout(
            f"huygens_{n}",
            "kg·m²",
            f"Huygens term of {n}: what moving the matrix from G to the chosen point adds.",
            _huygens(k),
            label=f"Terme de Huygens sur {n}",
            hint=f"Terme diagonal de la matrice de Huygens ajouté à {n} quand on passe de G au "
            f"point choisi : m·({sq}) avec GP = (a, b, c).",
        )
        for k, (n, sq) in enumerate(zip("ABC", ("b² + c²", "a² + c²", "a² + b²"), strict=True))
    ),
    SceneReadout(
        "gap",
        "",
        "Largest gap between the simulated matrix and the course's, over its largest term.",
        _gap,
        label="Écart au formulaire",
        hint="Plus grand écart entre la matrice du modèle simulé et celle du formulaire, "
        "rapporté au plus grand de ses termes.",
    ),
    SceneReadout(
        "spin_angle",
        "deg",
        "Angle between the rotation vector and the launch principal axis (180: flipped).",
        _spin_angle,
        label="Angle entre ω et l'axe de lancement",
        hint="Angle entre le vecteur rotation et l'axe principal de lancement, lié au solide : "
        "180° quand le solide s'est retourné.",
    ),
    SceneReadout(
        "omega",
        "rad/s",
        "Norm of the rotation vector of the solid.",
        lambda s: float(np.linalg.norm(_omega_local(s))),
        label="Norme de la rotation ω",
        hint="Norme du vecteur rotation du solide par rapport au repère R₀.",
    ),
    SceneReadout(
        "sigma_G",
        "kg·m²/s",
        "Norm of the angular momentum at G, conserved without torque.",
        lambda s: float(np.linalg.norm(_sigma_world(s))),
        label="Moment cinétique en G σ",
        hint="Norme du moment cinétique en G, constante en l'absence de couple extérieur.",
    ),
)


def _at_g(s: Snapshot) -> np.ndarray:
    return np.array(s.data.xipos[s.body_id("solid")])


def _launch_axis_world(s: Snapshot) -> np.ndarray:
    """The launch principal axis e_k in R₀ (unit vector)."""
    b = s.body_id("solid")
    e = simulated(s.model, s.values).axes[:, _choice(s.values, "spin_axis")]
    return np.asarray(s.data.xmat[b].reshape(3, 3) @ e)


def _axis_component(k: int):
    def fn(s: Snapshot) -> float:
        e = simulated(s.model, s.values).axes[:, _choice(s.values, "spin_axis")]
        if e[int(np.argmax(np.abs(e)))] < 0:  # an axis has no sign: show it pointing "up"
            e = -e
        return float(basis(s.values)[:, k] @ e) + 0.0

    return fn


AXIS_READOUTS = tuple(
    SceneReadout(
        f"axis_{c}",
        "",
        f"Component on the chosen basis' {c} of the launch principal axis at G.",
        _axis_component(k),
        label=f"Axe principal choisi, composante sur {c}",
        hint=f"Composante sur l'axe {c} de la base choisie du vecteur unitaire de l'axe "
        "principal d'inertie de lancement, en G.",
    )
    for k, c in enumerate("xyz")
)


ARROWS = (
    Arrow(
        "axis",
        "Axe principal de lancement",
        (220, 180, 30),
        lambda s: (_at_g(s), _launch_axis_world(s)),
        scale=0.25,
        point="G",
        hint="Axe principal d'inertie en G autour duquel le solide a été lancé (jaune).",
        magnitude=False,
    ),
    Arrow(
        "omega",
        "Rotation ω",
        (230, 80, 40),
        lambda s: (_at_g(s), _omega_world(s)),
        scale=0.02,
        unit="rad/s",
        point="G",
        hint="Vecteur rotation du solide, tracé depuis G (orange).",
    ),
    Arrow(
        "sigma_G",
        "Moment cinétique σ en G",
        (120, 60, 160),
        lambda s: (_at_g(s), _sigma_world(s)),
        scale=2.0,
        unit="kg·m²/s",
        point="G",
        hint="Moment cinétique en G, fixe dans R₀ puisqu'aucun couple n'agit (violet).",
    ),
)


# -- accuracy ----------------------------------------------------------------------------------
def flip_times(time: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Times [s] the angle rises through 90° (linear interpolation between samples)."""
    t, a = np.asarray(time, dtype=float), np.asarray(angle, dtype=float) - 90.0
    up = np.nonzero((a[:-1] < 0.0) & (a[1:] >= 0.0))[0]
    return t[up] - a[up] * (t[up + 1] - t[up]) / (a[up + 1] - a[up])


def period_error(series: Series, values: Values) -> float:
    """|measured flip period − Euler's closed form| / closed form (inf without two flips)."""
    times = flip_times(series["time"], series["spin_angle"])
    if len(times) < 2:
        return math.inf
    measured = float(np.mean(np.diff(times)))
    return abs(measured - flip_period(values)) / flip_period(values)


def invariants_drift(series: Series, values: Values) -> float:
    """Largest relative drift of T and |σ_G| over the run."""
    return max(relative_drift("T")(series, values), relative_drift("sigma_G")(series, values))


STEP_ANGLE = 0.13
"""Rotation per step [rad] the default timestep allows (12.6 rad/s × 10 ms at 120 rpm):
faster launches shrink the step to keep this angle, so the accuracy per revolution stays
the one ``sandbox bench`` measured at 120 rpm."""
TIMESTEP = 1e-2


def timestep_for(values: Values, data: mujoco.MjData | None = None) -> float:
    """Default timestep [s]: at most ``STEP_ANGLE`` of rotation per step."""
    return per_revolution_timestep(STEP_ANGLE, values["spin_rpm"] * RPM, largest=TIMESTEP)


SCENE = Scene(
    name="inertia",
    # G stays at the origin; the drawn basis and arrows reach ~0.4 m from it
    look_at=((0.0, 0.0, 0.0), 0.8),
    overlay={"spin_angle": "Angle entre ω et l'axe", "omega": "ω", "sigma_G": "σ en G"},
    title="Matrice d'inertie d'un solide : point, base, axes principaux",
    summary=(
        "A solid from the course (block, cylinder, sphere, rod, crankshaft) with its inertia "
        "matrix at a chosen point and basis, against the formulary. Launched about a "
        "principal axis it spins freely: steadily about the smallest and largest moments, "
        "with a flip about the intermediate one."
    ),
    mjcf="inertia.xml",
    params=PARAMS,
    effects=Effects(gravity=False, contacts=False, actuation=False),
    readouts=READOUTS + AXIS_READOUTS,
    edit=edit,
    drive=drive,
    initial_state=initial_state,
    reference=reference,
    # sandbox bench (120 rpm, 8 s, two flips): every integrator gets the flip period within
    # 1e-3, but only RK4 keeps T and |σ_G| (drift 2e-7 at 10 ms; Euler and the implicit ones
    # lose 1 to 40 %). RK4 at 10 ms is on the Pareto front, 2100 × real time.
    integrator="rk4",
    timestep=TIMESTEP,
    timestep_for=timestep_for,
    plots=("spin_angle", "omega"),
    study_presets=(
        StudyPreset(
            "Période du basculement selon la place de l'inertie intermédiaire",
            ("b", 0.12, 0.28, 9),
            "spin_angle",
            statistic="period",
            duration=20.0,
            course="flip_period",
            hint="Lancé autour de son axe intermédiaire, le pavé bascule périodiquement ; "
            "la période (Euler) est la plus courte quand I₂ est à mi-chemin de I₁ et I₃.",
            x=("Place de I₂ entre I₁ et I₃ : (I₂ − I₁)/(I₃ − I₁)", intermediate_place),
        ),
    ),
    xy_presets=(
        XYPreset(
            "Angle de l'axe de rotation au cours du temps",
            "time",
            ("spin_angle",),
            hint="Lancé autour de l'axe d'inertie intermédiaire, le solide bascule "
            "périodiquement ; autour des deux autres, l'angle reste petit.",
        ),
        XYPreset(
            "Composantes de l'axe principal choisi",
            "time",
            ("axis_x", "axis_y", "axis_z"),
            hint="Les composantes dans R₀ de l'axe principal autour duquel le solide est lancé.",
        ),
    ),
    arrows=ARROWS,
    body_frame="solid",
    sections="5.2–5.7, A.3",
    extra={"flip_period": flip_period, "solid_names": {"solid": "S"}},
    # Round-off: torque-free, {D} and the powers are 0 in the course; RK4 leaves 1e-17 N·m
    # and 1e-16 W, and G at rest keeps m·V(G) at 1e-17 kg·m/s.
    zero={
        "kg·m²": 1e-15,
        "kg·m²/s": 1e-15,
        "kg·m/s": 1e-14,
        "N": 1e-12,
        "N·m": 1e-12,
        "W": 1e-12,
        "": 1e-12,  # a component of a principal axis that symmetry makes 0
    },
    accuracy=Accuracy(
        key="spin_angle",
        readouts=("spin_angle", "T", "sigma_G"),
        duration=8.0,
        error=period_error,
        invariant="T and |σ_G| (torque-free motion)",
        drift=invariants_drift,
        rate=1000.0,
        timesteps=(5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2, 5e-2),
        drift_tol=1e-4,
    ),
)
