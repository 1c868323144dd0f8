"""Wheel balancer (course 7.1, 7.2): bearing forces, the machine's clips, the lab bench."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.scenes import wheel_balancer as wb
from sandbox.scenes.wheel_balancer import (
    MYSTERIES,
    SCENE,
    influence_solution,
    machine_solution,
    reference,
    supports_model,
    wheel_properties,
)
from sandbox.scenes.wheel_balancer.geometry import mass_points, springs, tube_inertia, z_to
from sandbox.scenes.wheel_balancer.params import AXIS, DAMPER, HALF_SPAN, SPRING
from sandbox.scenes.wheel_balancer.readouts import phase
from sandbox.web.panels.display import markers

RPM = 2 * math.pi / 60
FORCES = ("bearing_inner", "bearing_outer")
CLIPS = ("clip_inner_g", "clip_inner_deg", "clip_outer_g", "clip_outer_deg")
SOFT = {"supports": 1.0}

RIGID_CASES = [
    {},
    {"speed_rpm": 2000.0},
    {"defect_mass_g": 80.0, "defect_angle_deg": 300.0, "skew_deg": -0.8, "speed_rpm": 450.0},
    {"mass_inner_g": 25.0, "angle_inner_deg": 10.0, "mass_outer_g": 5.0, "trial_plane": 2.0},
    *({"mystery": float(k)} for k in range(1, len(MYSTERIES) + 1)),
]


def _run(values: dict[str, float], duration: float = 0.3) -> Simulation:
    sim = Simulation(get_scene("wheel_balancer"), values=values)
    sim.advance(duration)
    return sim


def _angle_gap(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


@pytest.mark.parametrize("values", RIGID_CASES)
def test_bearing_forces_match_the_course_on_rigid_bearings(values):
    """7.2.1 with the machine's geometry: P_A + P_B = ω² S and x_A P_A + x_B P_B = ω² C,
    S and C from the wheel's shapes (two_planes.bearing_forces), tolerance 0.5 %."""
    sim = _run(values)
    got = sim.readouts([*FORCES, "omega"])
    ref = reference(sim.values)
    for key in (*FORCES, "omega"):
        assert got[key] == pytest.approx(ref[key], rel=5e-3), key


@pytest.mark.parametrize("values", RIGID_CASES)
def test_machine_clips_from_measured_forces_are_the_exact_answer(values):
    """The clips the machine computes from its simulated bearing forces and speed are the
    closed form's (course 7.2.3) for the wheel as it is, hidden unbalance included."""
    sim = _run(values)
    got = sim.readouts(list(CLIPS))
    ref = reference(sim.values)
    for key in ("clip_inner_g", "clip_outer_g"):
        assert got[key] == pytest.approx(ref[key], rel=1e-6), key
    for key in ("clip_inner_deg", "clip_outer_deg"):
        assert _angle_gap(got[key], ref[key]) < 1e-4, key


def test_machine_clips_of_a_known_wheel_by_hand():
    """Tyre square (β = 0), heavy spot 30 g at 310 mm, angle 60°, in the mid-plane x = 100
    mm: its unbalance u = 9.3 g·m splits between the rim planes x = 15 and 185 mm by the
    lever rule: (185 − 100)/170 = 1/2 each, 4.65 g·m, i.e. 4.65/0.19 = 24.474 g per plane,
    opposite (240°). The machine reads it from its bearings."""
    sim = _run({"skew_deg": 0.0})
    got = sim.readouts(list(CLIPS))
    assert got["clip_inner_g"] == pytest.approx(24.4737, rel=1e-4)
    assert got["clip_outer_g"] == pytest.approx(24.4737, rel=1e-4)
    assert got["clip_inner_deg"] == pytest.approx(240.0, abs=1e-6)
    assert got["clip_outer_deg"] == pytest.approx(240.0, abs=1e-6)


def test_bearing_forces_of_the_heavy_spot_by_hand():
    """Same square tyre at 200 tr/min (ω² = 438.65 s⁻²): the rotating force of the spot is
    m r ω² = 0.03 × 0.31 × 438.65 = 4.0795 N at x = 0.10 m, carried by A (x = −0.30) and
    B (x = −0.10) on the lever: F_B = 4.0795 × 0.40/0.20 = 8.1590 N, F_A = 4.0795 N
    (opposite: the wheel overhangs)."""
    got = _run({"skew_deg": 0.0}).readouts(list(FORCES))
    assert got["bearing_outer"] == pytest.approx(8.1590, rel=5e-3)
    assert got["bearing_inner"] == pytest.approx(4.0795, rel=5e-3)


