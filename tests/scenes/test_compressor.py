"""Micro-compressor (course 4, 6, 7.3) against the slider-crank closed forms, hard cases.

Tolerances: pilon, tamis and motor torque within 0.5 % of their peak over a revolution at
3000 rpm and
1 % in the hard cases; closure < 1e-6 m; |P_int| (the energy-theorem residual, since only
the motor works on the mechanism) < 1e-3 of the peak motor power; speed within 0.1 %.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from sandbox.mechanics import huygens
from sandbox.physics.simulation import Simulation
from sandbox.scenes.compressor import RPM, SCENE, fit_orders, frame_force, kinematics

NAMES = ("pilon", "pilon_ref", "tamis", "tamis_ref", "motor_torque", "motor_torque_ref",
         "closure_error", "P_int", "P_ext", "omega")  # fmt: skip


def _run(values=None, duration=0.1, *, every=5e-4, settle=0.0, timestep=None):
    """Simulate and sample; returns arrays of every readout in NAMES after ``settle``."""
    sim = Simulation("compressor", values=values or {}, timestep=timestep)
    rows = []
    for _ in range(int(round(duration / every))):
        sim.advance(every)
        if sim.data.time >= settle:
            rows.append(sim.readouts(NAMES))
    return sim, {n: np.array([r[n] for r in rows]) for n in NAMES}


def _peak_error(s, name):
    ref = s[name + "_ref"]
    return float(np.max(np.abs(s[name] - ref)) / np.max(np.abs(ref)))


def _assert_healthy(s, pilon_tol):
    assert np.all(np.isfinite(s["pilon"]))
    assert s["closure_error"].max() < 1e-6
    assert _peak_error(s, "pilon") < pilon_tol
    assert np.max(np.abs(s["P_int"])) < 1e-3 * np.max(np.abs(s["P_ext"]))


def test_slider_crank_kinematics_at_dead_centres_and_by_differences():
    R, L, w = 0.015, 0.055, 300.0
    assert kinematics(math.pi / 2, w, R, L).lam == pytest.approx(L + R)  # top dead centre
    assert kinematics(-math.pi / 2, w, R, L).lam == pytest.approx(L - R)  # bottom
    assert kinematics(math.pi / 2, w, R, L).dlam == pytest.approx(0.0, abs=1e-12)
    h = 1e-6
    for th in (0.3, 1.9, 4.0):
        k = kinematics(th, w, R, L)
        lam = lambda t: kinematics(t, w, R, L).lam  # noqa: E731
        assert k.dlam == pytest.approx(w * (lam(th + h) - lam(th - h)) / (2 * h), rel=1e-6)
        dl = lambda t: kinematics(t, w, R, L).dlam  # noqa: E731
        assert k.ddlam == pytest.approx(w * (dl(th + h) - dl(th - h)) / (2 * h), rel=1e-5)
        ph = lambda t: kinematics(t, w, R, L).phi  # noqa: E731
        assert k.dphi == pytest.approx(w * (ph(th + h) - ph(th - h)) / (2 * h), rel=1e-6)


def test_model_inertia_is_the_courses_matrix():
    """MuJoCo's crank inertia, moved back to O, is I_O,1 with A1, B1, C1 and -E1."""
    sim = Simulation("compressor", values={"E1": 2e-6})
    m, d = sim.model, sim.data
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "crank")
    mujoco.mj_resetData(m, d)
    mujoco.mj_forward(m, d)
    rot = d.ximat[b].reshape(3, 3)
    i_g = rot @ np.diag(m.body_inertia[b]) @ rot.T
    i_o = huygens(i_g, float(m.body_mass[b]), -d.xipos[b])
    v = sim.values
    expected = [[v["A1"], 0, -2e-6], [0, v["B1"], 0], [-2e-6, 0, v["C1"]]]
    assert i_o == pytest.approx(np.array(expected), abs=1e-12)


def test_effects_weight_off_contacts_off_closure_on():
    flags = Simulation("compressor").model.opt.disableflags
    assert flags & mujoco.mjtDisableBit.mjDSBL_GRAVITY
    assert flags & mujoco.mjtDisableBit.mjDSBL_CONTACT
    assert not flags & mujoco.mjtDisableBit.mjDSBL_EQUALITY


