"""Inertia matrices against the course (5.4 block, 5.5 Huygens, 5.6 shapes)."""

from __future__ import annotations

import numpy as np
import pytest

from sandbox.mechanics import (
    MassProperties,
    block,
    change_basis,
    coefficients,
    combine,
    cylinder,
    hollow_cylinder,
    huygens,
    huygens_to_G,
    inertia_matrix,
    move_inertia,
    point_mass,
    principal_axes,
    rod,
    rotation_matrix,
    sphere,
)
from sandbox.mechanics.inertia import elliptic_k, torque_free_period


def _integrate(points: np.ndarray, mass: float) -> np.ndarray:
    dm = mass / len(points)
    return np.sum([point_mass(dm, p) for p in points], axis=0)


def test_course_block_example_5_4():
    """Square base a×a, height b, O at the centre of the base: A = m(a²/12 + b²/3)."""
    m, a, b = 2.0, 0.3, 0.5
    i_o = huygens(block(m, a, a, b), m, [0, 0, -b / 2])  # GO = (0, 0, -b/2)
    assert i_o[0, 0] == pytest.approx(m * (a * a / 12 + b * b / 3))
    n = 40  # midpoint rule: relative error ~1/n² on the a² terms
    g = (np.arange(n) + 0.5) / n
    x, y, z = np.meshgrid((g - 0.5) * a, (g - 0.5) * a, g * b, indexing="ij")
    numeric = _integrate(np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1), m)
    np.testing.assert_allclose(numeric, i_o, rtol=1e-3, atol=1e-9)
    A, B, C, D, E, F = coefficients(i_o)
    assert D == E == F == 0.0


def test_huygens_both_ways_and_the_course_warning():
    m, i_g = 3.0, block(3.0, 0.1, 0.2, 0.3)
    ga, gb = np.array([0.1, -0.2, 0.3]), np.array([-0.4, 0.1, 0.05])
    i_a = huygens(i_g, m, ga)
    np.testing.assert_allclose(huygens_to_G(i_a, m, ga), i_g, atol=1e-14)
    g = np.zeros(3)
    i_b = move_inertia(i_a, m, g, ga, gb)
    np.testing.assert_allclose(i_b, huygens(i_g, m, gb), atol=1e-14)
    wrong = huygens(i_a, m, gb - ga)  # Huygens from A instead of G: not I_B
    assert not np.allclose(wrong, i_b)


def test_shapes_reduce_to_rod():
    np.testing.assert_allclose(cylinder(2.0, 0.0, 1.0), rod(2.0, 1.0))
    np.testing.assert_allclose(block(2.0, 0.0, 0.0, 1.0), rod(2.0, 1.0))


def test_hollow_cylinder_is_full_minus_hole():
    rho, R, r, h = 7800.0, 0.1, 0.06, 0.2
    full, hole = rho * np.pi * R * R * h, rho * np.pi * r * r * h
    np.testing.assert_allclose(
        hollow_cylinder(full - hole, R, r, h),
        cylinder(full, R, h) - cylinder(hole, r, h),
        rtol=1e-12,
    )


def test_cylinder_and_sphere_by_sampling():
    rng = np.random.default_rng(1)
    pts = rng.uniform(-1, 1, size=(400_000, 3))
    ball = pts[np.linalg.norm(pts, axis=1) <= 1]
    np.testing.assert_allclose(
        np.diag(_integrate(ball * 0.2, 5.0)), np.diag(sphere(5.0, 0.2)), rtol=1e-2
    )
    R, h = 0.2, 0.5
    disk = pts[np.hypot(pts[:, 0], pts[:, 1]) <= 1] * [R, R, h / 2]
    np.testing.assert_allclose(
        np.diag(_integrate(disk, 4.0)), np.diag(cylinder(4.0, R, h)), rtol=1e-2
    )


def test_products_signs_of_a_point_mass():
    A, B, C, D, E, F = coefficients(point_mass(2.0, [1.0, 2.0, 3.0]))
    assert (D, E, F) == (12.0, 6.0, 4.0)
    assert (A, B, C) == (26.0, 20.0, 10.0)
    i = inertia_matrix(A, B, C, D, E, F)
    assert i[0, 1] == -4.0 and i[0, 2] == -6.0 and i[1, 2] == -12.0


