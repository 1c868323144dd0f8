"""Torsors in the course's notation: resultant, moment at a point, transport, comoment.

An action torsor is {T} = (R, M_A) at A; a kinematic torsor {V} = (Ω, V_A) is stored the
same way with ``resultant = Ω`` and ``moment = V_A``. Both transport with
M_B = M_A + R ∧ AB, and the power of {T} in the motion {V} is their comoment.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


def _vec(value: ArrayLike, what: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (3,):
        raise ValueError(f"{what} must be a 3-vector, got shape {arr.shape!r}")
    return arr.copy()


@dataclass(frozen=True, init=False)
class Torsor:
    """A torsor reduced at ``point``.

    Any 3-vectors (lists, tuples, arrays) are accepted; they are stored as float copies.

    Attributes:
        resultant: Resultant R, shape (3,).
        moment: Moment at ``point``, shape (3,).
        point: Reduction point (world coordinates [m]), shape (3,).
    """

    resultant: np.ndarray
    moment: np.ndarray
    point: np.ndarray

    def __init__(
        self, resultant: ArrayLike, moment: ArrayLike, point: ArrayLike = (0.0, 0.0, 0.0)
    ) -> None:
        object.__setattr__(self, "resultant", _vec(resultant, "resultant"))
        object.__setattr__(self, "moment", _vec(moment, "moment"))
        object.__setattr__(self, "point", _vec(point, "point"))

    @classmethod
    def zero(cls, point: ArrayLike = (0.0, 0.0, 0.0)) -> Torsor:
        """The null torsor at ``point``."""
        return cls(np.zeros(3), np.zeros(3), point)

    def at(self, point: ArrayLike) -> Torsor:
        """Same torsor reduced at another point B: M_B = M_A + R ∧ AB."""
        b = _vec(point, "point")
        return Torsor(self.resultant, self.moment + np.cross(self.resultant, b - self.point), b)

    def __add__(self, other: Torsor) -> Torsor:
        o = other.at(self.point)
        return Torsor(self.resultant + o.resultant, self.moment + o.moment, self.point)

    def __neg__(self) -> Torsor:
        return Torsor(-self.resultant, -self.moment, self.point)

    def __sub__(self, other: Torsor) -> Torsor:
        return self + (-other)

    def comoment(self, other: Torsor) -> float:
        """R1·M2 + M1·R2 with both torsors at the same point (power when one is kinematic)."""
        o = other.at(self.point)
        return float(self.resultant @ o.moment + self.moment @ o.resultant)

    def automoment(self) -> float:
        """R·M, the same at every point."""
        return float(self.resultant @ self.moment)

    def in_basis(self, basis: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Components of (R, M) in an orthonormal basis.

        Args:
            basis: 3x3 matrix whose columns are the basis vectors in world coordinates.
        """
        b = np.asarray(basis, dtype=float)
        if b.shape != (3, 3):
            raise ValueError(f"basis must be a 3x3 matrix, got shape {b.shape!r}")
        return b.T @ self.resultant, b.T @ self.moment

    def __repr__(self) -> str:
        def f(v: np.ndarray) -> str:
            return "(" + ", ".join(f"{x:.6g}" for x in v) + ")"

        return f"{{R={f(self.resultant)}, M={f(self.moment)}}} at {f(self.point)}"


def kinematic_torsor(omega: ArrayLike, v_a: ArrayLike, point: ArrayLike) -> Torsor:
    """{V} = (Ω, V_A) at A, stored as a :class:`Torsor`."""
    return Torsor(omega, v_a, point)


def sum_torsors(torsors: Iterable[Torsor], point: ArrayLike = (0.0, 0.0, 0.0)) -> Torsor:
    """Sum of torsors, reduced at ``point``."""
    total = Torsor.zero(point)
    for t in torsors:
        total = total + t
    return total