def test_3000_rpm_matches_the_course_within_half_a_percent_of_the_peak():
    sim, s = _run(duration=0.04, every=1e-4)  # two revolutions, 200 samples each
    assert _peak_error(s, "pilon") < 5e-3
    assert _peak_error(s, "tamis") < 5e-3
    assert np.max(np.abs(s["omega"] / (3000 * RPM) - 1)) < 1e-3  # speed held to 0.1 %
    _assert_healthy(s, 5e-3)
    assert _peak_error(s, "motor_torque") < 5e-3  # C_mot ω = dT/dt (energy theorem)


def test_the_frame_force_is_minus_the_sum_of_m_gamma():
    """Simulated pilon vs −Σ m Γ(G_i) from MuJoCo's own accelerations of the centres."""
    from sandbox.physics.readouts import body_accelerations

    sim = Simulation("compressor")
    sim.advance(0.007)
    sim.snapshot(["sup_R_x"])
    a_g, _ = body_accelerations(sim.model, sim.data)
    total = -(sim.model.body_mass[:, None] * a_g).sum(0)
    got = sim.readouts(["pilon", "tamis"])
    assert got["pilon"] == pytest.approx(total[1], rel=1e-6)
    assert got["tamis"] == pytest.approx(total[0], rel=1e-6)


def test_counterweight_trades_order_one_pilon_for_tamis_and_leaves_order_two():
    """7.3: balancing the rotating masses removes the tamis; more counterweight lowers
    the order-1 pilon but the tamis grows back; order 2 never changes."""
    out = {}
    for cw in (0.0, 0.1, 0.2):
        sim = Simulation("compressor", values={"counterweight_mass": cw})
        out[cw] = sim.readouts(["pilon_h1", "pilon_h2", "tamis_h1"])
        ref = sim.reference()
        for key in ("pilon_h1", "tamis_h1"):
            assert out[cw][key] == pytest.approx(ref[key], abs=5e-3 * ref["pilon_h1"] + 1.0)
        assert out[cw]["pilon_h2"] == pytest.approx(ref["pilon_h2"], rel=2e-2)
    assert out[0.2]["pilon_h1"] < out[0.1]["pilon_h1"] < out[0.0]["pilon_h1"]
    assert out[0.2]["tamis_h1"] > 5 * out[0.1]["tamis_h1"]
    h2 = [out[c]["pilon_h2"] for c in out]
    assert max(h2) - min(h2) < 1e-2 * max(h2)


def test_orders_fit_recovers_known_amplitudes():
    th = np.linspace(0, 2 * math.pi, 40, endpoint=False)
    amp = fit_orders(th, 3 + 2 * np.cos(th + 0.3) + 0.5 * np.sin(2 * th))
    assert amp[:3] == pytest.approx([3, 2, 0.5])


def test_frame_force_peaks_at_top_dead_centre():
    v = SCENE.defaults()
    w = 3000 * RPM
    f_tdc = frame_force(math.pi / 2, w, v)
    assert abs(f_tdc[1]) > abs(frame_force(0.0, w, v)[1])


def test_rod_shorter_than_crank_is_refused():
    from sandbox.errors import BadParameter

    with pytest.raises(BadParameter, match="longer than the crank"):
        Simulation("compressor", values={"R": 0.03, "L": 0.02})


# -- hard cases ------------------------------------------------------------------------------
@pytest.mark.slow
def test_17000_rpm_for_10_seconds():
    sim, s = _run({"speed_rpm": 17000}, duration=10.0, every=0.05)
    _assert_healthy(s, 1e-2)
    _, tail = _run({"speed_rpm": 17000}, duration=0.01, every=2e-5)  # a dense revolution
    _assert_healthy(tail, 1e-2)


def test_short_rod_l_over_r_1_1():
    _, s = _run({"L": 0.0165}, duration=0.1, every=2e-4)
    _assert_healthy(s, 1e-2)


def test_start_from_rest_with_a_ramp():
    sim = Simulation("compressor", values={"ramp_s": 0.1})
    assert sim.readouts(["omega"])["omega"] == 0.0
    rows = []
    while sim.data.time < 1.0:
        sim.advance(2e-3)
        rows.append(sim.readouts(NAMES))
    s = {n: np.array([r[n] for r in rows[-100:]]) for n in NAMES}  # the last 0.2 s
    assert np.max(np.abs(s["omega"] / (3000 * RPM) - 1)) < 1e-3
    assert max(r["closure_error"] for r in rows) < 1e-6
    _assert_healthy(s, 1e-2)


@pytest.mark.slow
def test_60_seconds_at_3000_rpm():
    sim, s = _run(duration=60.0, every=0.1)
    _assert_healthy(s, 1e-2)
    assert sim.readouts(["closure_error"])["closure_error"] < 1e-6
