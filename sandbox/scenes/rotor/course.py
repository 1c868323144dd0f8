"""Closed forms of the unbalanced rotor (course section 7.2): the speed, where the defect
and correction masses sit, the rotor's mass properties from its shapes, its unbalance, the
bearing forces and the correction masses that balance it."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.mechanics import MassProperties, coefficients, combine, cylinder, sphere
from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.spec import Values
from sandbox.scenes import bearings
from sandbox.scenes.rotor.params import (
    AXIS,
    BEARING_X,
    CORRECTION_RADIUS,
    DEFECT_RADIUS,
    DEFECT_X,
    DISK_RADIUS,
    DISK_THICKNESS,
    FLANGE_RADIUS,
    FLANGE_THICKNESS,
    MASS_SPHERE_RADIUS,
    PLANE_X,
    SHAFT_LENGTH,
    SHAFT_RADIUS,
    STEEL,
)


def omega(values: Values) -> float:
    """Imposed speed [rad/s]."""
    return values["speed_rpm"] * 2.0 * math.pi / 60.0


def _radial(x: float, radius: float, angle_deg: float) -> np.ndarray:
    a = math.radians(angle_deg)
    return np.array([x, radius * math.cos(a), radius * math.sin(a)])


def disk_axis(values: Values) -> np.ndarray:
    """Unit axis of the skewed disk in the rotor frame (tilted about z1)."""
    b = math.radians(values["skew_deg"])
    return np.array([math.cos(b), math.sin(b), 0.0])


def mass_points(values: Values) -> list[tuple[str, float, np.ndarray]]:
    return [
        ("defect", values["defect_mass_g"] / 1000.0, _radial(DEFECT_X, DEFECT_RADIUS, 0.0)),
        (
            "correction1",
            values["mass1_g"] / 1000.0,
            _radial(-PLANE_X, CORRECTION_RADIUS, values["angle1_deg"]),
        ),
        (
            "correction2",
            values["mass2_g"] / 1000.0,
            _radial(PLANE_X, CORRECTION_RADIUS, values["angle2_deg"]),
        ),
    ]


def mass_properties(values: Values) -> MassProperties:
    """Mass, centre of mass and inertia of rotor 1 in its own frame, from the shapes."""

    def shaped(inertia: np.ndarray, mass: float, com: np.ndarray, axis: np.ndarray):
        rot = np.zeros(9)
        quat = np.zeros(4)
        mujoco.mju_quatZ2Vec(quat, axis)
        mujoco.mju_quat2Mat(rot, quat)
        return MassProperties.of_shape(inertia, mass, com, rotation=rot.reshape(3, 3))

    def cyl_mass(r: float, h: float) -> float:
        return STEEL * math.pi * r * r * h

    parts = []
    m = cyl_mass(SHAFT_RADIUS, SHAFT_LENGTH)
    parts.append(shaped(cylinder(m, SHAFT_RADIUS, SHAFT_LENGTH), m, np.zeros(3), AXIS))
    m = cyl_mass(DISK_RADIUS, DISK_THICKNESS)
    parts.append(
        shaped(cylinder(m, DISK_RADIUS, DISK_THICKNESS), m, np.zeros(3), disk_axis(values))
    )
    m = cyl_mass(FLANGE_RADIUS, FLANGE_THICKNESS)
    for x in (-PLANE_X, PLANE_X):
        parts.append(
            shaped(cylinder(m, FLANGE_RADIUS, FLANGE_THICKNESS), m, np.array([x, 0, 0]), AXIS)
        )
    for _, mass, pos in mass_points(values):
        parts.append(MassProperties.of_shape(sphere(mass, MASS_SPHERE_RADIUS), mass, pos))
    return combine(parts)


def unbalance(values: Values) -> tuple[float, np.ndarray, float, float]:
    """(m, G, E, F) of the rotor: mass [kg], centre [m], products at O [kg·m²]."""
    props = mass_properties(values)
    _, _, _, _, e, f = coefficients(props.inertia_at(np.zeros(3)))
    return props.mass, props.com, e, f


def bearing_split(r: np.ndarray, m_o: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Forces of the frame at A and B from its action (R, M_O) across the axis.

    Bearing A (ball joint at x = -a) and B (linear annular joint at x = +a) make the
    guidance isostatic: R⊥ = F_A + F_B and M_O⊥ = OA ∧ F_A + OB ∧ F_B.
    """
    r_perp = r - np.dot(r, AXIS) * AXIS
    twist = _cross(m_o, AXIS) / BEARING_X
    return 0.5 * (r_perp - twist), 0.5 * (r_perp + twist)


def reference(values: Values) -> dict[str, float]:
    """Course 7.2: F_rot = m ω² Y, M_rot = ω² √(E²+F²), and the bearing forces; with the
    bearings' parameters, appendix B.2's largest pressure and friction torque in each."""
    w = omega(values)
    mass, g, e, f = unbalance(values)
    r = -mass * w * w * np.array([0.0, g[1], g[2]])
    m_o = w * w * np.array([0.0, e, -f])
    f_a, f_b = bearing_split(r, m_o)
    local: dict[str, float] = {}
    if all(k in values for k in ("bearing_R", "bearing_L", "bearing_model", "bearing_f")):
        for name, force in (("A", f_a), ("B", f_b)):
            load = float(np.linalg.norm(force))  # across the axis: the bearings' radial load
            local[f"bearing_{name}_pmax"] = bearings.max_pressure(load, values)
            local[f"bearing_{name}_Cf"] = bearings.friction_torque(load, values)
    return {
        **local,
        "omega": w,
        "static_unbalance": mass * math.hypot(g[1], g[2]),
        "products_EF": math.hypot(e, f),
        "F_rot": float(np.linalg.norm(r)),
        "M_rot": float(np.linalg.norm(m_o)),
        "bearing_A": float(np.linalg.norm(f_a)),
        "bearing_B": float(np.linalg.norm(f_b)),
    }


def balancing_solution(values: Values) -> dict[str, float]:
    """Correction masses that balance statically and dynamically (course 7.2.2–7.2.3).

    A point mass m_k at (x_k, r cos φ_k, r sin φ_k) adds u_k = m_k r (cos φ_k, sin φ_k)
    to m·(Y_y, Y_z) and x_k·u_k to (F, E). With the planes at x = ∓c, the conditions
    Y = 0 and E = F = 0 give u2 = -(S + Q/c)/2 and u1 = -(S - Q/c)/2.
    """
    bare = {**values, "mass1_g": 0.0, "mass2_g": 0.0}
    mass, g, e, f = unbalance(bare)
    s = mass * np.array([g[1], g[2]])
    q = np.array([f, e])
    u1 = -(s - q / PLANE_X) / 2.0
    u2 = -(s + q / PLANE_X) / 2.0
    out = {}
    for k, u in (("1", u1), ("2", u2)):
        out[f"mass{k}_g"] = float(np.linalg.norm(u) / CORRECTION_RADIUS * 1000.0)
        out[f"angle{k}_deg"] = float(math.degrees(math.atan2(u[1], u[0])))
    return out
