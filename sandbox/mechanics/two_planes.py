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
from dataclasses import dataclass, field

import numpy as np

from sandbox.mechanics.unbalance import PointMass
from sandbox.mechanics.vectors import cross


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


# -- the machine's two bearings, and the lab bench's soft supports ---------------------------
def split_across_axis(
    resultant: np.ndarray, moment_o: np.ndarray, p_a: np.ndarray, p_b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Forces F_a, F_b [N] across the line AB of two bearings at ``p_a``, ``p_b`` [m] whose
    sum is the action (R [N], M_O [N·m] at the origin O), world components, shape (3,).

    A ball joint at A and a linear annular joint at B make the guidance isostatic: the
    moment at A gives ``AB ∧ F_b = M_A⊥`` so ``F_b = (M_A ∧ n) / |AB|`` (n = AB/|AB|), and
    ``F_a = R⊥ − F_b``. The components along AB (an axial stop, the motor's torque) are
    dropped.

    Raises:
        ValueError: A and B coincide.
    """
    r = np.asarray(resultant, dtype=float)
    a, b = np.asarray(p_a, dtype=float), np.asarray(p_b, dtype=float)
    ab = b - a
    length = math.sqrt(float(ab @ ab))
    if not length > 0:
        raise ValueError(f"p_a and p_b must differ (one bearing), both {a.tolist()!r}")
    n = ab / length
    m_a = np.asarray(moment_o, dtype=float) - cross(a, r)
    f_b = cross(m_a, n) / length
    return r - float(r @ n) * n - f_b, f_b


@dataclass(frozen=True)
class SoftSupports:
    """A rigid rotor whose bearing housing hangs on isotropic springs (figure 40's bench).

    The housing and the rotor move together across the axis by small amounts: the point of
    the axis at abscissa ξ from the supports' centre M moves by ``w(ξ) = u + ξ ψ`` (complex
    ``y + i z``: u the translation of M, ψ the axis' slope). Springs and dampers act on u
    (``k_t``, ``c_t``) and on the tilt (``k_r``, ``c_r``); the rotor spins at ω with polar
    inertia A, whose gyroscopic moment stiffens the forward whirl (the ``+ω²A`` below).
    Linearised (course 7.2.1 with a moving axis), the synchronous response to the rotating
    unbalance is ``u = U e^{iωt}``, ``ψ = Ψ e^{iωt}`` (rotor-frame phases) with

        [k_t + iωc_t − ω²M    −ω²Q               ] [U]        [S  ]
        [−ω²Q                 k_r + iωc_r − ω²(J − A)] [Ψ] = ω² [C_M],

    S and C_M the static and couple unbalance about M.

    Attributes:
        mass: M, everything that vibrates (housing and rotor) [kg].
        first_moment: Q = Σ m ξ_G about M [kg·m].
        inertia: J, transverse moment of inertia of everything about M [kg·m²].
        polar: A, polar moment of inertia of the spinning rotor [kg·m²].
        k_t: Translational stiffness [N/m]; c_t its damping [N·s/m].
        k_r: Tilt stiffness [N·m/rad]; c_r its damping [N·m·s/rad].
    """

    mass: float
    first_moment: float
    inertia: float
    polar: float
    k_t: float
    c_t: float
    k_r: float
    c_r: float

    def response(self, static: complex, couple: complex, omega: float) -> tuple[complex, complex]:
        """(U [m], Ψ [rad]): steady synchronous motion of M and slope of the axis, in the
        rotor frame, for the unbalance S [kg·m] and C_M [kg·m²] about M at ω [rad/s]."""
        w2 = omega * omega
        a = np.array(
            [
                [self.k_t + 1j * omega * self.c_t - w2 * self.mass, -w2 * self.first_moment],
                [
                    -w2 * self.first_moment,
                    self.k_r + 1j * omega * self.c_r - w2 * (self.inertia - self.polar),
                ],
            ]
        )
        u, psi = np.linalg.solve(a, w2 * np.array([static, couple], dtype=complex))
        return complex(u), complex(psi)

    def critical_speeds(self) -> tuple[float, ...]:
        """Speeds [rad/s] at which the undamped synchronous response is infinite (forward
        whirl resonances), increasing: det = 0 is a quadratic in ω²."""
        j = self.inertia - self.polar
        a = self.mass * j - self.first_moment**2
        b = -(self.k_t * j + self.k_r * self.mass)
        c = self.k_t * self.k_r
        roots = np.roots([a, b, c]) if a != 0 else np.array([-c / b])
        real = [float(r.real) for r in np.atleast_1d(roots) if abs(r.imag) < 1e-9 * abs(r)]
        return tuple(sorted(math.sqrt(s) for s in real if s > 0))


def vibration(u: complex, psi: complex, xi: float, omega: float) -> complex:
    """Acceleration [m/s²] of the housing at abscissa ξ [m] from M, rotor-frame complex
    (amplitude and phase an accelerometer with a tachometer reads): −ω² (U + ξ Ψ)."""
    return -omega * omega * (u + xi * psi)


@dataclass(frozen=True)
class Whirl:
    """Steady synchronous vibration of a rotor and its housing on soft supports, in the
    rotor frame (components x, y, z; constant while everything turns together at ω).

    Attributes:
        d: Translation of the supports' centre M [m], shape (3,), no x component.
        phi: Small rotation vector of the housing (and the rotor's axis) [rad], shape (3,).
        omega: The speed [rad/s] it was computed for.
        rotor_resultant: The rotor's dynamic resultant [N] (= the bearings' action on it),
            rotor-frame components, shape (3,).
        rotor_moment: Its dynamic moment at M [N·m] (the bearings' action, the motor's
            axial torque aside), shape (3,).
    """

    d: np.ndarray
    phi: np.ndarray
    omega: float
    rotor_resultant: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotor_moment: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def bearing_forces(self, xi_a: float, xi_b: float) -> tuple[np.ndarray, np.ndarray]:
        """Forces [N] of the bearings at abscissae ξ_a, ξ_b from M on the rotor, rotor-frame
        components (:func:`split_across_axis` at their displaced positions)."""
        points = [xi * _X + self.displacement(xi) for xi in (xi_a, xi_b)]
        return split_across_axis(self.rotor_resultant, self.rotor_moment, *points)

    def displacement(self, xi: float) -> np.ndarray:
        """Displacement across the axis of the housing's point at abscissa ξ [m] from M."""
        return self.d + xi * np.cross(self.phi, _X)

    def acceleration(self, xi: float) -> complex:
        """Acceleration [m/s²] of the housing at ξ, rotor-frame complex ``y + i z``: the
        point runs on a circle at ω, so −ω² times its displacement."""
        w = self.displacement(xi)
        return -(self.omega**2) * complex(w[1], w[2])


_X = np.array([1.0, 0.0, 0.0])


def synchronous_whirl(
    *,
    omega: float,
    rotor_mass: float,
    rotor_com: np.ndarray,
    rotor_inertia: np.ndarray,
    housing_mass: float,
    housing_com: float,
    housing_inertia: float,
    supports: SoftSupports,
) -> Whirl:
    """The exact first-order steady vibration of figure 40's bench (no isotropy assumed).

    In the frame turning with the rotor, the steady state is a fixed pose: the housing
    translated by d and tilted by φ about M. The rotor then turns rigidly about the fixed
    axis (M, x) at ω, so course 7.2.1 gives its action exactly: resultant −ω² m G⊥ and
    moment at M ``ω² x ∧ (I_M x)``, with G and I_M those of the displaced, tilted rotor
    (to first order: ``I_M x`` gains ``φ ∧ I x − I (φ ∧ x) − m ξ_G d``). The housing (not
    turning) adds −ω² m_h times its centre's displacement and −ω² J_h φ. Springs and
    dampers give −k d − c ω x ∧ d (and the same with k_r, c_r on φ). Unlike
    :meth:`SoftSupports.response`, the rotor's own asymmetry (the unbalance masses' share
    of the inertia) is kept: the two differ by the ratio of the unbalance to the rotor.

    Args:
        omega: Speed [rad/s].
        rotor_mass: m [kg].
        rotor_com: G − M in the rotor frame [m], shape (3,) (its y, z: S / m).
        rotor_inertia: I at M in the rotor frame [kg·m²], shape (3, 3), products included.
        housing_mass: m_h [kg].
        housing_com: Abscissa of the housing's centre from M [m].
        housing_inertia: J_h, its transverse moment of inertia at its centre [kg·m²].
        supports: Stiffnesses and dampings (its inertia fields are not used).
    """
    w2 = omega * omega
    g0 = np.asarray(rotor_com, dtype=float)
    i0 = np.asarray(rotor_inertia, dtype=float)
    ix0 = i0 @ _X
    s = supports

    def rotor(d: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g = g0 + d + np.cross(phi, g0)
        ix = ix0 + np.cross(phi, ix0) - i0 @ np.cross(phi, _X) - rotor_mass * g0[0] * d
        force = -w2 * rotor_mass * g
        force[0] = 0.0
        return force, w2 * np.cross(_X, ix)

    def residual(q: np.ndarray) -> np.ndarray:
        d = np.array([0.0, q[0], q[1]])
        phi = np.array([0.0, q[2], q[3]])
        w_h = d + housing_com * np.cross(phi, _X)
        r_force, r_moment = rotor(d, phi)
        force = r_force - w2 * housing_mass * w_h
        force[0] = 0.0
        moment = (
            np.cross(housing_com * _X, -w2 * housing_mass * w_h)
            - w2 * housing_inertia * phi
            + r_moment
        )
        f_ext = -s.k_t * d - s.c_t * omega * np.cross(_X, d)
        m_ext = -s.k_r * phi - s.c_r * omega * np.cross(_X, phi)
        return np.concatenate([(force - f_ext)[1:], (moment - m_ext)[1:]])

    b = residual(np.zeros(4))
    a = np.stack([residual(e) - b for e in np.eye(4)], axis=1)
    q = np.linalg.solve(a, -b)
    d, phi = np.array([0.0, q[0], q[1]]), np.array([0.0, q[2], q[3]])
    return Whirl(d, phi, float(omega), *rotor(d, phi))
