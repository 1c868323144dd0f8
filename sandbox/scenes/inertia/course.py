"""The course's formulas for the inertia scene (5.4–5.7, A.3): the solid's parts, its mass
properties from the formulary, and the matrix moved to a point and a basis (Huygens, change
of basis), with the period of Euler's torque-free motion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from sandbox.errors import BadParameter
from sandbox.french import number
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
from sandbox.physics.spec import Values
from sandbox.scenes.inertia.params import (
    BLOCK,
    CRANKSHAFT,
    CRANKSHAFT_PARTS,
    CYLINDER,
    HOLLOW,
    ROD,
    ROD_SLENDERNESS,
    RPM,
    SHAPE,
    SOLIDS,
    SPHERE,
    SQUARE_BLOCK,
    choice_index,
)


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
    solid, a, b, c = choice_index(values, "solid"), values["a"], values["b"], values["c"]
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
    raise BadParameter(
        f"solid = {solid!r} is not a solid; lower solid to 0..{len(SOLIDS) - 1}",
        french=f"Solide n° {number(solid)} inconnu : choisissez entre 0 et {len(SOLIDS) - 1}.",
    )


def course_inertia(values: Values) -> MassProperties:
    """Mass, G and inertia at G in R_S from the course's formulary (5.4–5.7).

    The rod is the course's thin rod (``rod``: no moment about its own axis), not the thin
    cylinder the simulation needs.
    """
    return _course_inertia(tuple(float(values[n]) for n in SHAPE))


@lru_cache(maxsize=32)
def _course_inertia(shape: tuple[float, ...]) -> MassProperties:
    values = dict(zip(SHAPE, shape, strict=True))
    solid, mass = choice_index(values, "solid"), values["mass"]
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
    choice = choice_index(values, "point")
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


def flip_period(values: Values) -> float:
    """Course/Euler period [s] of the launched motion (nan if the moments are not distinct
    or the launch is exactly on an axis)."""
    props = course_inertia(values)
    moments, axes = principal_axes(props.inertia_G)
    k = choice_index(values, "spin_axis")
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
