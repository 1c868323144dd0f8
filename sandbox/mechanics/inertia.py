"""Inertia matrices with the course's signs, Huygens, principal axes and simple shapes.

I = [[A, -F, -E], [-F, B, -D], [-E, -D, C]] with A = ∫(y²+z²)dm, B = ∫(x²+z²)dm,
C = ∫(x²+y²)dm, D = ∫yz dm, E = ∫xz dm, F = ∫xy dm (course section 5.2).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


def inertia_matrix(
    A: float, B: float, C: float, D: float = 0.0, E: float = 0.0, F: float = 0.0
) -> np.ndarray:
    """3x3 matrix from the course's coefficients [kg·m²]."""
    return np.array([[A, -F, -E], [-F, B, -D], [-E, -D, C]], dtype=float)


def coefficients(inertia: ArrayLike) -> tuple[float, float, float, float, float, float]:
    """(A, B, C, D, E, F) of a 3x3 inertia matrix, with the course's signs."""
    i = np.asarray(inertia, dtype=float)
    return (
        float(i[0, 0]),
        float(i[1, 1]),
        float(i[2, 2]),
        float(-i[1, 2]),
        float(-i[0, 2]),
        float(-i[0, 1]),
    )


def _huygens_term(mass: float, ga: ArrayLike) -> np.ndarray:
    a, b, c = np.asarray(ga, dtype=float)
    return mass * np.array(
        [
            [b * b + c * c, -a * b, -a * c],
            [-a * b, a * a + c * c, -b * c],
            [-a * c, -b * c, a * a + b * b],
        ]
    )


def huygens(inertia_G: ArrayLike, mass: float, GA: ArrayLike) -> np.ndarray:
    """I_A = I_G + I_A^H with GA = (a, b, c) (course 5.5)."""
    return np.asarray(inertia_G, dtype=float) + _huygens_term(mass, GA)


def huygens_to_G(inertia_A: ArrayLike, mass: float, GA: ArrayLike) -> np.ndarray:
    """I_G = I_A − I_A^H: Huygens backwards, from any point A to G."""
    return np.asarray(inertia_A, dtype=float) - _huygens_term(mass, GA)


def move_inertia(
    inertia_A: ArrayLike, mass: float, G: ArrayLike, A: ArrayLike, B: ArrayLike
) -> np.ndarray:
    """I_B from I_A, through G as the course insists: I_B = I_A − I_A^H + I_B^H."""
    g = np.asarray(G, dtype=float)
    i_g = huygens_to_G(inertia_A, mass, np.asarray(A, dtype=float) - g)
    return huygens(i_g, mass, np.asarray(B, dtype=float) - g)


def rotation_matrix(axis: ArrayLike, angle_rad: float) -> np.ndarray:
    """Rotation of ``angle_rad`` about the unit direction of ``axis`` (Rodrigues)."""
    k = np.asarray(axis, dtype=float)
    norm = np.linalg.norm(k)
    if norm == 0:
        raise ValueError(f"axis must be non-zero, got {axis!r}")
    k = k / norm
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle_rad) * kx + (1 - np.cos(angle_rad)) * kx @ kx


def change_basis(inertia: ArrayLike, rotation: ArrayLike) -> np.ndarray:
    """The matrix in a new basis whose vectors are the columns of ``rotation``: Rᵀ I R."""
    r = np.asarray(rotation, dtype=float)
    return r.T @ np.asarray(inertia, dtype=float) @ r


