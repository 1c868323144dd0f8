"""Heavy gyroscope (course 2.2.2, 3): steady precession against the exact relation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.scenes.heavy_gyroscope import RPM, SCENE, G, precession


@pytest.mark.parametrize(
    "values",
    [{}, {"spin_rpm": 1000.0}, {"tilt_deg": 60.0}, {"mass": 3.0, "d": 0.05}, {"tilt_deg": 5.0}],
)
def test_steady_precession_matches_the_exact_relation_within_one_percent(values):
    sim = Simulation(get_scene("heavy_gyroscope"), values=values)
    exact, _ = precession(sim.values)
    for _ in range(10):
        sim.advance(0.2)
        r = sim.readouts(["precession_rate", "nutation"])
        assert r["precession_rate"] == pytest.approx(exact, rel=1e-2)
        assert r["nutation"] == pytest.approx(math.radians(sim.values["tilt_deg"]), abs=1e-3)


@pytest.mark.parametrize("values", [{}, {"spin_rpm": 500.0, "tilt_deg": 70.0}, {"d": 0.0}])
def test_the_slow_root_solves_the_steady_precession_relation(values):
    """A_O Ω² cos θ − C r Ω + m g d = 0, and Ω is the smaller of the two roots."""
    v = SCENE.defaults() | values
    omega, _ = precession(v)
    a_o = v["I_transverse"] + v["mass"] * v["d"] ** 2
    c_r = v["I_spin"] * v["spin_rpm"] * RPM
    k, mgd = a_o * math.cos(math.radians(v["tilt_deg"])), v["mass"] * G * v["d"]
    assert k * omega**2 - c_r * omega + mgd == pytest.approx(0.0, abs=1e-12 * c_r**2 / k)
    roots = sorted(np.roots([k, -c_r, mgd]).real)
    assert omega == pytest.approx(roots[0], rel=1e-9, abs=1e-12)


def test_too_slow_a_spin_has_no_steady_precession():
    exact, fast = precession(SCENE.defaults() | {"spin_rpm": 100.0})
    assert math.isnan(exact) and math.isfinite(fast)


def test_fast_top_limit():
    """Ω → m g d / (C r) when the spin grows: within 1 % at 30,000 rpm, where the default
    timestep still holds the exact root to 1e-3 (r dt = 0.47)."""
    exact, fast = precession(SCENE.defaults() | {"spin_rpm": 30000.0})
    assert exact == pytest.approx(fast, rel=1e-2)
    sim = Simulation(get_scene("heavy_gyroscope"), values={"spin_rpm": 30000.0})
    for _ in range(5):
        sim.advance(0.2)
        r = sim.readouts(["precession_rate", "nutation"])
        assert r["precession_rate"] == pytest.approx(fast, rel=1e-2)
        assert r["precession_rate"] == pytest.approx(exact, rel=1e-3)
        assert r["nutation"] == pytest.approx(math.radians(30.0), abs=1e-4)


def test_energy_and_vertical_angular_momentum_are_kept():
    sim = Simulation(get_scene("heavy_gyroscope"))
    r0 = sim.readouts(["T", "V", "sigma_O_z", "spin"])
    sim.advance(5.0)
    r = sim.readouts(["T", "V", "sigma_O_z", "spin"])
    assert r["T"] + r["V"] == pytest.approx(r0["T"] + r0["V"], rel=1e-6)
    assert r["sigma_O_z"] == pytest.approx(r0["sigma_O_z"], rel=1e-5)
    assert r["spin"] == pytest.approx(r0["spin"], rel=1e-6)


def test_ball_joint_does_not_drift_over_a_minute():
    """60 s on the ball joint (about 4 turns of precession): unit quaternion, θ, Ω, T + V.

    RK4 is not symplectic: it gains a little T + V, so θ creeps up linearly, as dt⁵.
    Measured at the default (0.5 ms at 3000 rpm): 3.4e-5 rad in a minute, Ω within 8.7e-6
    of the exact root, T + V within 8.5e-8 of itself (0.2 ms: 3.5e-7, 2.2e-7, 1e-9; 1 ms:
    1.1e-3 rad, 1.4e-4, 2.7e-6). The bounds below sit between 0.5 ms and 1 ms, under the
    four significant figures the page writes (30,00° and 0,002° of creep)."""
    assert Simulation(get_scene("heavy_gyroscope")).timestep == 5e-4
    sim = Simulation(get_scene("heavy_gyroscope"))
    exact, _ = precession(sim.values)
    theta = math.radians(sim.values["tilt_deg"])
    r0 = sim.readouts(["T", "V"])
    for _ in range(60):
        sim.advance(1.0)
        assert abs(np.linalg.norm(sim.data.qpos[:4]) - 1.0) < 1e-12
        r = sim.readouts(["precession_rate", "nutation", "T", "V"])
        assert r["nutation"] == pytest.approx(theta, abs=1e-4)
        assert r["precession_rate"] == pytest.approx(exact, rel=3e-5)
    assert r["T"] + r["V"] == pytest.approx(r0["T"] + r0["V"], rel=3e-7)


def test_a_new_spin_or_tilt_relaunches_on_the_new_steady_precession():
    sim = Simulation(get_scene("heavy_gyroscope"))
    sim.advance(0.3)
    model = sim.model
    sim.set_value("spin_rpm", 6000.0)
    sim.set_value("tilt_deg", 45.0)
    assert sim.model is model  # live: no rebuild
    sim.advance(0.5)
    exact, _ = precession(sim.values)
    r = sim.readouts(["precession_rate", "nutation", "spin"])
    assert r["precession_rate"] == pytest.approx(exact, rel=1e-3)
    assert r["nutation"] == pytest.approx(math.radians(45.0), abs=1e-4)
    assert r["spin"] == pytest.approx(6000.0 * RPM, rel=1e-6)


def test_the_timestep_follows_the_spin_above_9000_rpm():
    """At most 0.47 rad of spin per step (RK4's 6e-4 on Ω at 30,000 rpm and 0.15 ms),
    at most 0.5 ms; smaller at once, larger after 50 steps; a user's timestep stays."""
    spins = (0, 3000, 9000, 12000, 22500, 30000)
    assert [SCENE.default_timestep({"spin_rpm": r}) for r in spins] == [
        5e-4,
        5e-4,
        5e-4,
        3e-4,
        2e-4,
        1.5e-4,
    ]
    sim = Simulation(get_scene("heavy_gyroscope"))
    sim.set_value("spin_rpm", 30000.0)
    assert sim.timestep == 1.5e-4
    sim.set_value("spin_rpm", 3000.0)
    assert sim.timestep == 1.5e-4  # a step grows back only after 50 steps of the new motion
    for _ in range(52):  # (checked after each call of step)
        sim.step(1)
    assert sim.timestep == 5e-4
    assert Simulation(get_scene("heavy_gyroscope"), values={"spin_rpm": 30000.0}).timestep == 1.5e-4
    user = Simulation(get_scene("heavy_gyroscope"), timestep=5e-5)
    user.set_value("spin_rpm", 30000.0)
    assert user.timestep == 5e-5


def test_a_new_mass_acts_on_the_running_top():
    """Mass is model data: the motion goes on, no longer steady, so θ starts to nutate."""
    sim = Simulation(get_scene("heavy_gyroscope"), values={"spin_rpm": 1000.0})
    sim.advance(0.3)
    t, spin = sim.data.time, sim.readouts(["spin"])["spin"]
    sim.set_value("mass", 2.0)
    assert sim.data.time == t and sim.readouts(["spin"])["spin"] == pytest.approx(spin)
    theta = math.radians(sim.values["tilt_deg"])
    swing = 0.0
    for _ in range(20):
        sim.advance(0.02)
        swing = max(swing, abs(sim.readouts(["nutation"])["nutation"] - theta))
    assert swing > 1e-3


def test_impossible_inertia_is_refused():
    from sandbox.errors import BadParameter

    with pytest.raises(BadParameter, match="I_transverse"):
        Simulation(get_scene("heavy_gyroscope"), values={"I_spin": 0.01, "I_transverse": 0.001})
