"""The wind turbine's closed forms (course 6.4.2, with the rotor's aerodynamics kept as
simple as the course's chain): Betz's power, the rotor's power coefficient, the torques
on the low-speed shaft, the steady speed, the start from rest, and the powers of every
stage of the chain.

- **Wind.** P₁ = 8/27 ρ S V³ (Betz's limit, the course's 5 MW), S = π D²/4.
- **Rotor.** At the tip-speed ratio λ = ω R / V (R = D/2), the blades take
  P_rotor = ρ_h P₁ s(λ/λ*), s(x) = 2x − x² (1 at the optimum λ*, 0 at rest and at 2λ*):
  the power coefficient Cp = P_rotor / (½ ρ S V³) peaks at ρ_h · 16/27 (Betz's 16/27 for
  ρ_h = 1). Its torque C_a = P_rotor / ω = c (2 − x), c = ρ_h P₁ R / (V λ*), is affine in
  ω: C_a = a − b ω with a = 2c and b = c R / (V λ*).
- **Generator.** A resistive load: its torque on the fast shaft is C_g = K ω_g, ω_g = k ω.
- **Gearbox.** Efficiency ρ_m on the power it passes (driving mode: the rotor drives the
  generator). On the fast side ρ_m P_in = C_g ω_g + J_g ω_g ω̇_g, P_in the power entering
  from the slow shaft, P_in = (C_a − J_r ω̇) ω. Hence
  (J_r + J_g k² / ρ_m) ω̇ = C_a − k C_g / ρ_m = a − (b + k² K / ρ_m) ω:
  a first-order motion, ω → ω_∞ = a / (b + k² K / ρ_m) with the time constant
  τ = (J_r + J_g k² / ρ_m) / (b + k² K / ρ_m).
- **Downstream.** The generator, the transformer and the lines take their efficiency
  from the power they receive (no inertia, no dynamics).

Pure functions (math only).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from sandbox.mechanics.bearing import betz_power

Values = Mapping[str, float]

CP_BETZ = 16.0 / 27.0
"""Betz's limit of the power coefficient."""


def area(v: Values) -> float:
    """Swept area S = π D²/4 [m²]."""
    return math.pi * v["diameter"] ** 2 / 4.0


def wind_power(v: Values) -> float:
    """P₁ = 8/27 ρ S V³ [W]: what the course's chain starts from."""
    return betz_power(v["air_density"], area(v), v["wind_speed"])


def tip_speed_ratio(omega: float, v: Values) -> float:
    """λ = ω R / V (0 without wind)."""
    speed = v["wind_speed"]
    return omega * v["diameter"] / 2.0 / speed if speed > 0 else 0.0


def torque_coefficients(v: Values) -> tuple[float, float]:
    """(a [N·m], b [N·m·s/rad]) of the rotor's torque C_a = a − b ω (0, 0 without wind)."""
    speed = v["wind_speed"]
    if speed <= 0:
        return 0.0, 0.0
    radius = v["diameter"] / 2.0
    c = v["eta_rotor"] * wind_power(v) * radius / (speed * v["tsr_opt"])
    return 2.0 * c, c * radius / (speed * v["tsr_opt"])


def rotor_power(omega: float, v: Values) -> float:
    """P_rotor = C_a ω = ρ_h P₁ (2x − x²), x = λ/λ* [W]."""
    a, b = torque_coefficients(v)
    return (a - b * omega) * omega


def generator_damping(v: Values) -> float:
    """k² K / ρ_m [N·m·s/rad]: the generator's torque on the slow shaft per rad/s."""
    return v["gear_ratio"] ** 2 * v["generator_load"] / v["eta_gearbox"]


def slow_inertia(v: Values) -> float:
    """J_r + J_g k² / ρ_m [kg·m²]: the inertia the slow shaft's equation carries."""
    return v["rotor_inertia"] + v["generator_inertia"] * v["gear_ratio"] ** 2 / v["eta_gearbox"]


