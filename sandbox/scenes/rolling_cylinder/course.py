"""Closed forms of the rolling cylinder (course 3.2 remark 1, 6.1.3, 6.2): inertia, least
friction for rolling, acceleration rolling or slipping, and with an eccentric mass the
acceleration and the plane's normal force along the motion (energy theorem)."""

from __future__ import annotations

import math

from sandbox.physics.spec import Values

G = 9.81


def axis_inertia(v: Values) -> float:
    """Inertia of the cylinder about its axis: ½ m (R² + r²)."""
    return 0.5 * v["mass"] * (v["R"] ** 2 + v["inner_radius"] ** 2)


def mass_properties(v: Values) -> tuple[float, float, float]:
    """Total mass, distance e from the axis to G, inertia about G's axis (y)."""
    m_c, m_e, r_e = v["mass"], v["eccentric_mass"], v["eccentric_radius"]
    m = m_c + m_e
    e = m_e * r_e / m
    i_g = axis_inertia(v) + m_c * e * e + m_e * (r_e - e) ** 2
    return m, e, i_g


def mu_min(v: Values) -> float:
    """Least friction for rolling without slipping: tan α / (1 + m R² / I) (homogeneous)."""
    alpha = math.radians(v["slope_deg"])
    return math.tan(alpha) / (1 + v["mass"] * v["R"] ** 2 / axis_inertia(v))


def acceleration(v: Values) -> float:
    """Acceleration of the centre down the slope (homogeneous): rolling if μ ≥ μ_min,
    a = g sin α / (1 + I/(mR²)); else slipping, a = g (sin α − μ cos α)."""
    alpha = math.radians(v["slope_deg"])
    if v["mu"] >= mu_min(v):
        return G * math.sin(alpha) / (1 + axis_inertia(v) / (v["mass"] * v["R"] ** 2))
    return G * (math.sin(alpha) - v["mu"] * math.cos(alpha))


def eccentric_acceleration(beta: float, v_c: float, v: Values) -> float:
    """Rolling with G off the axis, from the energy theorem (Lagrange on φ = x_C / R).

    β is the angle of CG from the plane's normal towards the slope; T = ½ J_A(β) φ'²
    with J_A = I_G + m (e² + R² + 2 R e cos β), V = −m g·OG.
    """
    m, e, i_g = mass_properties(v)
    R, alpha = v["R"], math.radians(v["slope_deg"])
    j_a = i_g + m * (e * e + R * R + 2 * R * e * math.cos(beta))
    dj = -2 * m * R * e * math.sin(beta)
    dv = (
        -m * G * (math.sin(alpha) * (R + e * math.cos(beta)) + math.cos(alpha) * e * math.sin(beta))
    )
    dphi = v_c / R
    return R * -(0.5 * dj * dphi**2 + dv) / j_a


def eccentric_normal_force(beta: float, v_c: float, v: Values) -> float:
    """Normal force of the plane while rolling with G off the axis [N].

    The centre C stays at R from the plane, so G's acceleration along the normal z is that
    of e (sin β, cos β) turning at β' = v/R: z''(G) = −e (β'' sin β + β'² cos β) with
    β'' = a/R (a from :func:`eccentric_acceleration`). The PFD along z gives
    N = m g cos α + m z''(G) = m [g cos α − e (a sin β / R + v² cos β / R²)]. The cylinder
    leaves the plane where this reaches 0; started with the mass straight up (β = 0) on a
    horizontal plane, as soon as v0 > R √(g / e).
    """
    m, e, _ = mass_properties(v)
    R, alpha = v["R"], math.radians(v["slope_deg"])
    a = eccentric_acceleration(beta, v_c, v) if e > 0 else 0.0
    return m * (G * math.cos(alpha) - e * (a * math.sin(beta) / R + v_c**2 * math.cos(beta) / R**2))


def reference(v: Values) -> dict[str, float]:
    """Course values of a homogeneous cylinder (constant along the motion): μ_min (or μ
    while it slips), a, and N = m g cos α. With an eccentric mass they vary along the motion:
    the readouts a_ref and N_ref give them."""
    if v["eccentric_mass"] > 0:
        return {}
    return {
        "mu_required": mu_min(v) if v["mu"] >= mu_min(v) else v["mu"],
        "a": acceleration(v),
        "N": v["mass"] * G * math.cos(math.radians(v["slope_deg"])),
    }
