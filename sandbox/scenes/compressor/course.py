"""Closed forms of the micro-compressor (course sections 1, 4, 7.3): the slider-crank's
exact kinematics, the force the moving parts transmit to the frame and the motor torque.

λ = R sin θ + √(L² − R² cos² θ); every centre of mass moves on a known curve, so the force
the moving parts transmit to the frame is −Σ m_i Γ(G_i), and the kinetic-energy theorem
gives the motor torque C_mot ω = dT/dt (course, constant ω).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sandbox.physics.spec import Values
from sandbox.scenes.compressor.params import RPM
from sandbox.scenes.slider_crank import fit_orders

HARMONIC_SAMPLES = 64
"""Samples per revolution for the pilon's orders 1 and 2."""


@dataclass(frozen=True)
class Kinematics:
    """Slider-crank kinematics at crank angle θ [rad], speed ω = θ' [rad/s] and angular
    acceleration α = θ'' [rad/s²] (exact, every harmonic).

    Positions [m], velocities [m/s], accelerations [m/s²] in B0 (x, y); φ is the rod's
    angle from y0 to y2 about z0, with its rates. ``lam_theta`` = dλ/dθ [m] and
    ``phi_theta`` = dφ/dθ: the velocities are ``lam_theta`` ω and ``phi_theta`` ω, and the
    accelerations gain ``lam_theta`` α and ``phi_theta`` α when the speed changes.
    """

    theta: float
    omega: float
    lam: float
    dlam: float
    ddlam: float
    phi: float
    dphi: float
    ddphi: float
    alpha: float = 0.0
    lam_theta: float = 0.0
    phi_theta: float = 0.0


def kinematics(
    theta: float,
    omega: float,
    R: float,
    L: float,
    *,
    alpha: float = 0.0,
    sin_cos: tuple[float, float] | None = None,
) -> Kinematics:
    """λ = R sin θ + √(L² − R² cos² θ) and its derivatives; sin φ = R cos θ / L.

    With q = √(L² − R² cos² θ): λ_θ = R cos θ + R² sin θ cos θ / q,
    λ_θθ = −R sin θ + R² (cos² θ − sin² θ) / q − R⁴ sin² θ cos² θ / q³, and
    λ'' = λ_θθ ω² + λ_θ α; φ_θ = −R sin θ / (L cos φ),
    φ_θθ = −(R / L) (cos θ / cos φ + sin θ sin φ φ_θ / cos² φ), φ'' = φ_θθ ω² + φ_θ α.

    ``sin_cos``: (sin θ, cos θ) when the caller has them more exactly than from ``theta``
    (a throw's phase subtracted from a crank angle of millions of radians loses the
    angle's last digits; a rotation of the crank's own sine and cosine does not).
    """
    s, c = (math.sin(theta), math.cos(theta)) if sin_cos is None else sin_cos
    lam, dlam, ddlam, phi, dphi, ddphi, lam_t, phi_t = loop(s, c, omega, alpha, R, L)
    return Kinematics(
        theta, omega, lam, dlam, ddlam, phi, dphi, ddphi, alpha, lam_t, phi_t
    )  # fmt: skip


def loop(
    s: float, c: float, omega: float, alpha: float, R: float, L: float
) -> tuple[float, float, float, float, float, float, float, float]:
    """(λ, λ', λ'', φ, φ', φ'', λ_θ, φ_θ) of the slider-crank at sin θ = ``s``,
    cos θ = ``c``, θ' = ``omega``, θ'' = ``alpha`` (:func:`kinematics`'s formulas, as a
    tuple: the imposed motion evaluates them at every frame)."""
    q = math.sqrt(L * L - R * R * c * c)
    lam = R * s + q
    lam_t = R * c + R * R * s * c / q
    lam_tt = -R * s + R * R * (c * c - s * s) / q - R**4 * s * s * c * c / q**3
    sin_phi = R * c / L
    phi = math.asin(sin_phi)
    cp = math.cos(phi)
    phi_t = -R * s / (L * cp)
    phi_tt = -(R / L) * (c / cp + s * sin_phi * phi_t / cp**2)
    w2 = omega * omega
    return (
        lam,
        lam_t * omega,
        lam_tt * w2 + lam_t * alpha,
        phi,
        phi_t * omega,
        phi_tt * w2 + phi_t * alpha,
        lam_t,
        phi_t,
    )


