"""Two-plane balancing of a rigid rotor: the wheel-balancing machine (course 7.1, 7.2).

Rotor turning at ω about (O, x); vectors across the axis are complex numbers in the rotor
frame, ``y + i z`` (angles from y towards z, as :mod:`sandbox.mechanics.unbalance`):

- static unbalance ``S = m (Y_y + i Y_z)`` [kg·m], couple unbalance ``C = F + i E`` [kg·m²]
  (the products of inertia of the x column, course 7.2.1);
- a mass m at radius r, angle φ, abscissa x adds ``u = m r e^{iφ}`` to S and ``x u`` to C.

**Bearing forces.** The machine's shaft rests on two bearings at abscissae ``x_a`` and
``x_b``; ``P_a``, ``P_b`` are the rotating forces the rotor applies to them [N] (what the
machine's sensors read), constant in the rotor frame. The PFD of 7.2.1 (resultant
``−ω² S`` and moment at O ``ω² (E y − F z)`` from the frame) reads

    P_a + P_b = ω² S,        x_a P_a + x_b P_b = ω² C,

so the forces give S and C back, and S and C give the forces.

**Correction.** Masses ``u_in = m_in r_in e^{iφ_in}`` and ``u_out`` in the rim planes
``x_in`` and ``x_out`` balance the wheel dynamically (G on the axis and E = F = 0, 7.2.3) when
``u_in + u_out = −S`` and ``x_in u_in + x_out u_out = −C``.

**Influence coefficients** (figure 40's bench, the helicopter's accelerometers): a sensor's
vibration is linear in the unbalance, ``V = V₀ + H u`` with ``u = (u_in, u_out)`` the
added unbalances and H an unknown 2×2 complex matrix. One run with a trial mass in each
plane (the previous trial removed) gives each column of H, and ``u = −H⁻¹ V₀`` cancels V.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np

from sandbox.mechanics.unbalance import PointMass


@dataclass(frozen=True)
class Clips:
    """The two clip-on masses the machine asks for: mass [g] and angle [°] in [0, 360)
    from the rotor's y axis towards z, in the inner and outer rim planes."""

    clip_inner_g: float
    clip_inner_deg: float
    clip_outer_g: float
    clip_outer_deg: float

    def unbalances(self, radius_inner: float, radius_outer: float) -> tuple[complex, complex]:
        """(u_in, u_out) = m r e^{iφ} [kg·m] of the clips at the rims' radii [m]."""
        return (
            clip_unbalance(self.clip_inner_g, self.clip_inner_deg, radius_inner),
            clip_unbalance(self.clip_outer_g, self.clip_outer_deg, radius_outer),
        )

    def point_masses(
        self, *, x_inner: float, x_outer: float, radius_inner: float, radius_outer: float
    ) -> tuple[PointMass, PointMass]:
        """The clips as :class:`~sandbox.mechanics.unbalance.PointMass` (mass in kg)."""
        return (
            PointMass(self.clip_inner_g / 1000, x_inner, radius_inner, self.clip_inner_deg),
            PointMass(self.clip_outer_g / 1000, x_outer, radius_outer, self.clip_outer_deg),
        )


def to_complex(vector: np.ndarray) -> complex:
    """A rotor-frame 2-vector (y, z) as y + i z."""
    return complex(float(vector[0]), float(vector[1]))


def to_vector(value: complex) -> np.ndarray:
    """y + i z as the 2-vector (y, z), shape (2,)."""
    return np.array([value.real, value.imag])


def clip_unbalance(mass_g: float, angle_deg: float, radius: float) -> complex:
    """m r e^{iφ} [kg·m] of a mass ``mass_g`` [g] at ``radius`` [m] and ``angle_deg`` [°]."""
    return mass_g / 1000 * radius * cmath.exp(1j * math.radians(angle_deg))


def _clip(u: complex, radius: float) -> tuple[float, float]:
    """(grams, degrees in [0, 360)) of the mass at ``radius`` whose unbalance is u."""
    grams = abs(u) / radius * 1000
    angle = math.degrees(cmath.phase(u)) % 360.0 if grams > 0 else 0.0
    return grams, (0.0 if angle >= 360.0 else angle)


def _check_positive(**values: float) -> None:
    for name, value in values.items():
        if not value > 0:
            raise ValueError(f"{name} must be > 0, got {value!r}")


def _check_distinct(name_a: str, a: float, name_b: str, b: float) -> None:
    if a == b:
        raise ValueError(f"{name_a} and {name_b} must differ (one plane), both {a!r}")


def bearing_forces(
    static: complex, couple: complex, *, x_a: float, x_b: float, omega: float
) -> tuple[complex, complex]:
    """(P_a, P_b) [N]: forces the rotor applies to its bearings at x_a and x_b [m].

    P_b = ω² (C − x_a S) / (x_b − x_a), P_a = ω² S − P_b.

    Raises:
        ValueError: x_a == x_b or omega < 0.
    """
    _check_distinct("x_a", x_a, "x_b", x_b)
    if not omega >= 0:
        raise ValueError(f"omega must be >= 0, got {omega!r}")
    w2 = omega * omega
    p_b = w2 * (couple - x_a * static) / (x_b - x_a)
    return w2 * static - p_b, p_b


