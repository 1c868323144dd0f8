"""Static and couple unbalance of a rotor turning about (O, x) (course section 7.2).

In the rotor frame (x along the axis, angles measured from y towards z), a point mass m at
(x, r cos φ, r sin φ) adds

- ``m r (cos φ, sin φ)`` to the **static unbalance** ``m·OG⊥ = (m Y_y, m Y_z)`` [kg·m],
  whose rotating resultant is ``ω² m OG⊥`` (zero if and only if G is on the axis);
- ``x m r (cos φ, sin φ)`` to the **couple unbalance** ``(F, E) = (∫x y dm, ∫x z dm)``
  [kg·m²], the products of inertia of the x column, whose rotating moment at O is
  ``ω² (E y⃗ − F z⃗)``.

The rotor is balanced dynamically when both vectors are zero. Two masses in two planes
x = x₁ and x = x₂ give four unknowns for these four equations (:func:`two_planes`).
Numpy only: vectors are 2-component arrays (y, z) in the rotor frame.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PointMass:
    """A mass on the rotor: ``mass`` [kg] at abscissa ``x`` [m], radius ``radius`` [m] and
    angle ``angle_deg`` [°] from y towards z."""

    mass: float
    x: float
    radius: float
    angle_deg: float

    @property
    def static(self) -> np.ndarray:
        """Its static unbalance m r (cos φ, sin φ) [kg·m], shape (2,)."""
        a = math.radians(self.angle_deg)
        return self.mass * self.radius * np.array([math.cos(a), math.sin(a)])

    @property
    def couple(self) -> np.ndarray:
        """Its couple unbalance x m r (cos φ, sin φ) = its (F, E) [kg·m²], shape (2,)."""
        return self.x * self.static


def polar(vector: np.ndarray) -> tuple[float, float]:
    """(norm, angle [°] in (-180, 180]) of a 2-vector (y, z); angle 0 for the zero vector."""
    y, z = float(vector[0]), float(vector[1])
    norm = math.hypot(y, z)
    return norm, (math.degrees(math.atan2(z, y)) if norm > 0 else 0.0)


def rotating_loads(static: np.ndarray, couple: np.ndarray, omega: float) -> np.ndarray:
    """Rotating action of the frame on the rotor (course 7.2.1), rotor-frame components.

    Args:
        static: m·OG⊥ [kg·m], shape (2,).
        couple: (F, E) [kg·m²], shape (2,).
        omega: Rotation speed [rad/s].

    Returns:
        (R_y, R_z, M_y, M_z): resultant ``-ω² m OG⊥`` [N] and moment at O
        ``ω² (E y⃗ − F z⃗)`` [N·m].
    """
    w2 = omega * omega
    f, e = float(couple[0]), float(couple[1])
    return np.array([-w2 * static[0], -w2 * static[1], w2 * e, -w2 * f])


def two_planes(
    static: np.ndarray, couple: np.ndarray, x1: float, x2: float, radius: float
) -> tuple[PointMass, PointMass]:
    """The two correction masses at ``radius`` in the planes ``x1`` and ``x2`` that cancel
    a static unbalance and a couple unbalance (course 7.2.3: G on the axis, E = F = 0).

    Solves u₁ + u₂ = −S and x₁ u₁ + x₂ u₂ = −C for the masses' static vectors u₁, u₂.

    Raises:
        ValueError: the planes coincide (one plane cannot cancel a couple) or radius <= 0.
    """
    if x1 == x2 or radius <= 0:
        raise ValueError("two distinct planes and a positive radius are needed")
    s = np.asarray(static, dtype=float)
    c = np.asarray(couple, dtype=float)
    u2 = (x1 * s - c) / (x2 - x1)
    u1 = -s - u2
    out = []
    for x, u in ((x1, u1), (x2, u2)):
        norm, angle = polar(u)
        out.append(PointMass(norm / radius, x, radius, angle))
    return out[0], out[1]


@dataclass(frozen=True)
class Unbalance:
    """The rotor's unbalance vectors in the rotor frame, components (y₁, z₁).

    Attributes:
        static: m·OG⊥ of "rotor", "m1", "m2" [kg·m], each shape (2,).
        couple: (F, E) of the same parts [kg·m²], each shape (2,).
    """

    static: Mapping[str, np.ndarray]
    couple: Mapping[str, np.ndarray]

    @property
    def static_total(self) -> np.ndarray:
        """m·OG⊥ of the whole rotor [kg·m]."""
        return np.sum(list(self.static.values()), axis=0)

    @property
    def couple_total(self) -> np.ndarray:
        """(F, E) of the whole rotor [kg·m²]."""
        return np.sum(list(self.couple.values()), axis=0)
