"""Torsor transport, sum and comoment against hand computations (course 2–3, 6.1)."""

from __future__ import annotations

import numpy as np
import pytest

from sandbox.mechanics import Torsor, kinematic_torsor, sum_torsors

rng = np.random.default_rng(0)


def test_transport_by_hand():
    """A force F·z at A=O seen from B=(L,0,0): M_B = R ∧ AB = F·L·y."""
    t = Torsor([0, 0, 5.0], [0, 0, 0], [0, 0, 0]).at([2.0, 0, 0])
    np.testing.assert_allclose(t.moment, [0, 10.0, 0])
    np.testing.assert_allclose(t.point, [2.0, 0, 0])


def test_transport_round_trip_and_invariants():
    t = Torsor(rng.normal(size=3), rng.normal(size=3), rng.normal(size=3))
    p = rng.normal(size=3)
    back = t.at(p).at(t.point)
    np.testing.assert_allclose(back.moment, t.moment, atol=1e-12)
    assert t.at(p).automoment() == pytest.approx(t.automoment())


def test_sum_at_different_points():
    a = Torsor([1, 0, 0], [0, 0, 0], [0, 1, 0])
    b = Torsor([-1, 0, 0], [0, 0, 0], [0, -1, 0])
    s = a + b  # a couple: M_O = OP ∧ F summed = 2·(y ∧ x) = −2 z
    np.testing.assert_allclose(s.resultant, 0, atol=1e-15)
    np.testing.assert_allclose(s.moment, [0, 0, -2.0])
    total = sum_torsors([a, b], point=[5, 5, 5])
    np.testing.assert_allclose(total.moment, [0, 0, -2.0])
    np.testing.assert_allclose((a - a).moment, 0)


def test_comoment_independent_of_point():
    t = Torsor(rng.normal(size=3), rng.normal(size=3), rng.normal(size=3))
    v = Torsor(rng.normal(size=3), rng.normal(size=3), rng.normal(size=3))
    p = t.comoment(v)
    assert t.at(rng.normal(size=3)).comoment(v.at(rng.normal(size=3))) == pytest.approx(p)


def test_course_powers_of_motor_and_air():
    """6.1.2: P(motor) = C_mot·ω and P(air on piston) = −F_air·λ'."""
    motor = Torsor([0, 0, 0], [0, 0, 3.0], [0, 0, 0])
    crank = kinematic_torsor([0, 0, 20.0], [0, 0, 0], [0, 0, 0])
    assert motor.comoment(crank) == pytest.approx(60.0)
    air = Torsor([0, -100.0, 0], [0, 0, 0], [0, 0.1, 0])
    piston = kinematic_torsor([0, 0, 0], [0, 2.0, 0], [0, 0.1, 0])
    assert air.comoment(piston) == pytest.approx(-200.0)


def test_perfect_pivot_does_no_work():
    """6.1.3: a pivot of axis z transmits no moment about z, so its power is 0."""
    pivot = Torsor([1.0, 2.0, 3.0], [4.0, 5.0, 0.0], [0, 0, 0])
    assert pivot.comoment(kinematic_torsor([0, 0, 7.0], [0, 0, 0], [0, 0, 0])) == 0.0


def test_in_basis():
    c, s = np.cos(0.3), np.sin(0.3)
    basis = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    r, m = Torsor([c, s, 0], [0, 0, 1], [0, 0, 0]).in_basis(basis)
    np.testing.assert_allclose(r, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(m, [0, 0, 1], atol=1e-12)


def test_bad_shape_is_refused():
    with pytest.raises(ValueError, match="3-vector"):
        Torsor([1, 2], [0, 0, 0])
