"""The motor torque of the robot axis and the efficiency of its reducer (course 6.3 with
6.4's ρ): the torque that gives a motion, the power the reducer loses, and components in
series."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from sandbox.mechanics.robot_axis.axis import (
    Real,
    RobotAxis,
    arm_force,
    as_real,
    check_rho,
    inertia_terms,
)


def motor_torque(
    axis: RobotAxis,
    omega_m: Real,
    omega_m_dot: Real,
    *,
    y: Real = 0.0,
    v: Real = 0.0,
    flexible: bool = True,
    rho: float = 1.0,
) -> Real:
    """Motor torque C_m [N·m] that gives ω_m(t) (course 6.3, with 6.4's efficiency ρ).

    With ρ = 1 this is the kinetic-energy theorem solved for C_m, the arm's PFD giving
    M2 V_2 V̇_2 = -(K_t y + μ_t v) V_2::

        C_m = J_eq ω̇_m + f_v ω_m - R_p k (K_t y + μ_t v)      (flexible arm)
        C_m = J_eq ω̇_m + f_v ω_m                              (rigid arm, y and v ignored)

    With ρ < 1 the torque the reducer's output needs, referred to the motor shaft,
    C_s = (2 J_p k² + M1 (R_p k)² [+ M2 (R_p k)²]) ω̇_m - R_p k (K_t y + μ_t v), is divided
    by ρ when driving (C_s ω_m > 0) and multiplied by ρ when braking; (J_m + J_r) ω̇_m and
    f_v ω_m are added as they are.

    Args:
        omega_m: Motor speed [rad/s].
        omega_m_dot: Motor acceleration [rad/s²].
        y: Arm deflection y_2 - y_ch [m] (flexible arm only).
        v: Its rate V_2 - V_ch [m/s] (flexible arm only).
        flexible: False for the rigid arm (M2 in J_eq).
        rho: Reducer efficiency in (0, 1].

    Raises:
        ValueError: rho outside (0, 1].
    """
    check_rho(rho)
    upstream = (axis.J_m + axis.J_r) * omega_m_dot + axis.f_v * omega_m
    c_s = _output_torque(axis, omega_m_dot, y, v, flexible)
    if rho == 1.0:
        return upstream + c_s
    driving = np.asarray(c_s * omega_m) > 0
    return as_real(upstream + np.where(driving, c_s / rho, c_s * rho))


def _output_torque(axis: RobotAxis, omega_m_dot: Real, y: Real, v: Real, flexible: bool) -> Real:
    """C_s: torque needed downstream of the reducer, referred to the motor shaft [N·m]."""
    terms = inertia_terms(axis)
    j_out = terms["pulleys"] + terms["carriage"]
    if not flexible:
        return (j_out + terms["arm"]) * omega_m_dot
    return j_out * omega_m_dot - axis.ratio * arm_force(axis, y, v)


def reducer_loss(
    axis: RobotAxis,
    omega_m: Real,
    omega_m_dot: Real,
    *,
    y: Real = 0.0,
    v: Real = 0.0,
    flexible: bool = True,
    rho: float = 1.0,
) -> Real:
    """P_loss [W] (>= 0) dissipated in the reducer (course 6.4): (1 - ρ) P_e.

    P_e is the power entering the reducer: C_s ω_m / ρ from the motor when driving,
    -C_s ω_m from the load side when braking (C_s as in :func:`motor_torque`).
    Same arguments as :func:`motor_torque`; zero when ρ = 1.
    """
    check_rho(rho)
    p_s = _output_torque(axis, omega_m_dot, y, v, flexible) * omega_m
    p_e = np.where(np.asarray(p_s) > 0, p_s / rho, -p_s)
    return as_real((1.0 - rho) * p_e)


# --- 6.4: efficiency of components in series -------------------------------------------------


def series_efficiency(rhos: Iterable[float]) -> float:
    """Overall efficiency of components in series: the product of their ρ (course 6.4).

    Raises:
        ValueError: a ρ outside (0, 1] (the message gives its index), or no component.
    """
    product, count = 1.0, 0
    for index, rho in enumerate(rhos):
        if not 0.0 < rho <= 1.0:
            raise ValueError(f"rho[{index}] (efficiency) must be in (0, 1], got {rho!r}")
        product *= rho
        count += 1
    if count == 0:
        raise ValueError("rhos is empty: give at least one efficiency")
    return product


def power_loss(P_e: Real, rho: float) -> Real:
    """Power lost in a component [W]: P_e (1 - ρ), P_e the power entering it (course 6.4).

    Raises:
        ValueError: rho outside (0, 1].
    """
    check_rho(rho)
    return P_e * (1.0 - rho)