def test_principal_axes_of_a_rotated_block():
    i = block(1.0, 0.1, 0.3, 0.6)
    rot = rotation_matrix([1, 2, 3], 0.7)
    moments, basis = principal_axes(rot @ i @ rot.T)
    np.testing.assert_allclose(moments, np.sort(np.diag(i)), rtol=1e-12)
    np.testing.assert_allclose(change_basis(rot @ i @ rot.T, basis), np.diag(moments), atol=1e-12)
    assert np.linalg.det(basis) == pytest.approx(1.0)


def test_mass_properties_of_two_point_masses():
    a = MassProperties.of_shape(np.zeros((3, 3)), 1.0, [0.0, 1.0, 0.0])
    b = MassProperties.of_shape(np.zeros((3, 3)), 3.0, [0.0, 0.0, 2.0])
    s = combine([a, b, MassProperties(0.0, np.ones(3), np.zeros((3, 3)))])
    np.testing.assert_allclose(s.com, [0, 0.25, 1.5])
    np.testing.assert_allclose(
        s.inertia_at(np.zeros(3)), point_mass(1.0, a.com) + point_mass(3.0, b.com), atol=1e-12
    )
    np.testing.assert_allclose((a + b).inertia_G, s.inertia_G)


def test_bad_dimensions_are_refused():
    with pytest.raises(ValueError, match="mass"):
        sphere(-1.0, 0.1)
    with pytest.raises(ValueError, match="inner_radius"):
        hollow_cylinder(1.0, 0.1, 0.2, 0.1)


def test_elliptic_k_known_values():
    """K(0) = π/2; K(1/√2) = Γ(1/4)² / (4√π) = 1.8540746773013719."""
    assert elliptic_k(0.0) == pytest.approx(np.pi / 2, rel=1e-15)
    assert elliptic_k(2**-0.5) == pytest.approx(1.8540746773013719, rel=1e-14)
    assert elliptic_k(0.999999) > 7.0  # K → ∞ as k → 1 (a launch near the separatrix)
    with pytest.raises(ValueError, match="modulus"):
        elliptic_k(1.0)


def _euler_crossings(moments: np.ndarray, omega: np.ndarray, axis: int, dt: float, n: int):
    """Times ω_axis rises through 0, integrating Euler's equations (RK4) from ``omega``."""

    def rate(w: np.ndarray) -> np.ndarray:
        i1, i2, i3 = moments
        return np.array(
            [
                (i2 - i3) * w[1] * w[2] / i1,
                (i3 - i1) * w[2] * w[0] / i2,
                (i1 - i2) * w[0] * w[1] / i3,
            ]
        )

    w, t, ups = np.asarray(omega, dtype=float), 0.0, []
    for _ in range(n):
        k1 = rate(w)
        k2 = rate(w + dt / 2 * k1)
        k3 = rate(w + dt / 2 * k2)
        k4 = rate(w + dt * k3)
        new = w + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if w[axis] < 0 <= new[axis]:
            ups.append(t + dt * -w[axis] / (new[axis] - w[axis]))
        w, t = new, t + dt
    return np.array(ups)


@pytest.mark.parametrize(
    ("omega", "axis"),
    [
        ([0.0, 2 * np.pi * np.cos(0.0175), 2 * np.pi * np.sin(0.0175)], 1),  # flip, σ² > 2T I₂
        ([2 * np.pi * np.cos(0.0175), 2 * np.pi * np.sin(0.0175), 0.0], 1),  # near 1, σ² < 2T I₂
        ([1.0, 2.0, 3.0], 0),
    ],
    ids=["intermediate", "smallest", "generic"],
)
def test_torque_free_period_against_eulers_equations(omega, axis):
    """Block 0.1 × 0.2 × 0.3 m, 1 kg: the closed form (Jacobi functions) against a fine
    RK4 integration of Euler's equations: the component that changes sign comes back
    after one period (6.7132 s for the 60 rpm flip, 1° off the middle axis)."""
    moments = np.array([0.05, 0.10, 0.13]) / 12
    period = torque_free_period(moments, omega)
    ups = _euler_crossings(moments, np.array(omega), axis, 1e-3, int(2.5 * period / 1e-3))
    assert np.diff(ups) == pytest.approx(period, rel=1e-6)
    if axis == 1 and omega[0] == 0.0:
        assert period == pytest.approx(6.713204, rel=1e-6)


def test_torque_free_period_refuses_equal_moments_and_the_separatrix():
    with pytest.raises(ValueError, match="I1 < I2 < I3"):
        torque_free_period([1.0, 1.0, 2.0], [0.0, 1.0, 0.1])
    with pytest.raises(ValueError, match="separatrix"):
        torque_free_period([1.0, 2.0, 3.0], [0.0, 1.0, 0.0])
