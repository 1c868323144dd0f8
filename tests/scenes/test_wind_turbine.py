"""The wind turbine's power chain (issue 39, course 6.4.2): the course's numbers at its
values, the rotor's power coefficient and Betz's limit, the start from rest against its
closed form, the kinetic-energy theorem at every instant, the chain's balances, and the
hard cases (a runaway rotor, no wind)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.mechanics.bearing import WIND_TURBINE, overall_efficiency
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.scenes.wind_turbine.course import (
    CP_BETZ,
    optimal_load,
    speed_from,
    steady_chain,
    steady_speed,
    time_constant,
)
from sandbox.written import written


def _sim(**values: float) -> Simulation:
    return Simulation(get_scene("wind_turbine"), values=values)


def test_the_courses_numbers_at_its_values():
    """5 MW of wind (Betz), 3,75 MW entering the gearbox, 375 kW lost there, 0,52
    overall: the simulated steady state, as the page writes it and to the course's
    digits."""
    sim = _sim()
    sim.advance(1.0)
    r = sim.readouts()
    assert r["P_wind"] == pytest.approx(5e6, rel=1e-4)
    assert r["P_gearbox_in"] == pytest.approx(0.75 * r["P_wind"], rel=1e-7)
    assert r["P_gearbox_loss"] == pytest.approx(0.1 * r["P_gearbox_in"], rel=1e-9)
    assert r["efficiency"] == pytest.approx(overall_efficiency(WIND_TURBINE), rel=1e-7)
    assert round(r["efficiency"], 2) == 0.52
    shown = {n: str(written(n, r[n], "W")) for n in ("P_wind", "P_gearbox_in", "P_gearbox_loss")}
    assert shown == {
        "P_wind": "5\u00a0MW",
        "P_gearbox_in": "3,75\u00a0MW",
        "P_gearbox_loss": "0,375\u00a0MW",
    }
    assert written("efficiency", r["efficiency"], "").number == "0,5194"
    for name, value in steady_chain(sim.values).items():
        if name in r:
            assert r[name] == pytest.approx(value, rel=1e-9, abs=1e-6), name


def test_the_power_coefficient_peaks_at_the_optimum_under_betz():
    """Cp = ρ_h (16/27) (2x − x²), x = λ/λ*: at most ρ_h · 16/27 (Betz's 16/27 for a
    perfect rotor), at λ*."""
    sim = _sim(eta_rotor=1.0, generator_load=optimal_load(_sim(eta_rotor=1.0).values))
    sim.advance(1.0)
    r = sim.readouts()
    assert r["tip_speed_ratio"] == pytest.approx(8.0, rel=1e-9)
    assert r["Cp"] == pytest.approx(CP_BETZ, rel=1e-12)
    for factor in (0.3, 0.8, 1.5):
        other = _sim(eta_rotor=1.0, generator_load=factor * sim.values["generator_load"])
        other.advance(1.0)
        x = other.readouts()["tip_speed_ratio"] / 8.0
        assert other.readouts()["Cp"] == pytest.approx(CP_BETZ * (2 * x - x * x), rel=1e-9)
        assert other.readouts()["Cp"] < CP_BETZ


def test_a_start_from_rest_follows_its_closed_form_and_fills_the_kinetic_energy():
    """ω(t) = ω_∞ (1 − e^(−t/τ)), τ ≈ 7,9 s; P_acc = dT/dt = P_ext + P_int at every
    instant; the power stored tends to 0 and T to ½ (J_r + J_g k²) ω_∞²."""
    sim = _sim(start=1.0)
    assert time_constant(sim.values) == pytest.approx(7.89, abs=0.01)
    w_inf = steady_speed(sim.values)
    j = sim.values["rotor_inertia"] + sim.values["generator_inertia"] * 100.0**2
    stored, taken = [], []
    for _ in range(60):
        sim.advance(1.0)
        r = sim.readouts()
        t = float(sim.data.time)
        assert r["omega"] == pytest.approx(speed_from(0.0, t, sim.values), rel=1e-12)
        assert abs(r["P_acc"] - r["P_ext"] - r["P_int"]) < 1e-9 * r["P_wind"]
        stored.append(r["P_rotor_store"] + r["P_generator_store"])
        taken.append(r["P_rotor"])
        w = speed_from(0.0, t, sim.values)  # dT/dt = J ω ω̇, ω̇ = (ω∞ − ω) / τ
        exact = j * w * (w_inf - w) / time_constant(sim.values)
        assert stored[-1] == pytest.approx(exact, rel=1e-9)
        assert r["P_acc"] == pytest.approx(stored[-1], rel=1e-9)
    assert stored[0] > 0.9 * taken[0]  # the first second mostly fills T
    peak = int(np.argmax(stored))  # J ω ω̇: ω grows while ω̇ falls, a peak near τ/2
    assert 2 <= peak <= 6 and np.all(np.diff(stored[peak:]) < 0)
    assert stored[-1] < 2e-3 * r["P_rotor"]
    assert r["T"] == pytest.approx(0.5 * j * r["omega"] ** 2, rel=1e-12)
    assert r["omega"] == pytest.approx(w_inf, rel=1e-3)


@pytest.mark.parametrize(
    "values", [{}, {"start": 1.0}, {"wind_speed": 14.0, "generator_load": 120.0}]
)
def test_every_stage_balances(values):
    """Each organ passes on what it receives less its loss and what its inertia stores:
    P₁ = P_rotor + not taken; P_rotor = stored + P_in; ρ_m P_in = P_gen + stored; the
    electric stages take their efficiencies."""
    sim = _sim(**values)
    sim.advance(2.0)
    r, v = sim.readouts(), sim.values
    assert r["P_wind"] == pytest.approx(r["P_rotor"] + r["P_rotor_loss"], rel=1e-12)
    assert r["P_rotor"] == pytest.approx(r["P_rotor_store"] + r["P_gearbox_in"], rel=1e-12)
    out = r["P_gearbox_in"] - r["P_gearbox_loss"]
    assert out == pytest.approx(r["P_generator_in"] + r["P_generator_store"], rel=1e-9)
    assert r["P_electric"] == pytest.approx(v["eta_generator"] * r["P_generator_in"], rel=1e-12)
    assert r["P_grid"] == pytest.approx(
        v["eta_generator"] * v["eta_transformer"] * v["eta_lines"] * r["P_generator_in"],
        rel=1e-12,
    )


def test_the_optimal_load_gives_the_most_power():
    """Too light a load lets the rotor race past λ*, too heavy slows it below: the grid
    gets the most at the load that holds λ* (the study preset's curve)."""
    base = _sim().values
    k_opt = optimal_load(base)
    assert k_opt == pytest.approx(base["generator_load"], rel=1e-3)
    best = steady_chain({**base, "generator_load": k_opt})["P_grid"]
    for factor in (0.5, 0.9, 1.1, 2.0):
        assert steady_chain({**base, "generator_load": factor * k_opt})["P_grid"] < best


def test_a_runaway_rotor_and_no_wind_stay_finite():
    """Hard cases: no load in a 25 m/s wind, the rotor races to 2λ* where the blades take
    nothing (ten minutes, no divergence); no wind: no power, the efficiency reads « — »."""
    sim = _sim(wind_speed=25.0, generator_load=0.0, start=1.0)
    sim.advance(600.0)
    r = sim.readouts()
    assert r["tip_speed_ratio"] == pytest.approx(16.0, rel=1e-9)
    assert abs(r["P_rotor"]) < 1e-6 * r["P_wind"]
    calm = _sim(wind_speed=0.0)
    calm.advance(5.0)
    r = calm.readouts()
    assert r["P_wind"] == 0.0 and r["omega"] == 0.0
    for ratio in ("efficiency", "Cp"):  # 0/0: written « — »
        assert math.isnan(r[ratio]) and written(ratio, r[ratio], "").number == "—"
    assert all(math.isfinite(v) for k, v in r.items() if k not in ("efficiency", "Cp"))


def test_choosing_the_start_relaunches_the_rotor_at_once():
    """« Départ : À l'arrêt » (a lesson's preset, or the dropdown) stops the rotor at once,
    the time going on; back to « En régime établi » it turns at ω∞ again; another
    parameter leaves the motion alone."""
    sim = _sim()
    sim.advance(3.0)
    t = float(sim.data.time)
    sim.set_value("start", 1.0)
    assert float(sim.data.qvel[0]) == 0.0 and float(sim.data.time) == t
    sim.advance(5.0)
    moving = float(sim.data.qvel[0])
    assert 0.0 < moving < steady_speed(sim.values)
    sim.set_value("wind_speed", 11.0)
    assert float(sim.data.qvel[0]) == moving
    sim.set_value("start", 0.0)
    assert float(sim.data.qvel[0]) == pytest.approx(steady_speed(sim.values), rel=1e-12)