@pytest.mark.parametrize("speed", [200.0, 2000.0])
@pytest.mark.parametrize("mystery", range(len(MYSTERIES) + 1))
def test_the_machines_clips_balance_the_wheel(speed, mystery):
    """Issue 15: with the machine's clips both bearing forces fall below 1 % of the
    unbalanced ones (here below 1e-6: the clips are exact)."""
    values = {"speed_rpm": speed, "mystery": float(mystery)}
    before = _run(values)
    shown = before.readouts(list(CLIPS))
    forces = before.readouts(list(FORCES))
    placed = {
        "mass_inner_g": shown["clip_inner_g"],
        "angle_inner_deg": shown["clip_inner_deg"],
        "mass_outer_g": shown["clip_outer_g"],
        "angle_outer_deg": shown["clip_outer_deg"],
    }
    assert placed.items() <= (machine_solution(before.values) | placed).items()
    after = _run(values | placed).readouts([*FORCES, "clip_inner_g", "clip_outer_g"])
    for key in FORCES:
        assert forces[key] > 1.0  # N: a real unbalance to cancel
        assert after[key] < 1e-6 * forces[key], key
    # the machine then asks for nothing more
    assert after["clip_inner_g"] < 1e-5 and after["clip_outer_g"] < 1e-5


def test_rounded_clips_as_a_student_types_them_are_within_two_percent():
    """The lesson's mystery step accepts 2 %: clips typed to 0.1 g and 0.1° do it."""
    values = {"mystery": 2.0}
    exact = machine_solution(Simulation(get_scene("wheel_balancer"), values=values).values)
    typed = {k: round(v, 1) for k, v in exact.items()}
    before = _run(values).readouts(list(FORCES))
    after = _run(values | typed).readouts(list(FORCES))
    for key in FORCES:
        assert after[key] < 0.02 * before[key], key


def test_mystery_wheels_hide_their_unbalance():
    """A mystery wheel changes the physics, not the sliders: they keep the free setting;
    its heavy spot is not drawn nor labelled; no readout is an unbalance parameter."""
    free = _run({})
    hidden_names = set(wb.HIDDEN)
    for k in range(1, len(MYSTERIES) + 1):
        sim = _run({"mystery": float(k)})
        for name in hidden_names:
            assert sim.values[name] == SCENE.param(name).default
        defect = sim.model.geom("defect").id
        assert sim.model.geom_rgba[defect][3] == 0.0
        assert defect not in markers(sim.model)
        assert sim.readouts(["bearing_inner"]) != free.readouts(["bearing_inner"])
    assert free.model.geom("defect").id in markers(free.model)
    names = {r.name for r in SCENE.readouts}
    assert not names & hidden_names
    assert names == {"omega", *FORCES, *CLIPS, "accel_inner", "accel_inner_deg"} | {
        "accel_outer",
        "accel_outer_deg",
        *(f"bearing_{b}_{q}" for b in "AB" for q in ("pmax", "Cf")),
    }


def test_mysteries_are_distinct_and_within_the_sliders():
    for hidden in MYSTERIES:
        for name, value in hidden.items():
            assert SCENE.param(name).check(value) == value
    clips = [machine_solution(SCENE.defaults() | {"mystery": float(k)}) for k in (1, 2, 3)]
    assert len({round(c["mass_inner_g"], 1) for c in clips}) == 3
    for c in clips:
        assert c["mass_inner_g"] <= 150 and c["mass_outer_g"] <= 150  # the sliders reach them


def test_course_speeds_of_7_1():
    """Course 7.1: the helicopter's main rotor turns at 400 tr/min, its tail rotor at
    2000 tr/min (the scene's top speed): ω = 41.888 and 209.44 rad/s, and the bearing
    forces grow as ω², by (2000/400)² = 25 (within 0.5 %)."""
    assert SCENE.param("speed_rpm").max == 2000.0
    slow = _run({"speed_rpm": 400.0}).readouts(["omega", *FORCES])
    fast = _run({"speed_rpm": 2000.0}).readouts(["omega", *FORCES])
    assert slow["omega"] == pytest.approx(41.888, rel=5e-3)
    assert fast["omega"] == pytest.approx(209.44, rel=5e-3)
    for key in FORCES:
        assert fast[key] / slow[key] == pytest.approx(25.0, rel=5e-3)


