"""The robot axis's data record and its kinematics (course 6.3): the chain's numbers, the
inertia each part contributes to J_eq, the speeds tied to the motor's and the arm's force.

Numpy only; every function accepts floats or arrays of the same shape (broadcast).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TypeAlias

import numpy as np

Real: TypeAlias = "float | np.ndarray"


@dataclass(frozen=True)
class RobotAxis:
    """Data of the robot's y axis, with the course's names and numbers (6.3) as defaults.

    Attributes:
        J_m: Inertia of the motor shaft [kg·m²].
        J_r: Inertia of the reducer referred to the motor shaft [kg·m²].
        J_p: Inertia of one pulley (there are two) [kg·m²].
        R_p: Pitch radius of a toothed pulley [m].
        k: Reduction ratio ω_p / ω_m [-].
        M1: Equivalent mass of the rigid parts (carriage ``ch``) [kg].
        M2: Equivalent mass of the flexible parts (arm z) [kg].
        K_t: Equivalent stiffness of the arm [N/m].
        mu_t: Equivalent internal damping of the arm, μ_t [N·s/m].
        f_v: Viscous friction referred to the motor shaft [N·m·s/rad].

    Raises:
        ValueError: a mass, inertia, radius, ratio or stiffness is not > 0, or a damping
            or friction coefficient is < 0; the message names the field.
    """

    J_m: float = 4.2e-4
    J_r: float = 1.2e-4
    J_p: float = 6e-5
    R_p: float = 0.020
    k: float = 1 / 5
    M1: float = 136.0
    M2: float = 46.0
    K_t: float = 124_000.0
    mu_t: float = 64.0
    f_v: float = 0.0171

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            if not math.isfinite(value):
                raise ValueError(f"{field.name} must be finite, got {value!r}")
            if field.name in ("mu_t", "f_v"):
                if value < 0:
                    raise ValueError(f"{field.name} must be >= 0, got {value!r}")
            elif value <= 0:
                raise ValueError(f"{field.name} must be > 0, got {value!r}")

    @property
    def ratio(self) -> float:
        """V_ch / ω_m = R_p k [m/rad]: the belt's displacement per motor radian."""
        return self.R_p * self.k


def as_real(value: Real) -> Real:
    """A float for a scalar (0-d array) result, the array otherwise."""
    return float(value) if np.ndim(value) == 0 else np.asarray(value)


def check_rho(rho: float) -> None:
    """Refuse an efficiency outside (0, 1].

    Raises:
        ValueError: rho outside (0, 1].
    """
    if not 0.0 < rho <= 1.0:
        raise ValueError(f"rho (efficiency) must be in (0, 1], got {rho!r}")


# --- 6.3: equivalent inertia and kinematics ------------------------------------------------


def inertia_terms(axis: RobotAxis) -> dict[str, float]:
    """Each part's share of the inertia seen by the motor [kg·m²] (course 6.3).

    Returns:
        ``motor_reducer`` J_m + J_r, ``pulleys`` 2 J_p k², ``carriage`` M1 (R_p k)²,
        ``arm`` M2 (R_p k)² (counted in J_eq only when the arm is rigid).
    """
    r2 = axis.ratio**2
    return {
        "motor_reducer": axis.J_m + axis.J_r,
        "pulleys": 2 * axis.J_p * axis.k**2,
        "carriage": axis.M1 * r2,
        "arm": axis.M2 * r2,
    }


def equivalent_inertia(axis: RobotAxis, *, flexible: bool = True) -> float:
    """J_eq seen by the motor [kg·m²] (course 6.3).

    Flexible arm: J_m + J_r + 2 J_p k² + M1 (R_p k)² (2.7208e-3 with the course's data);
    rigid arm: M2 (R_p k)² added (3.4568e-3).
    """
    terms = inertia_terms(axis)
    j_eq = terms["motor_reducer"] + terms["pulleys"] + terms["carriage"]
    return j_eq if flexible else j_eq + terms["arm"]


def speeds(axis: RobotAxis, omega_m: Real) -> tuple[Real, Real]:
    """(ω_p [rad/s], V_ch [m/s]) from the motor speed ω_m [rad/s]: ω_p = k ω_m, V_ch = R_p ω_p.

    For a rigid arm V_2 = V_ch; for the flexible arm V_2 is a state of its own.
    """
    omega_p = axis.k * omega_m
    return omega_p, axis.R_p * omega_p


def arm_force(axis: RobotAxis, y: Real, v: Real) -> Real:
    """Force of the arm on the carriage along y [N]: K_t (y_2 - y_ch) + μ_t (V_2 - V_ch).

    Args:
        y: Deflection y_2 - y_ch [m].
        v: Its rate V_2 - V_ch [m/s].
    """
    return axis.K_t * y + axis.mu_t * v


def arm_acceleration(axis: RobotAxis, y: Real, v: Real) -> Real:
    """V̇_2 [m/s²] from the arm's own PFD, M2 V̇_2 = -K_t (y_2 - y_ch) - μ_t (V_2 - V_ch)."""
    return -arm_force(axis, y, v) / axis.M2
