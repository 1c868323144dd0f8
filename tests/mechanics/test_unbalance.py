"""Static and couple unbalance of point masses, and the two-plane correction, by hand."""

from __future__ import annotations

import numpy as np
import pytest

from sandbox.mechanics.unbalance import PointMass, polar, rotating_loads, two_planes


def test_a_point_mass_adds_m_r_and_x_m_r_in_its_direction():
    mass = PointMass(0.020, 0.1, 0.05, 90.0)  # 20 g, x = 100 mm, r = 50 mm, along z
    assert mass.static == pytest.approx([0.0, 1e-3], abs=1e-15)  # 0.02 × 0.05
    assert mass.couple == pytest.approx([0.0, 1e-4], abs=1e-15)  # 0.1 × 1e-3: E = m x z
    assert polar(np.array([-1.0, 0.0])) == pytest.approx((1.0, 180.0))
    assert polar(np.zeros(2)) == (0.0, 0.0)


def test_rotating_loads_are_the_course_torsor():
    """Course 7.2.1: R = -ω² m Y y1, M_O = ω² (E y1 - F z1)."""
    loads = rotating_loads(np.array([2e-3, 0.0]), np.array([3e-4, 1e-4]), omega=10.0)
    assert loads == pytest.approx([-0.2, 0.0, 0.01, -0.03])


def test_two_planes_cancel_a_static_and_a_couple_unbalance():
    static, couple = np.array([1.6e-3, 0.0]), np.array([-4.2e-4, 0.0])
    m1, m2 = two_planes(static, couple, -0.12, 0.12, 0.05)
    assert m1.static + m2.static + static == pytest.approx([0, 0], abs=1e-15)
    assert m1.couple + m2.couple + couple == pytest.approx([0, 0], abs=1e-15)
    # by hand: 16 g at 180° in each plane for the static part, ±35 g for the couple
    assert (m1.mass, m1.angle_deg) == pytest.approx((0.016 + 0.035, 180.0))
    assert (m2.mass, m2.angle_deg) == pytest.approx((0.035 - 0.016, 0.0), abs=1e-12)
    with pytest.raises(ValueError, match="two distinct planes"):
        two_planes(static, couple, 0.1, 0.1, 0.05)