def test_long_run_at_the_top_speed_stays_steady():
    """60 s at 2000 tr/min on rigid bearings: speed and forces unchanged (1e-6)."""
    sim = _run({"speed_rpm": 2000.0})
    start = sim.readouts(["omega", *FORCES])
    sim.advance(60.0)
    end = sim.readouts(["omega", *FORCES])
    for key in start:
        assert end[key] == pytest.approx(start[key], rel=1e-6), key


def test_machine_shows_nothing_at_rest():
    sim = _run({"speed_rpm": 0.0})
    got = sim.readouts([*CLIPS, *FORCES])
    assert all(math.isnan(got[k]) for k in CLIPS)
    assert got["bearing_inner"] == pytest.approx(0.0, abs=1e-9)


def test_wheel_properties_are_the_models():
    """The closed form's wheel (shapes + Huygens) is MuJoCo's: mass, centre, inertia."""
    for values in ({}, {"mystery": 1.0, "mass_outer_g": 40.0, "angle_outer_deg": 70.0}):
        sim = Simulation(get_scene("wheel_balancer"), values=values)
        m, d = sim.model, sim.data
        ids = [m.body(b).id for b in ("wheel", "rim", "tyre")]
        mass = float(sum(m.body_mass[i] for i in ids))
        com = sum(m.body_mass[i] * d.xipos[i] for i in ids) / mass
        inertia = np.zeros((3, 3))
        for i in ids:
            rot = d.ximat[i].reshape(3, 3)
            r = d.xipos[i] - com
            inertia += rot @ np.diag(m.body_inertia[i]) @ rot.T
            inertia += m.body_mass[i] * (r @ r * np.eye(3) - np.outer(r, r))
        props = wheel_properties(sim.values)
        assert mass == pytest.approx(props.mass, rel=1e-9)
        assert com == pytest.approx(props.com, abs=1e-12)  # the wheel frame at the start
        assert inertia == pytest.approx(props.inertia_G, abs=1e-9)


def test_live_speed_change_needs_no_rebuild_and_a_clip_keeps_the_motion():
    sim = _run({})
    model = sim.model
    sim.set_value("speed_rpm", 600)
    assert sim.model is model
    sim.advance(1.0)
    assert sim.readouts(["omega"])["omega"] == pytest.approx(600 * RPM, rel=1e-4)
    angle, t = float(sim.data.qpos[0]), float(sim.data.time)
    sim.set_value("mass_inner_g", 12.0)
    assert float(sim.data.qpos[0]) == angle and float(sim.data.time) == t


# -- the lab bench: soft supports ----------------------------------------------------------------
def _criticals_rpm() -> tuple[float, ...]:
    return tuple(w / RPM for w in supports_model(SCENE.defaults() | SOFT).critical_speeds())


@pytest.mark.parametrize("speed", [100.0, 200.0, 600.0, 1500.0, 2000.0])
@pytest.mark.parametrize("mystery", [0.0, 3.0])
def test_soft_supports_vibrate_as_the_first_order_closed_form(speed, mystery):
    """Accelerometers on the bearings: amplitude within 0.5 %, phase within 0.5°, and the
    bearing forces within 0.5 %, against two_planes.synchronous_whirl (the bench's steady
    vibration, exact to first order)."""
    sim = _run(SOFT | {"speed_rpm": speed, "mystery": mystery}, duration=1.0)
    keys = ("accel_inner", "accel_outer", "accel_inner_deg", "accel_outer_deg")
    got = sim.readouts(list(keys))
    ref = reference(sim.values)
    for key in ("accel_inner", "accel_outer"):
        assert got[key] == pytest.approx(ref[key], rel=5e-3), key
    forces = sim.readouts(list(FORCES))  # the housing's action on the shaft
    for key in FORCES:
        assert forces[key] == pytest.approx(ref[key], rel=5e-3), key
    for key in ("accel_inner_deg", "accel_outer_deg"):
        assert _angle_gap(got[key], ref[key]) < 0.5, key


def test_critical_speeds_of_the_supports():
    """Two forward critical speeds inside the speed range: the housing's bounce and tilt
    (gyroscopic stiffening included); the lesson's 200 tr/min lies below the first."""
    low, high = _criticals_rpm()
    assert 250 < low < 400 and 900 < high < 1400, (low, high)


