"""A fast rotation's numbers held at one angle (sandbox.physics.strobe): the held instant
is the last time the input passed its scene's angle, the state there is the imposed
motion's exact one (the course's closed forms at that angle), the same every turn, and
nothing is held when the rotation is slow, seen in slow motion, simulated, or varying.
"""

from __future__ import annotations

import math

import pytest

from sandbox.physics.simulation import Simulation
from sandbox.physics.strobe import HELD_PERIOD, TURN, Held, held_time
from sandbox.scenes import get_scene


def _compressor(rpm: float = 3000.0, motion: str = "imposed") -> Simulation:
    return Simulation(get_scene("compressor"), values={"speed_rpm": rpm}, motion=motion)


def test_the_held_instant_is_the_last_passage_at_the_scenes_angle():
    sim = _compressor()
    imposed = sim.imposed
    assert imposed is not None
    omega = 3000 * TURN / 60
    for t in (0.0, 0.013, 0.25, 7.0031, 3600.0):
        at = held_time(imposed, sim.values, sim.data, t)
        assert at is not None and 0.0 <= t - at < TURN / omega + 1e-12
        theta = imposed.motion(sim.values, sim.data, at)[0]
        gap = (theta - imposed.spec.held_at + math.pi) % TURN - math.pi
        assert abs(gap) < 1e-9 * max(1.0, abs(theta)), (t, gap)  # rad, round-off of θ(t)


def test_nothing_is_held_when_a_reader_can_follow_the_rotation():
    slow = _compressor(rpm=20.0)  # one turn in 3 s
    assert slow.imposed is not None
    assert held_time(slow.imposed, slow.values, slow.data, 1.0) is None
    fast = _compressor()
    assert fast.imposed is not None
    # 50 turns a second seen at ×0.01: one turn every 2 s of wall time, readable
    assert held_time(fast.imposed, fast.values, fast.data, 1.0, speed=0.01) is None
    assert held_time(fast.imposed, fast.values, fast.data, 1.0, speed=0.011) is not None
    assert 1 / HELD_PERIOD < 3000 / 60 * 0.011
    # simulated, not imposed: nothing to place exactly
    assert Held(_compressor(motion="free")).snapshot(1.0) is None


def test_the_held_state_is_the_courses_at_that_angle_and_the_same_every_turn():
    sim = _compressor()
    held = Held(sim)
    names = ["theta", "pilon", "pilon_ref", "tamis", "tamis_ref", "motor_torque"]
    first = held.snapshot(0.5)
    assert first is not None
    a = sim.readouts(names, snapshot=first)
    t_a = float(first.data.time)
    generation = held.generation
    second = held.snapshot(0.77)  # thirteen turns and a half later
    assert second is not None
    b = sim.readouts(names, snapshot=second)
    assert held.generation == generation  # the same state: not placed again
    assert float(second.data.time) > t_a + 0.25  # this turn's instant
    assert math.degrees(a["theta"]) % 360 == pytest.approx(60.0, abs=1e-9)
    for name in ("pilon", "tamis", "motor_torque"):
        assert b[name] == a[name]
    peak = abs(a["pilon_ref"]) + abs(a["tamis_ref"])
    assert abs(a["pilon"] - a["pilon_ref"]) <= 1e-9 * peak  # exact: inverse dynamics
    assert abs(a["tamis"] - a["tamis_ref"]) <= 1e-9 * peak
    # a new speed: the law's new anchor, the state placed again, the course's new values
    sim.set_value("speed_rpm", 6000.0)
    third = held.snapshot(float(sim.data.time) + 0.3)
    assert third is not None and held.generation == generation + 1
    c = sim.readouts(names, snapshot=third)
    assert abs(c["pilon"]) == pytest.approx(4 * abs(a["pilon"]), rel=1e-9)  # ω²
    assert abs(c["pilon"] - c["pilon_ref"]) <= 1e-9 * (abs(c["pilon_ref"]) + abs(c["tamis_ref"]))


def test_a_speed_still_reached_through_a_lag_is_live_then_held_once_steady():
    """With ramp_s = 0.2 s the set point's lag makes the speed creep for a while: the
    numbers stay live while it changes by over a millionth a turn, held after."""
    sim = Simulation(
        get_scene("compressor"), values={"speed_rpm": 3000.0, "ramp_s": 0.2}, motion="imposed"
    )
    imposed = sim.imposed
    assert imposed is not None
    t0 = float(sim.data.time)
    assert held_time(imposed, sim.values, sim.data, t0 + 0.1) is None  # accelerating
    assert held_time(imposed, sim.values, sim.data, t0 + 5.0) is not None  # 25 lags later


def test_a_carriage_on_its_slide_is_never_held():
    sim = Simulation(get_scene("robot_axis"), values={"flexible": 0.0}, motion="imposed")
    assert sim.imposed is not None and sim.imposed.spec.held_at is None
    assert all(held_time(sim.imposed, sim.values, sim.data, t) is None for t in (0.1, 0.5, 2.0))