def true_inertia(v: Values) -> float:
    """J_r + J_g k² [kg·m²]: the inertia of the kinetic energy T = ½ (J_r + J_g k²) ω²."""
    return v["rotor_inertia"] + v["generator_inertia"] * v["gear_ratio"] ** 2


def steady_speed(v: Values) -> float:
    """ω_∞ = a / (b + k² K / ρ_m) [rad/s]."""
    a, b = torque_coefficients(v)
    return a / (b + generator_damping(v))


def time_constant(v: Values) -> float:
    """τ [s] of the approach to ω_∞ (inf without wind nor load)."""
    _, b = torque_coefficients(v)
    damping = b + generator_damping(v)
    return slow_inertia(v) / damping if damping > 0 else math.inf


def speed_from(omega0: float, t: float, v: Values) -> float:
    """ω(t) from ω(0) = ``omega0``: ω_∞ + (ω₀ − ω_∞) e^(−t/τ)."""
    tau = time_constant(v)
    w_inf = steady_speed(v)
    return w_inf + (omega0 - w_inf) * math.exp(-t / tau) if math.isfinite(tau) else omega0


def optimal_load(v: Values) -> float:
    """The generator's K [N·m·s/rad] that holds the rotor at λ* in this wind:
    k² K / ρ_m = b (then ω_∞ = a / 2b = V λ* / R)."""
    _, b = torque_coefficients(v)
    return b * v["eta_gearbox"] / v["gear_ratio"] ** 2


def chain(omega: float, omega_dot: float, v: Values) -> dict[str, float]:
    """Every stage's power [W] at speed ``omega`` and acceleration ``omega_dot``.

    The names are the scene's readouts: P_wind, P_rotor and its loss, P_rotor_store
    (J_r ω ω̇), P_gearbox_in and its loss, P_generator_store (J_g k² ω ω̇), P_generator_in
    (C_g ω_g), P_generator_loss, P_electric, P_transformer_loss, P_transformer_out,
    P_line_loss, P_grid, and the overall efficiency P_grid / P₁."""
    k = v["gear_ratio"]
    p1 = wind_power(v)
    p_rotor = rotor_power(omega, v)
    store_rotor = v["rotor_inertia"] * omega * omega_dot
    p_in = p_rotor - store_rotor
    generator_torque = v["generator_load"] * k * omega
    p_gen = generator_torque * k * omega
    p_elec = v["eta_generator"] * p_gen
    p_tr = v["eta_transformer"] * p_elec
    p_grid = v["eta_lines"] * p_tr
    return {
        "P_wind": p1,
        "P_rotor": p_rotor,
        "P_rotor_loss": p1 - p_rotor,
        "P_rotor_store": store_rotor,
        "P_gearbox_in": p_in,
        "P_gearbox_loss": (1.0 - v["eta_gearbox"]) * p_in,
        "P_generator_store": v["generator_inertia"] * k * k * omega * omega_dot,
        "P_generator_in": p_gen,
        "P_generator_loss": p_gen - p_elec,
        "P_electric": p_elec,
        "P_transformer_loss": p_elec - p_tr,
        "P_transformer_out": p_tr,
        "P_line_loss": p_tr - p_grid,
        "P_grid": p_grid,
        "efficiency": p_grid / p1 if p1 > 0 else math.nan,
        "generator_torque": generator_torque,
        "rotor_torque": p_rotor / omega if omega != 0 else torque_coefficients(v)[0],
    }


def steady_chain(v: Values) -> dict[str, float]:
    """The chain at the steady speed (ω̇ = 0), with ω, λ and Cp: the course's numbers at
    its values (5 MW, 3,75 MW into the gearbox, 375 kW lost there, 0,52 overall)."""
    w = steady_speed(v)
    out = chain(w, 0.0, v)
    out["omega"] = w
    out["omega_g"] = v["gear_ratio"] * w
    out["tip_speed_ratio"] = tip_speed_ratio(w, v)
    kinetic = 0.5 * v["air_density"] * area(v) * v["wind_speed"] ** 3
    out["Cp"] = out["P_rotor"] / kinetic if kinetic > 0 else math.nan
    return out