@pytest.mark.parametrize("index", [0, 1])
def test_resonance_of_the_supports_stays_stable_and_as_predicted(index):
    """At each critical speed: 20 s of simulation stay finite, the vibration matches the
    closed form (0.5 %) and is several times the one at 0.7 times that speed."""
    critical = _criticals_rpm()[index]
    sim = _run(SOFT | {"speed_rpm": critical}, duration=1.0)
    sim.advance(19.0)
    got = sim.readouts(["accel_inner", "accel_outer"])
    ref = reference(sim.values)
    for key in got:
        assert math.isfinite(got[key])
        assert got[key] == pytest.approx(ref[key], rel=5e-3), key
    away = reference(SCENE.defaults() | SOFT | {"speed_rpm": 0.7 * critical})
    at = max(got.values()) / (0.7**2)  # remove the ω² of the unbalance forcing
    assert at > 2.0 * max(away["accel_inner"], away["accel_outer"])


def test_soft_start_is_already_steady():
    """The initial state is the closed form's vibration: no start-up transient."""
    sim = Simulation(get_scene("wheel_balancer"), values=SOFT)
    sim.step(1)
    first = sim.readouts(["accel_outer"])["accel_outer"]
    assert first == pytest.approx(reference(sim.values)["accel_outer"], rel=5e-3)


@pytest.mark.parametrize("mystery", [0.0, 1.0, 2.0])
def test_influence_coefficients_from_three_simulated_runs_balance_the_bench(mystery):
    """Figure 40's method: runs without trial mass, with 20 g in the inner plane, then in
    the outer plane; the influence coefficients give the clips, which bring both
    accelerations below 1 % of the unbalanced ones once the transient has died out, and
    land within 1 g and 1° of the rigid machine's exact answer."""
    values = SCENE.defaults() | SOFT | {"mystery": mystery}
    before = _run(values, duration=0.5).readouts(["accel_inner", "accel_outer"])
    found = influence_solution(values)
    after = _run(values | found, duration=3.0).readouts(["accel_inner", "accel_outer"])
    for key in before:
        assert after[key] < 0.01 * before[key], key
    exact = machine_solution(values)
    for side in ("inner", "outer"):
        assert found[f"mass_{side}_g"] == pytest.approx(exact[f"mass_{side}_g"], abs=1.0)
        assert _angle_gap(found[f"angle_{side}_deg"], exact[f"angle_{side}_deg"]) < 1.0


def test_machine_formula_is_wrong_on_soft_supports():
    """The rigid machine's clips assume fixed bearings: on the soft bench near its first
    critical speed the housing's motion spoils them (why the lab uses trial masses)."""
    from sandbox.physics.snapshot import Snapshot

    sim = _run(SOFT | {"speed_rpm": 300.0}, duration=1.0)
    assert math.isnan(sim.readouts(["clip_outer_g"])["clip_outer_g"])  # not offered
    snap = sim.snapshot(("sup_R_x",))
    as_if_fixed = Snapshot(sim.model, sim.data, {**sim.values, "supports": 0.0})
    got = wb.machine_clips(as_if_fixed)["clip_outer_g"]  # the formula, forced
    assert snap.data is as_if_fixed.data
    assert abs(got / machine_solution(sim.values)["mass_outer_g"] - 1.0) > 0.2


def test_soft_supports_add_the_housing_joints():
    rigid, soft = (
        Simulation(get_scene("wheel_balancer")),
        Simulation(get_scene("wheel_balancer"), values=SOFT),
    )
    assert rigid.model.nv == 1 and soft.model.nv == 5
    flags = soft.model.opt.disableflags
    assert not flags & mujoco.mjtDisableBit.mjDSBL_SPRING
    assert rigid.readouts(["accel_inner"])["accel_inner"] == 0.0


def _typed_from_hint(hint: str) -> dict[str, float]:
    """The two clips a hint gives ("21,7 g à 333,5°"), as the student types them."""
    import re

    found = re.findall(r"([\d,]+) g à ([\d,]+)°", hint)
    assert len(found) == 2, hint
    number = [(float(g.replace(",", ".")), float(a.replace(",", "."))) for g, a in found]
    return {
        "mass_inner_g": number[0][0],
        "angle_inner_deg": number[0][1],
        "mass_outer_g": number[1][0],
        "angle_outer_deg": number[1][1],
    }


@pytest.mark.parametrize(("title", "keys"), [("Poser", FORCES), ("coefficients", ("accel_inner",))])
def test_the_lessons_hinted_clips_pass_its_checks(title, keys):
    """Lesson 8: the clips a hint states (machine display, influence computation), typed
    as written, pass the step's goal; the hints' trial readings are the simulation's."""
    from sandbox.lessons import get_lesson

    lesson = get_lesson("equilibreuse")
    index = next(i for i, s in enumerate(lesson.steps) if title in s.title)
    values: dict[str, float] = {}
    for step in lesson.steps[: index + 1]:
        values.update(dict(step.preset))
    step = lesson.steps[index]
    hint = next(h for h in reversed(step.hints) if " g à " in h)
    before = _run(values, duration=0.5).readouts(["accel_inner", "accel_outer", *FORCES])
    after = _run(values | _typed_from_hint(hint), duration=3.0).readouts(list(before))
    limit = 0.02 if keys == FORCES else 0.05
    names = FORCES if keys == FORCES else ("accel_inner", "accel_outer")
    for key in names:
        assert after[key] < limit * before[key], key


