"""Closed forms of the inline engine (course sections 1, 7.3): the number of cylinders,
the masses of each slider-crank split into reciprocating and rotating ones, the course's
engine at constant ω (:class:`sandbox.mechanics.engine.Engine`), its orders, largest
rocking moment and motor torque."""

from __future__ import annotations

import numpy as np

from sandbox.errors import BadParameter
from sandbox.french import number
from sandbox.mechanics.engine import (
    THROWS_DEG,
    Engine,
    pilon_orders,
    shaking_moment_amplitude,
)
from sandbox.physics.spec import Values
from sandbox.scenes.compressor import course as compressor
from sandbox.scenes.compressor.params import RPM


def cylinder_count(v: Values) -> int:
    """The number of cylinders, 1, 2 or 4.

    Raises:
        BadParameter: for 3 or a fraction (one line naming the fix).
    """
    n = v["cylinders"]
    if n not in (1.0, 2.0, 4.0):
        raise BadParameter(
            f"cylinders = {n:g} is not offered: lower it to 2 or raise it to 4 "
            "(inline engines of 1, 2 or 4 cylinders)",
            french=f"Nombre de cylindres n = {number(n)} refusé : choisissez 1, 2 ou 4.",
        )
    return int(n)


def masses(v: Values) -> tuple[float, float]:
    """(m, m_rot) [kg]: reciprocating mass m3 + m2 d2/L at the piston pin and rotating
    mass m1 d1/R + m2 (1 − d2/L) at the crank pin, per cylinder (the rod split in two
    point masses keeps its centre of mass, hence every force)."""
    w = v["d2"] / v["L"]
    return v["m3"] + v["m2"] * w, v["m1"] * v["d1"] / v["R"] + v["m2"] * (1 - w)


def engine_of(v: Values, omega: float | None = None) -> Engine:
    """The course's engine for the parameters ``v`` at ``omega`` [rad/s] (default: the
    set point)."""
    m, m_rot = masses(v)
    w = v["speed_rpm"] * RPM if omega is None else abs(omega)
    return Engine(
        cylinder_count(v), v["R"], v["L"], m, w, spacing=v["spacing"], m_rot=m_rot,
        k_rot=v["counterweight_rot"], k_rec=v["counterweight_rec"],
        balance_shaft=1.0 if v["lanchester"] >= 0.5 else 0.0,
    )  # fmt: skip


def counterweight_mass(v: Values) -> float:
    """Counterweight at R opposite each pin [kg]: k_r m_rot + k_a m."""
    m, m_rot = masses(v)
    return v["counterweight_rot"] * m_rot + v["counterweight_rec"] * m


def reference(v: Values) -> dict[str, float]:
    """Course values at the set point: ω, the exact pilon's orders 1 and 2 and the rocking
    moment's largest value over a revolution."""
    e = engine_of(v)
    orders = pilon_orders(e)
    return {
        "omega": e.omega,
        "shaking_force_h1": float(orders[1]),
        "shaking_force_h2": float(orders[2]),
        "shaking_moment_max": shaking_moment_amplitude(e),
    }


def motor_torque_ref(theta_c: float, omega: float, v: Values) -> float:
    """C_mot at constant ω [N·m]: the compressor's (dT/dt)/ω summed over the cylinders at
    θ_c − φ_i (the shafts at constant speed need none)."""
    one = {"R": v["R"], "L": v["L"], "d2": v["d2"], "m2": v["m2"], "m3": v["m3"],
           "C2": v["C2"], "C1": 0.0, "counterweight_mass": 0.0, "counterweight_radius": 0.0}  # fmt: skip
    phis = np.radians(THROWS_DEG[cylinder_count(v)])
    return float(sum(compressor.motor_torque(theta_c - p, omega, one) for p in phis))