def principal_axes(inertia: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(principal moments ascending, right-handed basis with the principal axes as columns)."""
    moments, basis = np.linalg.eigh(np.asarray(inertia, dtype=float))
    if np.linalg.det(basis) < 0:
        basis[:, 2] = -basis[:, 2]
    return moments, basis


def _check(**values: float) -> None:
    for name, value in values.items():
        if not np.isfinite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")


def block(mass: float, a: float, b: float, c: float) -> np.ndarray:
    """Block (pavé) at G, edges a, b, c along x, y, z (course 5.6.1)."""
    _check(mass=mass, a=a, b=b, c=c)
    return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * mass / 12.0


def cylinder(mass: float, radius: float, height: float) -> np.ndarray:
    """Solid cylinder at G, axis z (course 5.6.2)."""
    _check(mass=mass, radius=radius, height=height)
    t = mass * (radius**2 / 4.0 + height**2 / 12.0)
    return np.diag([t, t, mass * radius**2 / 2.0])


def hollow_cylinder(
    mass: float, outer_radius: float, inner_radius: float, height: float
) -> np.ndarray:
    """Tube at G, axis z: full cylinder minus the hole (mass = the tube's)."""
    _check(mass=mass, outer_radius=outer_radius, inner_radius=inner_radius, height=height)
    if inner_radius >= outer_radius:
        raise ValueError(
            f"inner_radius {inner_radius!r} must be below outer_radius {outer_radius!r}"
        )
    r2 = outer_radius**2 + inner_radius**2
    t = mass * (r2 / 4.0 + height**2 / 12.0)
    return np.diag([t, t, mass * r2 / 2.0])


def sphere(mass: float, radius: float) -> np.ndarray:
    """Solid sphere at G (course 5.6.3)."""
    _check(mass=mass, radius=radius)
    return np.eye(3) * 2.0 * mass * radius**2 / 5.0


def rod(mass: float, length: float) -> np.ndarray:
    """Thin rod at G, axis z."""
    _check(mass=mass, length=length)
    return np.diag([1.0, 1.0, 0.0]) * mass * length**2 / 12.0


def point_mass(mass: float, position: ArrayLike) -> np.ndarray:
    """Inertia at the origin of a point mass at ``position``."""
    _check(mass=mass)
    return _huygens_term(mass, -np.asarray(position, dtype=float))


@dataclass(frozen=True)
class MassProperties:
    """Mass [kg], centre of mass G [m] and inertia at G in world axes [kg·m²]."""

    mass: float
    com: np.ndarray
    inertia_G: np.ndarray

    @classmethod
    def of_shape(
        cls, inertia_G: ArrayLike, mass: float, com: ArrayLike, rotation: ArrayLike | None = None
    ) -> MassProperties:
        """A shape whose own-axes inertia is rotated into world axes (columns = own axes)."""
        i = np.asarray(inertia_G, dtype=float)
        if rotation is not None:
            r = np.asarray(rotation, dtype=float)
            i = r @ i @ r.T
        return cls(float(mass), np.asarray(com, dtype=float), i)

    def inertia_at(self, point: ArrayLike) -> np.ndarray:
        """I at ``point`` by Huygens."""
        return huygens(self.inertia_G, self.mass, np.asarray(point, dtype=float) - self.com)

    def __add__(self, other: MassProperties) -> MassProperties:
        return combine((self, other))


def combine(parts: Iterable[MassProperties]) -> MassProperties:
    """One solid from several rigidly joined ones (barycentre, Huygens both ways)."""
    items = [p for p in parts if p.mass > 0]
    mass = sum(p.mass for p in items)
    if mass == 0:
        return MassProperties(0.0, np.zeros(3), np.zeros((3, 3)))
    com = sum((p.mass * p.com for p in items), np.zeros(3)) / mass
    inertia_o = sum(p.inertia_at(com) for p in items)
    return MassProperties(mass, com, np.asarray(inertia_o))


def elliptic_k(k: float) -> float:
    """Complete elliptic integral of the first kind K(k), modulus ``k`` in [0, 1), by the
    arithmetic-geometric mean: K = π / (2 AGM(1, √(1 − k²)))."""
    if not 0.0 <= k < 1.0:
        raise ValueError(f"modulus k must be in [0, 1), got {k!r}")
    a, b = 1.0, float(np.sqrt(1.0 - k * k))
    for _ in range(60):
        if abs(a - b) <= 1e-16 * a:
            break
        a, b = (a + b) / 2.0, float(np.sqrt(a * b))
    return float(np.pi / (2.0 * a))


def torque_free_period(moments: ArrayLike, omega: ArrayLike) -> float:
    """Period [s] of ω seen from the solid in a torque-free rotation about G (Euler).

    ``moments`` are the principal moments I₁ < I₂ < I₃ [kg·m²] and ``omega`` the initial
    rotation vector in the principal basis [rad/s]. With 2T = Σ Iᵢωᵢ² and σ² = Σ Iᵢ²ωᵢ²,
    the components follow Jacobi's functions sn, cn, dn of modulus k (Landau and Lifshitz,
    Mechanics §37); for σ² > 2T I₂ (ω closer to axis 3, or near axis 2 leaning to 3):
    λ² = (I₃ − I₂)(σ² − 2T I₁)/(I₁I₂I₃), k² = (I₂ − I₁)(2T I₃ − σ²)/((I₃ − I₂)(σ² − 2T I₁)),
    and axes 1 and 3 swap roles for σ² < 2T I₂. The components ω₁ (or ω₃) and ω₂ return
    after 4K(k)/λ: the period of a flip about the intermediate axis and back. Axes 1 and 3
    themselves come back after half of it (their angle to ω has period 2K(k)/λ).

    Raises:
        ValueError: if the moments are not strictly increasing or ω sits on the separatrix
            (σ² = 2T I₂: an infinitely slow flip).
    """
    i1, i2, i3 = (float(x) for x in np.asarray(moments, dtype=float))
    if not 0.0 < i1 < i2 < i3:
        raise ValueError(f"moments must be 0 < I1 < I2 < I3, got {moments!r}")
    w = np.asarray(omega, dtype=float)
    i = np.array([i1, i2, i3])
    two_t = float(np.sum(i * w * w))
    s2 = float(np.sum((i * w) ** 2))
    if s2 > two_t * i2:
        lam2 = (i3 - i2) * (s2 - two_t * i1) / (i1 * i2 * i3)
        k2 = (i2 - i1) * (two_t * i3 - s2) / ((i3 - i2) * (s2 - two_t * i1))
    elif s2 < two_t * i2:
        lam2 = (i2 - i1) * (two_t * i3 - s2) / (i1 * i2 * i3)
        k2 = (i3 - i2) * (s2 - two_t * i1) / ((i2 - i1) * (two_t * i3 - s2))
    else:
        raise ValueError("ω lies on the separatrix (σ² = 2T I2): the flip never ends")
    return 4.0 * elliptic_k(float(np.sqrt(max(k2, 0.0)))) / float(np.sqrt(lam2))