def _crank_mass_moment(v: Values) -> float:
    """Σ m·(distance along x1) of the crank and its counterweight [kg·m]."""
    return v["m1"] * v["d1"] - v["counterweight_mass"] * v["counterweight_radius"]


def _crank_point(theta: float, omega: float, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """(∂P/∂θ, Γ(P)) of a crank point at unit distance from O on x1: y1 and
    −ω² x1 + α y1 (x1 = (cos θ, sin θ), y1 = (−sin θ, cos θ) in B0)."""
    s, c = math.sin(theta), math.cos(theta)
    x1, y1 = np.array([c, s]), np.array([-s, c])
    return y1, -(omega**2) * x1 + alpha * y1


def frame_force(theta: float, omega: float, v: Values, *, alpha: float = 0.0) -> np.ndarray:
    """Force (x0, y0) the moving parts transmit to the frame: −Σ m_i Γ(G_i) [N].

    Exact slider-crank at θ, ω = θ' and α = θ'' (α = 0: the course's constant speed).
    G1 and the counterweight are on x1, G3 moves with B (Γ(B) = λ'' y0) and G2 lies on AB
    at AG2 = d2: Γ(G2) = (1 − d2/L) Γ(A) + (d2/L) Γ(B).
    """
    k = kinematics(theta, omega, v["R"], v["L"], alpha=alpha)
    _, unit = _crank_point(theta, omega, alpha)
    g_a = v["R"] * unit
    g_b = np.array([0.0, k.ddlam])
    w = v["d2"] / v["L"]
    g_2 = (1 - w) * g_a + w * g_b
    total = _crank_mass_moment(v) * unit + v["m2"] * g_2 + v["m3"] * g_b
    return -total


def motor_torque(theta: float, omega: float, v: Values, *, alpha: float = 0.0) -> float:
    """C_mot: torque the motor passes on to the crank (its rotor's own J α excluded) [N·m].

    Virtual power (Lagrange on θ; at constant ω it is the course's C_mot ω = dT/dt):
    C_mot = (C1 + m_cw r_cw²) α + m2 Γ(G2)·∂G2/∂θ + m3 λ'' λ_θ + I_G2,z φ'' φ_θ, with
    I_G2,z = C2 − m2 d2² and ∂G2/∂θ = (1 − d2/L) R y1 + (d2/L) λ_θ y0. Defined at ω = 0
    too (a start from rest: C_mot = inertia seen by the motor × α).
    """
    k = kinematics(theta, omega, v["R"], v["L"], alpha=alpha)
    y1, unit = _crank_point(theta, omega, alpha)
    w = v["d2"] / v["L"]
    dg_2 = (1 - w) * v["R"] * y1 + w * np.array([0.0, k.lam_theta])
    g_2 = (1 - w) * v["R"] * unit + w * np.array([0.0, k.ddlam])
    i_g2 = v["C2"] - v["m2"] * v["d2"] ** 2
    i_crank = v["C1"] + v["counterweight_mass"] * v["counterweight_radius"] ** 2
    return (
        i_crank * alpha
        + v["m2"] * float(g_2 @ dg_2)
        + v["m3"] * k.ddlam * k.lam_theta
        + i_g2 * k.ddphi * k.phi_theta
    )


def reference(v: Values) -> dict[str, float]:
    """The course's constant values at ``speed_rpm``: ω, the pilon's orders 1 and 2 and the
    tamis' order 1 (angle-dependent ones are readouts: pilon_ref, tamis_ref...)."""
    omega = v["speed_rpm"] * RPM
    thetas = np.linspace(0, 2 * math.pi, HARMONIC_SAMPLES, endpoint=False)
    forces = np.array([frame_force(t, omega, v) for t in thetas])
    amp = fit_orders(thetas, forces[:, 1])
    tamis = fit_orders(thetas, forces[:, 0])
    return {
        "omega": omega,
        "pilon_h1": float(amp[1]),
        "pilon_h2": float(amp[2]),
        "tamis_h1": float(tamis[1]),
    }