def test_the_lessons_resonance_peaks_of_bearing_b():
    """Lesson 8, step 5: the acceleration at B peaks near 350 and 1200 tr/min (simulated),
    next to the undamped critical speeds 332 and 1129 tr/min it quotes."""
    low, high = _criticals_rpm()
    assert round(low) == 332 and round(high) == 1129

    def accel(rpm: float) -> float:
        return _run(SOFT | {"speed_rpm": rpm}, duration=1.0).readouts(["accel_outer"])[
            "accel_outer"
        ]

    for peak, below, above in ((350.0, 250.0, 450.0), (1200.0, 1000.0, 1400.0)):
        top = accel(peak)
        assert top > accel(below) and top > accel(above), peak


def test_the_machines_clips_are_blank_on_the_soft_bench():
    """Issue 21: on the lab bench (supports = 1) the fixed-bearing formula gave 96 g at
    48° and 45 g at 212° for a wheel needing 22 g at 334° and 55 g at 217°: the machine's
    clips read NaN there ("—" in the page); the influence-coefficient method remains."""
    import math

    sim = Simulation(get_scene("wheel_balancer"), values={"supports": 1.0, "speed_rpm": 600.0})
    sim.advance(0.5)
    names = ["clip_inner_g", "clip_inner_deg", "clip_outer_g", "clip_outer_deg"]
    out = sim.readouts([*names, "accel_inner", "accel_outer"])
    assert all(math.isnan(out[n]) for n in names), out
    assert out["accel_inner"] > 0 and out["accel_outer"] > 0
    rigid = Simulation(get_scene("wheel_balancer"), values={"supports": 0.0})
    rigid.advance(0.2)
    assert all(math.isfinite(v) for v in rigid.readouts(names).values())


def test_springs_are_twice_the_per_bearing_ones_and_tilt_with_the_half_span_squared():
    k_t, c_t, k_r, c_r = springs()
    assert (k_t, c_t) == (2 * SPRING, 2 * DAMPER)
    assert k_r == pytest.approx(2 * SPRING * HALF_SPAN**2)
    assert c_r == pytest.approx(2 * DAMPER * HALF_SPAN**2)


def test_z_to_turns_z_onto_the_axis_and_tube_inertia_is_the_hollow_cylinder():
    for axis in (AXIS, np.array([0.0, 0.6, 0.8]), np.array([0.0, 0.0, 1.0])):
        turned = np.zeros(3)
        mujoco.mju_rotVecQuat(turned, np.array([0.0, 0.0, 1.0]), z_to(axis))
        assert turned == pytest.approx(axis, abs=1e-12)
    i = tube_inertia(8.0, 0.31, 0.19, 0.15)
    assert np.diag(i) == pytest.approx(
        [8.0 * (0.31**2 + 0.19**2) / 4 + 8.0 * 0.15**2 / 12] * 2 + [8.0 * (0.31**2 + 0.19**2) / 2]
    )


def test_mass_points_place_the_heavy_spot_the_clips_and_the_trial_mass():
    values = SCENE.defaults() | {"mass_inner_g": 25.0, "angle_inner_deg": 90.0}
    points = {name: (mass, pos) for name, mass, pos in mass_points(values)}
    assert list(points) == ["defect", "clip_inner", "clip_outer", "trial"]
    assert points["clip_inner"][0] == pytest.approx(0.025)
    assert points["clip_inner"][1] == pytest.approx([0.015, 0.0, 0.19], abs=1e-12)
    assert points["trial"][0] == 0.0  # trial_plane 0: no trial mass
    hidden = mass_points(values | {"mystery": 1.0})[0]
    assert hidden[1] == pytest.approx(MYSTERIES[0]["defect_mass_g"] / 1000)


def test_phase_counts_degrees_from_the_valve_in_0_360():
    assert phase(0j) == 0.0
    assert phase(1j) == pytest.approx(90.0)
    assert phase(-1 + 0j) == pytest.approx(180.0)
    assert phase(-1j) == pytest.approx(270.0)
