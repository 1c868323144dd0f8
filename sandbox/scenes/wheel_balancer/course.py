"""Closed forms of the wheel balancer (course 7.2): the wheel's mass properties, its static
and couple unbalance, the clips that cancel them (7.2.3), the rigid bearings' forces and
the lab bench's steady vibration on soft supports.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.mechanics import MassProperties, combine, cylinder, sphere
from sandbox.mechanics.two_planes import (
    SoftSupports,
    Whirl,
    bearing_forces,
    correction,
    synchronous_whirl,
)
from sandbox.physics.spec import Values
from sandbox.scenes.wheel_balancer.geometry import (
    mass_points,
    springs,
    tube_inertia,
    tyre_axis,
    z_to,
)
from sandbox.scenes.wheel_balancer.params import (
    ALUMINIUM,
    AXIS,
    CLIP_RADIUS,
    DISC_RADIUS,
    DISC_THICKNESS,
    DISC_X,
    FLANGE_RADIUS,
    FLANGE_THICKNESS,
    FLANGE_X,
    HOUSING_LENGTH,
    HOUSING_RADIUS,
    MASS_SPHERE_RADIUS,
    RIM_INNER,
    RIM_MASS,
    RIM_OUTER,
    RIM_WIDTH,
    SHAFT_FROM,
    SHAFT_RADIUS,
    SHAFT_TO,
    STEEL,
    TYRE_INNER,
    TYRE_MASS,
    TYRE_OUTER,
    TYRE_WIDTH,
    X_A,
    X_B,
    X_INNER,
    X_M,
    X_OUTER,
    X_WHEEL,
    omega,
    soft,
)


def _shaped(inertia: np.ndarray, mass: float, com: np.ndarray, axis: np.ndarray) -> MassProperties:
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, z_to(axis))
    return MassProperties.of_shape(inertia, mass, com, rotation=rot.reshape(3, 3))


def _cylinder_mass(radius: float, length: float, density: float) -> float:
    return density * math.pi * radius * radius * length


def wheel_properties(values: Values) -> MassProperties:
    """Mass, centre and inertia of the turning wheel (shaft to tyre, point masses) in the
    wheel frame (origin O at the hub face), from the shapes."""
    x = np.array([1.0, 0.0, 0.0])
    parts = []
    length = SHAFT_TO - SHAFT_FROM
    m = _cylinder_mass(SHAFT_RADIUS, length, STEEL)
    com = np.array([(SHAFT_TO + SHAFT_FROM) / 2, 0.0, 0.0])
    parts.append(_shaped(cylinder(m, SHAFT_RADIUS, length), m, com, x))
    m = _cylinder_mass(FLANGE_RADIUS, FLANGE_THICKNESS, STEEL)
    parts.append(
        _shaped(cylinder(m, FLANGE_RADIUS, FLANGE_THICKNESS), m, np.array([FLANGE_X, 0, 0]), x)
    )
    m = _cylinder_mass(DISC_RADIUS, DISC_THICKNESS, ALUMINIUM)
    parts.append(_shaped(cylinder(m, DISC_RADIUS, DISC_THICKNESS), m, np.array([DISC_X, 0, 0]), x))
    centre = np.array([X_WHEEL, 0.0, 0.0])
    parts.append(
        _shaped(tube_inertia(RIM_MASS, RIM_OUTER, RIM_INNER, RIM_WIDTH), RIM_MASS, centre, x)
    )
    tyre = tube_inertia(TYRE_MASS, TYRE_OUTER, TYRE_INNER, TYRE_WIDTH)
    parts.append(_shaped(tyre, TYRE_MASS, centre, tyre_axis(values)))
    for _, mass, pos in mass_points(values):
        parts.append(MassProperties.of_shape(sphere(mass, MASS_SPHERE_RADIUS), mass, pos))
    return combine(parts)


def unbalance(values: Values) -> tuple[complex, complex]:
    """(S [kg·m], C [kg·m²] at O) of the wheel as it is (clips and trial mass included),
    rotor-frame complex ``y + i z``: S = m (Y_y + i Y_z), C = F + i E (course 7.2.1)."""
    props = wheel_properties(values)
    i_o = props.inertia_at(np.zeros(3))
    f, e = -i_o[0, 1], -i_o[0, 2]  # course signs: I = [[A, −F, −E], ...]
    s = props.mass * complex(props.com[1], props.com[2])
    return s, complex(f, e)


def bare(values: Values) -> dict[str, float]:
    """The values without clips nor trial mass (what the garage's wheel arrives as)."""
    return {**values, "mass_inner_g": 0.0, "mass_outer_g": 0.0, "trial_plane": 0.0}


def machine_solution(values: Values) -> dict[str, float]:
    """The exact clips (course 7.2.3) for the wheel of ``values`` (its hidden unbalance
    when it is a mystery wheel): the parameters that balance it."""
    s, c = unbalance(bare(values))
    clips = correction(
        s,
        c,
        x_inner=X_INNER,
        x_outer=X_OUTER,
        radius_inner=CLIP_RADIUS,
        radius_outer=CLIP_RADIUS,
    )
    return {
        "mass_inner_g": clips.clip_inner_g,
        "angle_inner_deg": clips.clip_inner_deg,
        "mass_outer_g": clips.clip_outer_g,
        "angle_outer_deg": clips.clip_outer_deg,
        "trial_plane": 0.0,
    }


def housing_properties() -> MassProperties:
    """The housing tube (steel, centred on M), world axes."""
    m = _cylinder_mass(HOUSING_RADIUS, HOUSING_LENGTH, STEEL)
    return _shaped(cylinder(m, HOUSING_RADIUS, HOUSING_LENGTH), m, np.array([X_M, 0.0, 0.0]), AXIS)


def supports_model(values: Values) -> SoftSupports:
    """The lab bench as :class:`SoftSupports`: housing and wheel about M (x = −0.20 m)."""
    wheel = wheel_properties(values)
    housing = housing_properties()
    total = combine([wheel, housing])
    m_point = np.array([X_M, 0.0, 0.0])
    k_t, c_t, k_r, c_r = springs()
    return SoftSupports(
        mass=total.mass,
        first_moment=total.mass * (float(total.com[0]) - X_M),
        inertia=float(total.inertia_at(m_point)[1, 1]),
        polar=float(wheel.inertia_G[0, 0]),
        k_t=k_t,
        c_t=c_t,
        k_r=k_r,
        c_r=c_r,
    )


def steady_motion(values: Values) -> tuple[complex, complex]:
    """(U [m], Ψ [rad]) of the textbook model (:class:`SoftSupports`, isotropic rotor)."""
    s, c = unbalance(values)
    return supports_model(values).response(s, c - X_M * s, omega(values))


def steady_whirl(values: Values) -> Whirl:
    """The lab bench's steady vibration, exact to first order (:func:`synchronous_whirl`)."""
    wheel = wheel_properties(values)
    housing = housing_properties()
    m_point = np.array([X_M, 0.0, 0.0])
    return synchronous_whirl(
        omega=omega(values),
        rotor_mass=wheel.mass,
        rotor_com=wheel.com - m_point,
        rotor_inertia=wheel.inertia_at(m_point),
        housing_mass=housing.mass,
        housing_com=float(housing.com[0]) - X_M,
        housing_inertia=float(housing.inertia_G[1, 1]),
        supports=supports_model(values),
    )


def reference(values: Values) -> dict[str, float]:
    """Course 7.2: bearing forces on rigid bearings, the clips that cancel them, and the
    lab bench's accelerations (linear synchronous response) on soft ones."""
    w = omega(values)
    s, c = unbalance(values)
    out: dict[str, float] = {"omega": w}
    if not soft(values):
        p_a, p_b = _rigid_forces(s, c, w)
        out |= {"bearing_inner": abs(p_a), "bearing_outer": abs(p_b)}
        out |= {"accel_inner": 0.0, "accel_outer": 0.0}
    else:
        whirl = steady_whirl(values)
        f_a, f_b = whirl.bearing_forces(X_A - X_M, X_B - X_M)
        out |= {"bearing_inner": _norm(f_a), "bearing_outer": _norm(f_b)}
        for name, x in (("inner", X_A), ("outer", X_B)):
            v = whirl.acceleration(x - X_M)
            out[f"accel_{name}"] = abs(v)
            out[f"accel_{name}_deg"] = math.degrees(math.atan2(v.imag, v.real)) % 360.0
    # what the machine displays: the clips that would cancel the wheel as it now is
    clips = correction(
        s,
        c,
        x_inner=X_INNER,
        x_outer=X_OUTER,
        radius_inner=CLIP_RADIUS,
        radius_outer=CLIP_RADIUS,
    )
    out |= {
        "clip_inner_g": clips.clip_inner_g,
        "clip_inner_deg": clips.clip_inner_deg,
        "clip_outer_g": clips.clip_outer_g,
        "clip_outer_deg": clips.clip_outer_deg,
    }
    return out


def _norm(v: np.ndarray) -> float:
    return float(np.linalg.norm(v))


def _rigid_forces(s: complex, c: complex, w: float) -> tuple[complex, complex]:
    return bearing_forces(s, c, x_a=X_A, x_b=X_B, omega=w)
