"""Rotor scene (course 7.2) against the closed-form rotating torsor, and balancing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.scenes.rotor import (
    SCENE,
    balancing_solution,
    bearing_split,
    mass_properties,
    reference,
)

KEYS = ("F_rot", "M_rot", "bearing_A", "bearing_B", "static_unbalance", "products_EF", "omega")

CASES = [
    {},
    {"speed_rpm": 3000.0},
    {"defect_mass_g": 50.0, "skew_deg": -4.0, "speed_rpm": 800.0},
    {"mass1_g": 30.0, "angle1_deg": 120.0, "mass2_g": 12.0, "angle2_deg": -45.0},
]


def _settled(values: dict[str, float], duration: float = 0.25) -> Simulation:
    sim = Simulation(get_scene("rotor"), values=values)
    sim.advance(duration)
    return sim


@pytest.mark.parametrize("values", CASES)
def test_rotating_torsor_matches_course_within_half_percent(values):
    """7.2.1: F_rot = m ω² Y and M_rot = ω² √(E²+F²), tolerance 0.5 %."""
    sim = _settled(values)
    got = sim.readouts(KEYS)
    ref = reference(sim.values)
    for key in KEYS:
        assert got[key] == pytest.approx(ref[key], rel=5e-3), key


def test_bearing_split_by_hand():
    """Frame's action R = (7, 10, −4) N, M_O = (3, 1.5, 3) N·m; bearings A at x = −a and B
    at x = +a, a = 0.15 m, carrying forces across the axis x only.
    Resultant: F_A + F_B = (0, 10, −4) (the axial 7 N goes to A's ball joint's axial stop
    and is not a bearing force across the axis).
    Moment at O: OA ∧ F_A + OB ∧ F_B with x ∧ (0, Fy, Fz) = (0, −Fz, Fy) x:
    a (0, F_Az − F_Bz, F_By − F_Ay) = (0, 1.5, 3) (the axial 3 N·m is the motor's), so
    F_Az − F_Bz = 10 and F_By − F_Ay = 20. With F_Ay + F_By = 10 and F_Az + F_Bz = −4:
    F_A = (0, −5, 3) N, F_B = (0, 15, −7) N."""
    f_a, f_b = bearing_split(np.array([7.0, 10.0, -4.0]), np.array([3.0, 1.5, 3.0]))
    assert f_a == pytest.approx([0.0, -5.0, 3.0], abs=1e-12)
    assert f_b == pytest.approx([0.0, 15.0, -7.0], abs=1e-12)


def test_bearing_split_of_a_force_off_centre_is_the_lever_rule():
    """A rotating force F = 10 N along y0 applied at x = 0.05 m (M_O = 0.05 x0 ∧ 10 y0 =
    0.5 z0 N·m): lever rule on the span 2a = 0.3 m, F_A = 10 × (0.15 − 0.05)/0.3 = 3.333 N
    and F_B = 10 × (0.15 + 0.05)/0.3 = 6.667 N, both along y0."""
    f_a, f_b = bearing_split(np.array([0.0, 10.0, 0.0]), np.array([0.0, 0.0, 0.5]))
    assert f_a == pytest.approx([0.0, 10.0 / 3.0, 0.0], abs=1e-12)
    assert f_b == pytest.approx([0.0, 20.0 / 3.0, 0.0], abs=1e-12)


def test_bearing_forces_of_two_point_masses_by_hand():
    """Disk square to the axis (skew 0): only the point masses unbalance the rotor, both at
    angle 0 (along y1). ω = 1500 rpm = 157.0796 rad/s, ω² = 24674.01 s⁻². Defect 20 g at
    80 mm, x = 0: m r ω² = 0.0016 × 24674.01 = 39.4784 N; correction 30 g at 50 mm in plane
    x = −0.12 m: 0.0015 × 24674.01 = 37.0110 N. Lever rule on A (x = −0.15) and B (x = +0.15):
    F_A = 39.4784 × 0.15/0.30 + 37.0110 × 0.27/0.30 = 19.7392 + 33.3099 = 53.0491 N,
    F_B = 19.7392 + 37.0110 × 0.03/0.30 = 23.4403 N (simulated, within 0.5 %)."""
    sim = _settled({"skew_deg": 0.0, "mass1_g": 30.0, "angle1_deg": 0.0})
    got = sim.readouts(["bearing_A", "bearing_B"])
    assert got["bearing_A"] == pytest.approx(53.0491, rel=5e-3)
    assert got["bearing_B"] == pytest.approx(23.4403, rel=5e-3)


def test_bearing_forces_scale_with_speed_squared():
    """Doubling the speed multiplies every bearing force by 4 (within 1 %)."""
    slow = _settled({"speed_rpm": 1500.0}).readouts(["bearing_A", "bearing_B"])
    fast = _settled({"speed_rpm": 3000.0}).readouts(["bearing_A", "bearing_B"])
    for key in slow:
        assert fast[key] / slow[key] == pytest.approx(4.0, rel=1e-2)


def test_speed_is_held_constant():
    sim = _settled({"speed_rpm": 3000.0}, duration=1.0)
    assert sim.readouts(["omega"])["omega"] == pytest.approx(3000 * math.pi / 30, rel=1e-3)


def test_shapes_mass_matches_mujoco():
    """The reference's inertia (course shapes + Huygens) is the model's inertia."""
    sim = Simulation(get_scene("rotor"))
    props = mass_properties(sim.values)
    b = sim.model.body("rotor").id
    assert props.mass == pytest.approx(float(sim.model.body_mass[b]), rel=1e-9)


def test_two_correction_masses_balance_statically_and_dynamically():
    """Both bearing forces fall below 1 % of the unbalanced ones (7.2.2 and 7.2.3)."""
    base = {"speed_rpm": 3000.0}
    before = _settled(base).readouts(["bearing_A", "bearing_B"])
    solution = balancing_solution(SCENE.defaults() | base)
    for key in ("mass1_g", "mass2_g"):
        assert 0.0 < solution[key] <= 200.0
    after_sim = _settled(base | solution)
    after = after_sim.readouts(["bearing_A", "bearing_B", "static_unbalance", "products_EF"])
    assert after["bearing_A"] < 0.01 * before["bearing_A"]
    assert after["bearing_B"] < 0.01 * before["bearing_B"]
    assert after["static_unbalance"] < 1e-3 * reference(SCENE.defaults())["static_unbalance"]


def test_static_balance_alone_leaves_a_rotating_moment():
    """One mass opposite G cancels F_rot but not M_rot: static is not dynamic balance."""
    values = SCENE.defaults() | {"skew_deg": 3.0}
    props = mass_properties(values)
    m_needed = props.mass * math.hypot(props.com[1], props.com[2]) / 0.05 * 1000.0
    angle = math.degrees(math.atan2(-props.com[2], -props.com[1]))
    # Put the whole static correction in the plane through G's abscissa (x = 0 is not a
    # correction plane, so split it equally between the two planes: no extra couple).
    static = {
        "mass1_g": m_needed / 2,
        "angle1_deg": angle,
        "mass2_g": m_needed / 2,
        "angle2_deg": angle,
    }
    got = _settled(values | static).readouts(["F_rot", "M_rot", "bearing_A"])
    unbalanced = _settled(values).readouts(["F_rot", "M_rot"])
    assert got["F_rot"] < 1e-2 * unbalanced["F_rot"]
    assert got["M_rot"] > 0.5 * unbalanced["M_rot"]
    assert got["bearing_A"] > 1.0  # the bearings still feel the couple


def test_live_speed_change_needs_no_rebuild():
    sim = Simulation(get_scene("rotor"))
    model = sim.model
    sim.set_value("speed_rpm", 3000)
    assert sim.model is model
    sim.advance(0.5)
    assert sim.readouts(["omega"])["omega"] == pytest.approx(100 * math.pi, rel=1e-3)


def test_moving_a_mass_keeps_the_motion():
    sim = Simulation(get_scene("rotor"))
    sim.advance(0.1)
    angle, t = float(sim.data.qpos[0]), float(sim.data.time)
    sim.set_value("mass1_g", 40)
    assert float(sim.data.qpos[0]) == angle and float(sim.data.time) == t


def test_mass_points_place_the_defect_and_the_corrections_in_their_planes():
    from sandbox.scenes.rotor import CORRECTION_RADIUS, DEFECT_RADIUS, PLANE_X, mass_points

    values = {p.name: p.default for p in SCENE.params}
    values |= {"defect_mass_g": 20.0, "mass1_g": 5.0, "angle1_deg": 90.0, "mass2_g": 0.0,
               "angle2_deg": 180.0}  # fmt: skip
    points = {name: (mass, pos) for name, mass, pos in mass_points(values)}
    assert list(points) == ["defect", "correction1", "correction2"]
    assert points["defect"][0] == pytest.approx(0.02)
    assert points["defect"][1] == pytest.approx([0.0, DEFECT_RADIUS, 0.0])
    assert points["correction1"][0] == pytest.approx(0.005)
    assert points["correction1"][1] == pytest.approx([-PLANE_X, 0.0, CORRECTION_RADIUS])
    assert points["correction2"][0] == 0.0
    assert points["correction2"][1] == pytest.approx([PLANE_X, -CORRECTION_RADIUS, 0.0])
