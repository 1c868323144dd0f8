"""Imposed motion in the scenes (issue 35): the course's closed forms to 1e-9, the free
simulation's readouts at its finest setting to 1e-4 of their peak, loops closed after an
hour, continuous switches, recordings that replay bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.errors import BadOption
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene, resolve
from sandbox.scenes.compressor.params import RPM

IMPOSED_SCENES = [name for name, s in SCENES.items() if s.imposed is not None]


def test_the_scenes_the_course_drives_offer_an_imposed_motion():
    assert set(IMPOSED_SCENES) == {
        "compressor",
        "engine",
        "rotor",
        "wheel_balancer",
        "robot_axis",
    }
    assert Simulation(get_scene("compressor")).motion == "imposed"  # the course's steady regime
    assert Simulation(get_scene("engine")).motion == "imposed"
    assert Simulation(get_scene("rotor")).motion == "free"  # free by default, imposed on request
    assert Simulation(get_scene("gyroscope")).motions == ("free",)


def _turn(sim: Simulation, names: list[str], samples: int = 48) -> dict[str, np.ndarray]:
    """The readouts ``names`` at ``samples`` instants over one revolution."""
    omega = abs(sim.readouts(["omega"])["omega"]) if "omega" in sim.readout_names() else 1.0
    period = 2 * math.pi / omega
    rows = []
    for _ in range(samples):
        sim.advance(period / samples)
        r = sim.readouts(names)
        rows.append([r[n] for n in names])
    return dict(zip(names, np.array(rows).T, strict=True))


@pytest.mark.parametrize(
    "values",
    [
        {},
        {"speed_rpm": 17000.0},
        {"counterweight_mass": 0.12, "counterweight_radius": 0.02, "L": 0.03},
        {"speed_rpm": 6000.0, "ramp_s": 0.05},  # a start: θ'' in every term
    ],
)
def test_the_compressor_imposed_holds_the_course_s_closed_forms_to_1e9(values):
    sim = Simulation(get_scene("compressor"), values=values, motion="imposed")
    sim.advance(0.013)
    pairs = [("pilon", "pilon_ref"), ("tamis", "tamis_ref"), ("motor_torque", "motor_torque_ref")]
    got = _turn(
        sim, [n for pair in pairs for n in pair] + ["closure_error", "P_int", "P_acc", "P_ext"]
    )
    for a, b in pairs:
        peak = np.abs(got[b]).max()
        assert np.abs(got[a] - got[b]).max() <= 1e-9 * peak, a
    assert got["closure_error"].max() < 1e-12
    power = np.abs(got["P_ext"]).max()
    assert np.abs(got["P_acc"] - got["P_ext"] - got["P_int"]).max() <= 1e-9 * power
    assert np.abs(got["P_int"]).max() <= 1e-9 * power
    if not values.get("ramp_s"):
        r, ref = sim.readouts(), sim.reference()
        for name in ("pilon_h1", "pilon_h2", "tamis_h1"):
            assert r[name] == pytest.approx(ref[name], rel=1e-9, abs=1e-9 * ref["pilon_h1"])


@pytest.mark.parametrize(
    "values",
    [
        {"cylinders": 1},
        {"cylinders": 2},
        {"cylinders": 4},
        {"cylinders": 4, "lanchester": 1.0, "speed_rpm": 9000.0},
    ],
)
def test_the_engine_imposed_holds_the_course_s_closed_forms_to_1e9(values):
    sim = Simulation(get_scene("engine"), values=values, motion="imposed")
    sim.advance(0.01)
    names = ["pilon", "pilon_ref", "tamis", "tamis_ref", "shaking_moment", "shaking_moment_ref"]
    got = _turn(sim, names + ["closure_error", "P_acc", "P_ext", "P_int"])
    scale = max(np.abs(got["pilon_ref"]).max(), np.abs(got["tamis_ref"]).max(), 1.0)
    for a in ("pilon", "tamis"):
        assert np.abs(got[a] - got[a + "_ref"]).max() <= 1e-9 * scale, a
    moment = max(np.abs(got["shaking_moment_ref"]).max(), 1e-3)
    assert np.abs(got["shaking_moment"] - got["shaking_moment_ref"]).max() <= 1e-9 * moment
    assert got["closure_error"].max() < 1e-12
    power = max(np.abs(got["P_ext"]).max(), 1.0)
    assert np.abs(got["P_acc"] - got["P_ext"] - got["P_int"]).max() <= 1e-9 * power
    r, ref = sim.readouts(), sim.reference()
    for name in ("shaking_force_h1", "shaking_force_h2", "shaking_moment_max"):
        big = max(ref["shaking_force_h2"], ref["shaking_force_h1"], 1.0)
        assert r[name] == pytest.approx(ref[name], abs=1e-9 * big), name


def _peaks_by_unit(sim: Simulation, turn: dict[str, np.ndarray]) -> dict[str, float]:
    """The largest value over a revolution of the readouts of each unit (the scale a
    readout of that unit is compared at: a closure error against the lengths, P_int
    against the powers)."""
    units = {i.name: i.unit for i in sim.readout_infos()}
    peaks: dict[str, float] = {}
    for name, values in turn.items():
        unit = units[name]
        peaks[unit] = max(peaks.get(unit, 0.0), float(np.abs(values).max()))
    return peaks


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["compressor", "engine"])
def test_every_readout_imposed_equals_the_free_simulation_at_its_finest_setting(scene):
    """In steady state, at the free simulation's θ, θ' and θ'' (RK4, 1e-5 s, the
    benchmark's finest), every readout of the imposed motion is the free one's within 1e-4 of the
    peak of its kind (its unit) over a revolution."""
    free = Simulation(resolve(scene), motion="free", integrator="rk4", timestep=1e-5)
    free.advance(0.1)
    names = [n for n in free.readout_names() if n != "time"]
    imposed = Simulation(resolve(scene), motion="imposed")
    motion = imposed.imposed
    assert motion is not None
    turn = _turn(Simulation(resolve(scene), motion="imposed"), names)
    peaks = _peaks_by_unit(imposed, turn)
    units = {i.name: i.unit for i in imposed.readout_infos()}
    for _ in range(6):  # six instants of a revolution
        free.advance(0.0031)
        a = free.readouts(names)
        theta, omega = motion.input(free.data)
        alpha = float(free.data.qacc[0])  # the servo's ripple: J_rotor θ'' is in P_ext
        motion.place(imposed.model, imposed.data, imposed.values, (theta, omega, alpha))
        b = imposed.readouts(names)
        for n in names:
            scale = peaks[units[n]]
            if units[n] == "m":  # a closure error: against the mechanism's size
                scale = max(scale, float(imposed.model.stat.extent))
            assert abs(a[n] - b[n]) <= 1e-4 * scale + 1e-12, (n, a[n], b[n], scale)


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["compressor", "engine"])
def test_the_loops_stay_closed_after_an_hour_imposed(scene):
    sim = Simulation(resolve(scene), values={"speed_rpm": 6000.0}, motion="imposed")
    sim.advance(3600.0)
    assert sim.data.time == pytest.approx(3600.0, abs=1e-6)
    r = sim.readouts(["closure_error", "omega", "P_int", "P_ext"])
    assert r["closure_error"] < 1e-12
    assert r["omega"] == 6000.0 * RPM
    assert abs(r["P_int"]) < 1e-9 * max(abs(r["P_ext"]), 1.0)


def test_switching_keeps_the_input_s_angle_and_speed():
    sim = Simulation(get_scene("compressor"), motion="free")
    sim.advance(0.05)
    before = sim.readouts(["theta", "omega", "lambda"])
    sim.set_motion("imposed")
    after = sim.readouts(["theta", "omega", "lambda", "closure_error"])
    assert after["theta"] == before["theta"]
    assert after["omega"] == pytest.approx(before["omega"], rel=1e-4)  # the servo's ripple
    assert after["lambda"] == pytest.approx(before["lambda"], abs=1e-6)  # loop closed exactly
    assert after["closure_error"] < 1e-15
    sim.advance(0.05)
    mid = sim.readouts(["theta", "omega"])
    sim.set_motion("free")
    back = sim.readouts(["theta", "omega", "closure_error"])
    assert back["theta"] == mid["theta"] and back["omega"] == mid["omega"]
    sim.advance(0.05)
    assert sim.readouts(["closure_error"])["closure_error"] < 1e-6


def test_a_live_speed_change_keeps_the_angle_and_a_ramp_keeps_the_speed():
    sim = Simulation(get_scene("compressor"), motion="imposed")
    sim.advance(0.02)
    theta = sim.readouts(["theta"])["theta"]
    sim.set_value("speed_rpm", 6000.0)
    r = sim.readouts(["theta", "omega"])
    assert r["theta"] == theta and r["omega"] == 6000.0 * RPM  # the course's speed step
    ramp = Simulation(get_scene("compressor"), values={"ramp_s": 0.1}, motion="imposed")
    ramp.advance(0.05)
    before = ramp.readouts(["theta", "omega"])
    ramp.set_value("speed_rpm", 1000.0)
    after = ramp.readouts(["theta", "omega", "motor_torque", "motor_torque_ref"])
    assert after["theta"] == before["theta"] and after["omega"] == before["omega"]
    assert after["motor_torque"] == pytest.approx(after["motor_torque_ref"], rel=1e-9)


@pytest.mark.parametrize("scene", IMPOSED_SCENES)
def test_each_imposed_scene_runs_exactly_and_keeps_the_energy_theorem(scene):
    values = {"flexible": 0.0} if scene == "robot_axis" else {}
    sim = Simulation(resolve(scene), values=values, motion="imposed")
    for _ in range(20):
        sim.advance(0.037)
        r = sim.readouts()
        assert all(math.isfinite(v) for v in r.values())
        assert abs(r["P_acc"] - r["P_ext"] - r["P_int"]) <= 1e-9 * max(abs(r["P_ext"]), 1.0)
    assert sim.imposed is not None and sim.imposed.residual < 1e-9


def test_the_robot_axis_imposed_move_needs_the_rigid_arm_and_the_back_and_forth():
    with pytest.raises(BadOption, match="flexible"):
        Simulation(get_scene("robot_axis"), motion="imposed")
    sim = Simulation(get_scene("robot_axis"), values={"flexible": 0.0}, motion="imposed")
    sim.advance(0.3)
    r = sim.readouts(["C_m", "C_m_ref", "C_m_gap"])
    assert r["C_m"] == pytest.approx(r["C_m_ref"], rel=1e-9, abs=1e-12)
    sim.set_value("profile", 0.0)  # a torque command: the motion is simulated from here
    assert sim.motion == "free"
    sim.set_value("profile", 2.0)
    assert sim.motion == "imposed"  # asked for, and possible again


def test_the_wheel_balancer_s_soft_bench_is_simulated():
    with pytest.raises(BadOption) as caught:
        Simulation(get_scene("wheel_balancer"), values={"supports": 1.0}, motion="imposed")
    assert "ressorts" in caught.value.french


def test_a_motion_the_scene_lacks_or_a_crafted_name_is_refused_in_both_languages():
    with pytest.raises(BadOption) as caught:
        Simulation(get_scene("gyroscope"), motion="imposed")
    assert "--motion free" in str(caught.value)
    sim = Simulation(get_scene("compressor"))
    with pytest.raises(BadOption) as bad:
        sim.set_motion("<script>")
    assert "imposé ou libre" in bad.value.french
    assert sim.motion == "imposed"


def test_the_imposed_torque_row_is_named_for_what_the_motor_must_give():
    labels = {i.name: i.label for i in Simulation(get_scene("compressor")).readout_infos()}
    assert labels["motor_torque"] == "Couple nécessaire Cₘₒₜ"
    labels = {
        i.name: i.label for i in Simulation(get_scene("compressor"), motion="free").readout_infos()
    }
    assert labels["motor_torque"] == "Couple moteur Cₘₒₜ"


def test_an_imposed_recording_replays_and_verifies_bit_for_bit(tmp_path):
    from sandbox.recording import Recorder, load
    from sandbox.replay import open_simulation, verify

    sim = Simulation(get_scene("compressor"), values={"ramp_s": 0.05})
    path = tmp_path / "c.sbx"
    rec = Recorder(path, sim)
    for k in range(30):
        sim.step(7)
        if k == 10:
            sim.set_value("speed_rpm", 4500.0)
        if k == 18:
            sim.set_motion("free")
        if k == 24:
            sim.set_motion("imposed")
        rec.frame(sim.readouts())
    rec.close()
    loaded = load(path)
    assert loaded.header["motion"] == "imposed"
    assert [e["value"] for e in loaded.events if e["k"] == "motion"] == ["free", "imposed"]
    assert verify(loaded).deviation == 0.0
    again = open_simulation(loaded)
    assert again.motion == "imposed"
    assert again.readouts(["motor_torque"]) == pytest.approx(
        {"motor_torque": loaded.readouts[0][loaded.names.index("motor_torque")]}, rel=1e-12
    )


def test_an_imposed_speed_change_brings_its_timestep_at_once():
    """The imposed motion is exact at any step: the new speed's default timestep comes at
    once, both ways (the free crank keeps the fine step while its servo brakes it)."""
    sim = Simulation(get_scene("compressor"))
    sim.set_value("speed_rpm", 17000.0)
    assert sim.timestep == 1e-4
    sim.set_value("speed_rpm", 3000.0)
    assert sim.timestep == 5e-4
    sim.set_motion("free")
    assert sim.timestep == 5e-4
