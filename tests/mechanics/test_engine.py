"""Inline engine's shaking force and rocking moment (course 1, 7.3, figure 1), by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.mechanics.engine import (
    RPM,
    Engine,
    cylinder_forces,
    lanchester_unbalance,
    pilon_orders,
    piston_acceleration,
    shaking_force,
    shaking_force_h1,
    shaking_force_h2,
    shaking_moment,
    shaking_moment_amplitude,
    shaking_moment_h1,
    shaking_moment_h2,
    strokes_per_second,
    transverse_force_h1,
)
from sandbox.scenes import compressor

# The compressor's slider-crank (R = 15 mm, L = 55 mm, piston 80 g) at 3000 tr/min.
R, L, M, W = 0.015, 0.055, 0.08, 3000 * RPM
LAM = R / L  # 0.27273
F1 = M * R * W**2  # 0.08 × 0.015 × 314.16² = 118.44 N: one cylinder's first order
A = 0.09  # cylinder spacing [m]
A2 = LAM + LAM**3 / 4 + 15 * LAM**5 / 128 + 35 * LAM**7 / 512  # 0.277983
A4 = LAM**3 / 4 + 3 * LAM**5 / 16 + 35 * LAM**7 / 256  # 0.005370
THETA = np.linspace(0, 2 * math.pi, 97)


def engine(n: int, **kw: float) -> Engine:
    return Engine(n, R, L, M, W, spacing=A, **kw)


def test_one_cylinder_by_hand():
    e = engine(1)
    assert F1 == pytest.approx(118.435, rel=1e-4)
    # top dead centre: y'' = −R ω² (1 + λ) exactly, the two-term formula agrees there
    assert shaking_force(e, 0.0) == pytest.approx([0.0, F1 * (1 + LAM)], rel=1e-12)
    assert shaking_force(e, 0.0, exact=False) == pytest.approx([0.0, F1 * (1 + LAM)])
    # ψ = 90°: exact −m ω² R² / √(L² − R²) (−33.54 N), two-term −m R ω² λ (−32.30 N)
    exact_90 = -M * W**2 * R**2 / math.sqrt(L**2 - R**2)
    assert shaking_force(e, math.pi / 2)[1] == pytest.approx(exact_90, rel=1e-12)
    assert shaking_force(e, math.pi / 2, exact=False)[1] == pytest.approx(-F1 * LAM)
    assert shaking_force_h1(e) == pytest.approx(F1, rel=1e-12)
    assert shaking_force_h2(e) == pytest.approx(F1 * LAM, rel=1e-12)  # 32.30 N
    assert shaking_moment_h1(e) == 0.0 and shaking_moment_amplitude(e) == pytest.approx(0.0)


def test_exact_orders_are_the_series_in_lambda():
    """Order 1 is exactly m R ω²; order 2 = m R ω² (λ + λ³/4 + 15λ⁵/128 + 35λ⁷/512 + ...),
    order 4 = m R ω² (λ³/4 + 3λ⁵/16 + 35λ⁷/256 + ...); no odd order beyond the first.
    Tolerances: the first term left out (λ⁹ ~ 8e-6) over the order."""
    orders = pilon_orders(engine(1))
    assert orders[1] == pytest.approx(F1, rel=1e-12)
    assert orders[2] == pytest.approx(F1 * A2, rel=1e-5)
    assert orders[4] == pytest.approx(F1 * A4, rel=5e-4)
    assert orders[[0, 3, 5]] == pytest.approx([0, 0, 0], abs=1e-9 * F1)
    # the two-term h2 underestimates the exact second order by λ²/4 + 15λ⁴/128 + ... = 1.93 %
    assert orders[2] / shaking_force_h2(engine(1)) - 1 == pytest.approx(0.01928, rel=1e-3)


def test_one_cylinder_is_the_compressors_slider_crank():
    """The compressor's frame_force with its rod's mass at the pin, crank mass m_rot at R and
    a counterweight: same force at θ_compressor = θ + 90° (x0 and y0)."""
    m_rot, k_rec = 0.05, 0.5
    e = engine(1, m_rot=m_rot, k_rot=1.0, k_rec=k_rec)
    v = {"R": R, "L": L, "d1": R, "d2": 0.0, "m1": m_rot, "m2": 0.0, "m3": M}
    v |= {"counterweight_mass": m_rot + k_rec * M, "counterweight_radius": R}
    for theta in (0.0, 0.4, 1.9, 3.5, 5.0):
        ref = compressor.frame_force(theta + math.pi / 2, W, v)
        assert shaking_force(e, theta) == pytest.approx(ref, rel=1e-10, abs=1e-10 * F1)
    v = {**v, "m1": 0.0, "counterweight_mass": 0.0, "speed_rpm": 3000.0}
    ref = compressor.reference(v)
    assert shaking_force_h1(engine(1)) == pytest.approx(ref["pilon_h1"], rel=1e-9)
    assert pilon_orders(engine(1))[2] == pytest.approx(ref["pilon_h2"], rel=1e-9)


def test_counterweight_trades_pilon_for_tamis():
    """Half the reciprocating mass on the counterweight (rotating mass fully balanced):
    first-order pilon and tamis both 0.5 m R ω² (course 1: it cannot remove both)."""
    e = engine(1, m_rot=0.05, k_rot=1.0, k_rec=0.5)
    assert shaking_force_h1(e) == pytest.approx(0.5 * F1)
    assert transverse_force_h1(e) == pytest.approx(0.5 * F1)
    # at ψ = 90° the throw points along −x0 (x1 = (−sin ψ, cos ψ)); the net counterweight
    # u = −0.5 m opposite it pulls the block along +x0 with 0.5 m R ω²
    assert shaking_force(e, math.pi / 2, exact=False) == pytest.approx([0.5 * F1, -F1 * LAM])
    full = engine(1, k_rec=1.0)
    assert shaking_force_h1(full) == pytest.approx(0.0) and transverse_force_h1(full) == F1


def test_inline_four_cancels_first_order_and_moments_keeps_four_second_orders():
    e = engine(4)
    assert shaking_force_h1(e) == pytest.approx(0.0, abs=1e-12 * F1)
    assert shaking_force_h2(e) == pytest.approx(4 * shaking_force_h2(engine(1)), rel=1e-12)
    assert shaking_force_h2(e) == pytest.approx(4 * F1 * LAM)  # 129.2 N
    assert shaking_moment_h1(e) == pytest.approx(0.0, abs=1e-12 * F1 * A)
    assert shaking_moment_h2(e) == pytest.approx(0.0, abs=1e-12 * F1 * A)
    # the exact forces too: mirror-symmetric crank, no moment at any angle
    assert shaking_moment_amplitude(e) == pytest.approx(0.0, abs=1e-12 * F1 * A)
    orders = pilon_orders(e)
    assert orders[1] == pytest.approx(0.0, abs=1e-12 * F1)
    assert orders[2] == pytest.approx(4 * pilon_orders(engine(1))[2], rel=1e-12)
    two_term = shaking_force(e, THETA, exact=False)
    assert two_term[:, 1] == pytest.approx(4 * F1 * LAM * np.cos(2 * THETA))
    # rotating masses on the throws cancel as well (forces and moments)
    assert shaking_force_h1(engine(4, m_rot=0.1)) == pytest.approx(0.0, abs=1e-12 * F1)
    assert shaking_moment_amplitude(engine(4, m_rot=0.1)) == pytest.approx(0.0, abs=1e-9)


def test_cylinder_forces_add_up_to_the_shaking_force():
    """The per-cylinder forces sum to the block's force (no shafts); cylinder 2 of the
    twin is cylinder 1 half a turn later."""
    e = engine(2, m_rot=0.05, k_rot=0.5, k_rec=0.3)
    per = cylinder_forces(e, THETA)
    assert per.shape == (THETA.size, 2, 2)
    assert per.sum(axis=-2) == pytest.approx(shaking_force(e, THETA), abs=1e-12 * F1)
    assert per[:, 1] == pytest.approx(
        cylinder_forces(engine(1, m_rot=0.05, k_rot=0.5, k_rec=0.3), THETA + math.pi)[:, 0]
    )
    shafts = engine(4, balance_shaft=1.0)
    assert cylinder_forces(shafts, THETA) == pytest.approx(cylinder_forces(engine(4), THETA))


def test_twin_cancels_first_order_force_not_its_rocking_moment():
    e = engine(2)
    assert shaking_force_h1(e) == pytest.approx(0.0, abs=1e-12 * F1)
    assert shaking_force_h2(e) == pytest.approx(2 * F1 * LAM)
    assert shaking_moment_h1(e) == pytest.approx(F1 * A)  # 118.44 × 0.09 = 10.66 N·m
    assert shaking_moment_h2(e) == pytest.approx(0.0, abs=1e-12 * F1 * A)
    # exact: M_x = (a/2)(F(θ) − F(θ + π)) = a m R ω² cos θ, the even orders cancel
    moment = shaking_moment(e, THETA)
    assert moment[:, 0] == pytest.approx(F1 * A * np.cos(THETA), abs=1e-12 * F1 * A)
    assert shaking_moment_amplitude(e) == pytest.approx(F1 * A, rel=1e-12)


def test_lanchester_shafts_cancel_the_fours_second_order():
    e = engine(4, balance_shaft=1.0)
    assert lanchester_unbalance(e) == pytest.approx(M * R * LAM / 2)  # 1.636e-4 kg·m
    # each shaft: 4 ω² m·e; the pair: 8 ω² m·e = the four's 4 m R ω² λ
    assert 8 * W**2 * lanchester_unbalance(e) == pytest.approx(shaking_force_h2(engine(4)))
    assert shaking_force_h2(e) == 0.0
    assert shaking_force(e, THETA, exact=False) == pytest.approx(
        np.zeros((THETA.size, 2)), abs=1e-12 * F1
    )
    # left: the exact second order beyond λ (λ³/4 + ...: 1.9 % of it) and the fourth order
    orders = pilon_orders(e)
    assert orders[2] == pytest.approx(4 * F1 * (A2 - LAM), rel=5e-4)
    assert orders[4] == pytest.approx(pilon_orders(engine(4))[4], rel=1e-12)
    half = engine(4, balance_shaft=0.5)
    assert shaking_force_h2(half) == pytest.approx(0.5 * shaking_force_h2(engine(4)))


def test_the_courses_numbers():
    """Course 1: 17,000 tr/min, "le piston effectue 280 aller-retour chaque seconde":
    17,000 / 60 = 283.3; the course rounds down (1.2 %)."""
    assert strokes_per_second(17000) == pytest.approx(283.333, rel=1e-5)
    assert strokes_per_second(17000) == pytest.approx(280, rel=0.012)
    # forces grow with ω²: (17,000 / 3000)² = 32.1 times the compressor's default speed
    fast = Engine(1, R, L, M, 17000 * RPM)
    assert shaking_force_h1(fast) / F1 == pytest.approx((17000 / 3000) ** 2, rel=1e-12)


def test_piston_acceleration_is_the_second_derivative_of_its_position():
    psi, h = 0.7, 1e-4
    y = [
        R * math.cos(p) + math.sqrt(L**2 - (R * math.sin(p)) ** 2) for p in (psi - h, psi, psi + h)
    ]
    fd = (y[0] - 2 * y[1] + y[2]) / h**2 * W**2
    assert float(piston_acceleration(psi, R, L, W)) == pytest.approx(fd, rel=1e-6)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"cylinders": 3}, "cylinders"),
        ({"R": 0.0}, "R"),
        ({"L": 0.01}, "L"),
        ({"m": -1.0}, "m"),
        ({"omega": -1.0}, "omega"),
        ({"spacing": 0.0}, "spacing"),
        ({"m_rot": -0.1}, "m_rot"),
        ({"k_rec": 1.5}, "k_rec"),
        ({"k_rot": -0.1}, "k_rot"),
        ({"balance_shaft": 2.0}, "balance_shaft"),
        ({"R": float("nan")}, "R"),
    ],
)
def test_bad_inputs_name_the_parameter(kwargs, name):
    base = {"cylinders": 4, "R": R, "L": L, "m": M, "omega": W}
    with pytest.raises(ValueError, match=rf"^{name} "):
        Engine(**(base | kwargs))


def test_bad_samples_and_speed():
    with pytest.raises(ValueError, match="samples"):
        pilon_orders(engine(1), orders=6, samples=12)
    with pytest.raises(ValueError, match="speed_rpm"):
        strokes_per_second(-1.0)