def unbalance_from_bearings(
    p_a: complex, p_b: complex, *, x_a: float, x_b: float, omega: float
) -> tuple[complex, complex]:
    """(S [kg·m], C [kg·m²]) from the bearing forces: S = (P_a + P_b)/ω²,
    C = (x_a P_a + x_b P_b)/ω².

    Raises:
        ValueError: x_a == x_b or omega <= 0 (no force to measure at rest).
    """
    _check_distinct("x_a", x_a, "x_b", x_b)
    _check_positive(omega=omega)
    w2 = omega * omega
    return (p_a + p_b) / w2, (x_a * p_a + x_b * p_b) / w2


def correction(
    static: complex,
    couple: complex,
    *,
    x_inner: float,
    x_outer: float,
    radius_inner: float,
    radius_outer: float,
) -> Clips:
    """The clips in the planes x_inner, x_outer [m] at the rims' radii [m] that cancel S and C.

    u_out = (x_in S − C) / (x_out − x_in), u_in = −S − u_out (course 7.2.3).

    Raises:
        ValueError: the planes coincide or a radius is not positive.
    """
    _check_distinct("x_inner", x_inner, "x_outer", x_outer)
    _check_positive(radius_inner=radius_inner, radius_outer=radius_outer)
    u_out = (x_inner * static - couple) / (x_outer - x_inner)
    u_in = -static - u_out
    g_in, a_in = _clip(u_in, radius_inner)
    g_out, a_out = _clip(u_out, radius_outer)
    return Clips(g_in, a_in, g_out, a_out)


def clips_from_bearings(
    p_a: complex,
    p_b: complex,
    *,
    x_a: float,
    x_b: float,
    omega: float,
    x_inner: float,
    x_outer: float,
    radius_inner: float,
    radius_outer: float,
) -> Clips:
    """What the machine does: bearing forces [N] → S and C → clips (see :func:`correction`)."""
    s, c = unbalance_from_bearings(p_a, p_b, x_a=x_a, x_b=x_b, omega=omega)
    return correction(
        s,
        c,
        x_inner=x_inner,
        x_outer=x_outer,
        radius_inner=radius_inner,
        radius_outer=radius_outer,
    )


def influence_matrix(
    v0: np.ndarray,
    v_inner: np.ndarray,
    v_outer: np.ndarray,
    trial_inner: complex,
    trial_outer: complex,
) -> np.ndarray:
    """H [sensor unit per kg·m], shape (2, 2): column j = (V_j − V₀) / trial_j.

    Args:
        v0: The two sensors' vibration vectors without trial mass, complex, shape (2,).
        v_inner: The same with only the trial mass of the inner plane.
        v_outer: The same with only the trial mass of the outer plane.
        trial_inner: m r e^{iφ} [kg·m] of the inner trial mass (:func:`clip_unbalance`).
        trial_outer: Likewise for the outer one.

    Raises:
        ValueError: a trial unbalance is zero or a vector does not have two sensors.
    """
    arrays = {"v0": v0, "v_inner": v_inner, "v_outer": v_outer}
    vs = {k: np.asarray(a, dtype=complex) for k, a in arrays.items()}
    for name, v in vs.items():
        if v.shape != (2,):
            raise ValueError(f"{name} must hold two sensors' vectors, got shape {v.shape}")
    for name, t in (("trial_inner", trial_inner), ("trial_outer", trial_outer)):
        if t == 0:
            raise ValueError(f"{name} must be a nonzero unbalance, got {t!r}")
    return np.stack(
        [(vs["v_inner"] - vs["v0"]) / trial_inner, (vs["v_outer"] - vs["v0"]) / trial_outer],
        axis=1,
    )


def influence_correction(
    v0: np.ndarray,
    v_inner: np.ndarray,
    v_outer: np.ndarray,
    trial_inner: complex,
    trial_outer: complex,
    *,
    radius_inner: float,
    radius_outer: float,
) -> Clips:
    """The clips (trial masses removed) that cancel V₀: u = −H⁻¹ V₀.

    Raises:
        ValueError: as :func:`influence_matrix`, a radius is not positive, or H is
            singular (the trials moved the sensors alike: the planes are not told apart).
    """
    _check_positive(radius_inner=radius_inner, radius_outer=radius_outer)
    h = influence_matrix(v0, v_inner, v_outer, trial_inner, trial_outer)
    scale = float(np.abs(h).max())
    if scale == 0 or abs(np.linalg.det(h)) <= 1e-12 * scale * scale:
        raise ValueError(
            "v_inner, v_outer: the trial runs give a singular influence matrix; "
            "place the trial masses in two planes that the sensors tell apart"
        )
    u = np.linalg.solve(h, -np.asarray(v0, dtype=complex))
    g_in, a_in = _clip(complex(u[0]), radius_inner)
    g_out, a_out = _clip(complex(u[1]), radius_outer)
    return Clips(g_in, a_in, g_out, a_out)
