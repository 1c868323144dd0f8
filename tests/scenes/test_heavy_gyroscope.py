"""Heavy gyroscope (course 2.2.2, 3): steady precession against the exact relation."""

from __future__ import annotations

import math

import pytest

from sandbox.physics.simulation import Simulation
from sandbox.scenes.heavy_gyroscope import precession


@pytest.mark.parametrize(
    "values",
    [{}, {"spin_rpm": 1000.0}, {"tilt_deg": 60.0}, {"mass": 3.0, "d": 0.05}, {"tilt_deg": 5.0}],
)
def test_steady_precession_matches_the_exact_relation_within_one_percent(values):
    sim = Simulation("heavy_gyroscope", values=values)
    exact, _ = precession(sim.values)
    for _ in range(10):
        sim.advance(0.2)
        r = sim.readouts(["precession_rate", "nutation"])
        assert r["precession_rate"] == pytest.approx(exact, rel=1e-2)
        assert r["nutation"] == pytest.approx(math.radians(sim.values["tilt_deg"]), abs=1e-3)


def test_fast_top_limit():
    """Ω → m g d / (C r) when the spin grows: within 1 % at 30,000 rpm."""
    exact, fast = precession({**Simulation("heavy_gyroscope").values, "spin_rpm": 30000.0})
    assert exact == pytest.approx(fast, rel=1e-2)
    sim = Simulation("heavy_gyroscope", values={"spin_rpm": 30000.0}, timestep=5e-5)
    sim.advance(0.5)
    assert sim.readouts(["precession_rate"])["precession_rate"] == pytest.approx(fast, rel=1e-2)


def test_energy_and_vertical_angular_momentum_are_kept():
    sim = Simulation("heavy_gyroscope")
    r0 = sim.readouts(["T", "V", "sigma_O_z", "spin"])
    sim.advance(5.0)
    r = sim.readouts(["T", "V", "sigma_O_z", "spin"])
    assert r["T"] + r["V"] == pytest.approx(r0["T"] + r0["V"], rel=1e-6)
    assert r["sigma_O_z"] == pytest.approx(r0["sigma_O_z"], rel=1e-5)
    assert r["spin"] == pytest.approx(r0["spin"], rel=1e-6)


def test_impossible_inertia_is_refused():
    from sandbox.errors import BadParameter

    with pytest.raises(BadParameter, match="I_transverse"):
        Simulation("heavy_gyroscope", values={"I_spin": 0.01, "I_transverse": 0.001})
