"""The imposed laws of an input (sandbox.mechanics.imposed): positions, speeds and
accelerations consistent with each other, and continuous where they start."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.mechanics.imposed import Anchor, follow, set_speed
from sandbox.mechanics.robot_axis import back_and_forth, back_and_forth_motion


def _derivative(fn, t: float, h: float = 1e-5) -> float:
    return (fn(t + h) - fn(t - h)) / (2 * h)


@pytest.mark.parametrize("tau", [0.0, 0.05, 0.4])
def test_a_set_speed_law_is_its_own_derivative(tau):
    """θ' = ω and ω' = α at every instant, by central differences (1e-7 relative)."""
    anchor = Anchor(0.3, 1.2, 20.0)
    target = 314.0
    for t in (0.3001, 0.35, 0.7, 2.0):
        pos, speed, acc = set_speed(anchor, target, tau, t)
        dpos = _derivative(lambda x: set_speed(anchor, target, tau, x)[0], t)
        dspeed = _derivative(lambda x: set_speed(anchor, target, tau, x)[1], t)
        assert dpos == pytest.approx(speed, rel=1e-7)
        assert dspeed == pytest.approx(acc, rel=1e-6, abs=1e-6 * target)


def test_a_set_speed_law_starts_at_its_anchor_and_reaches_its_target():
    anchor = Anchor(1.0, 2.0, 10.0)
    pos, speed, acc = set_speed(anchor, 100.0, 0.2, 1.0)
    assert (pos, speed) == (2.0, 10.0)
    assert acc == pytest.approx(-(10.0 - 100.0) / 0.2)
    _, late, _ = set_speed(anchor, 100.0, 0.2, 1.0 + 40 * 0.2)
    assert late == pytest.approx(100.0, rel=1e-15)
    # τ = 0: the course's constant speed from the anchor on (a step in speed)
    assert set_speed(anchor, 100.0, 0.0, 3.0) == (2.0 + 200.0, 100.0, 0.0)


def test_following_a_reference_starts_where_the_input_was_and_joins_it():
    def ref(t: float) -> tuple[float, float, float]:
        return math.sin(t), math.cos(t), -math.sin(t)

    anchor = Anchor(0.5, math.sin(0.5) + 0.01, math.cos(0.5) - 0.2)
    x, v, _ = follow(anchor, ref, 0.1, 0.5)
    assert (x, v) == pytest.approx((anchor.position, anchor.speed), abs=1e-15)
    for t in (0.52, 0.6, 0.9):
        dx = _derivative(lambda s: follow(anchor, ref, 0.1, s)[0], t)
        dv = _derivative(lambda s: follow(anchor, ref, 0.1, s)[1], t)
        x, v, a = follow(anchor, ref, 0.1, t)
        assert dx == pytest.approx(v, rel=1e-7, abs=1e-9)
        assert dv == pytest.approx(a, rel=1e-6, abs=1e-6)
    late = follow(anchor, ref, 0.1, 5.0)
    assert late == pytest.approx(ref(5.0), abs=1e-12)
    on = Anchor(0.5, *ref(0.5)[:2])
    assert follow(on, ref, 0.1, 0.8) == ref(0.8)  # on the reference: the reference itself


def test_the_back_and_forth_acceleration_is_its_speed_s_derivative():
    args = (1.0, 1.5, 0.2, 0.3)
    t = np.linspace(0.001, 6.0, 3001)
    for ti in t:
        x, v, a = back_and_forth_motion(ti, *args)
        assert (x, v) == back_and_forth(ti, *args)
        # away from the corners of the trapezoid, a = dv/dt
        left, right = (
            back_and_forth_motion(ti - 1e-6, *args),
            back_and_forth_motion(ti + 1e-6, *args),
        )
        if left[2] == right[2] == a:
            assert (right[1] - left[1]) / 2e-6 == pytest.approx(a, abs=1e-6)
