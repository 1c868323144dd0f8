"""Gyrometer (course 1): the spinning rotor keeps its axis; hard cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.physics.simulation import Simulation

N = ("spin", "gimbal_outer", "gimbal_inner", "axis_drift", "gimbal_lock", "sigma_G_x",
     "sigma_G_y", "sigma_G_z", "pivot_moment_inner", "pivot_moment_outer")  # fmt: skip


def _sigma(r):
    return math.sqrt(r["sigma_G_x"] ** 2 + r["sigma_G_y"] ** 2 + r["sigma_G_z"] ** 2)


def test_30000_rpm_for_10_seconds_with_the_case_still():
    sim = Simulation("gyroscope", values={"spin_rpm": 30000.0})
    r0 = sim.readouts(N)
    assert _sigma(r0) == pytest.approx(4e-4 * 30000 * 2 * math.pi / 60)  # C r
    sim.advance(10.0)
    r = sim.readouts(N)
    assert r["axis_drift"] < 1e-3
    assert _sigma(r) == pytest.approx(_sigma(r0), rel=1e-6)
    assert r["spin"] == pytest.approx(r0["spin"], rel=1e-4)


def test_spinning_the_axis_holds_and_the_gimbals_read_the_case():
    """Yaw the case by 40°: the outer gimbal turns back by 40° in the case, the axis stays."""
    sim = Simulation("gyroscope", values={"spin_rpm": 12000.0})
    sim.set_value("case_yaw_deg", 40.0)
    sim.advance(1.5)
    r = sim.readouts(N)
    assert r["axis_drift"] < 1e-2
    assert r["gimbal_outer"] == pytest.approx(-math.radians(40.0), rel=2e-2)
    assert r["pivot_moment_outer"] < 1e-3


def test_at_spin_zero_the_rotor_follows_the_case():
    sim = Simulation("gyroscope", values={"spin_rpm": 0.0})
    sim.set_value("case_yaw_deg", 40.0)
    sim.advance(3.0)
    assert sim.readouts(["axis_drift"])["axis_drift"] > 0.5 * math.radians(40.0)


@pytest.mark.parametrize("spin", [12000.0, 30000.0])
def test_gimbal_lock_is_traversed_without_warning_and_flagged(spin):
    sim = Simulation("gyroscope", values={"spin_rpm": spin})
    sim.set_value("manoeuvre", 1.0)
    flags = []
    for _ in range(60):
        sim.advance(0.1)  # Diverged would be raised on any MuJoCo warning or NaN
        r = sim.readouts(N)
        assert all(math.isfinite(v) for v in r.values())
        flags.append(r["gimbal_lock"])
    assert max(flags) == 1.0 and flags[-1] == 0.0
    assert r["spin"] == pytest.approx(spin * 2 * math.pi / 60, rel=1e-4)


def test_first_order_integrators_gain_energy_where_rk4_does_not():
    """The reason for the default: euler spins the axis away in the bench manoeuvre."""
    out = {}
    for integrator in ("euler", "rk4"):
        sim = Simulation(
            "gyroscope",
            values={"spin_rpm": 30000.0, "manoeuvre": 2.0},
            integrator=integrator,
            timestep=5e-4,
        )
        s0 = _sigma(sim.readouts(N))
        sim.advance(2.0)
        out[integrator] = abs(_sigma(sim.readouts(N)) / s0 - 1)
    assert out["rk4"] < 1e-6 < 1e-2 < out["euler"]


def test_pivot_moments_appear_when_the_case_turns_a_spinning_rotor():
    sim = Simulation("gyroscope", values={"spin_rpm": 30000.0})
    sim.set_value("manoeuvre", 2.0)
    peak = 0.0
    for _ in range(20):
        sim.advance(0.05)
        peak = max(peak, sim.readouts(["pivot_moment_inner"])["pivot_moment_inner"])
    assert np.isfinite(peak) and peak > 1e-4
