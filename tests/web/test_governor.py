"""The frame-rate governor (sandbox.web.loop.governor), driven with a fake clock: an
overloaded loop lowers every session's rate alike down to 15 frames/s, never the
simulated time; a lighter load raises it back; past the floor the process is saturated."""

from __future__ import annotations

import pytest

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.web.loop.controller import Controller
from sandbox.web.loop.governor import FLOOR_FPS, HIGH, LOW, SATURATED_AFTER, WINDOW, Governor
from sandbox.web.loop.scheduler import Scheduler


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def _window(gov: Governor, clock: Clock, share: float, given: float | None = None) -> None:
    """One window in which the loop was busy ``share`` of the wall time and gave each of
    its 30 sessions ``given`` frames a second (None: all it asked for when the loop had
    time to spare, half of it when busy all the time)."""
    if given is None:
        given = gov.fps * (0.5 if share > HIGH else 1.0)
    gov.spent(share * WINDOW, frames=round(30 * given * WINDOW))
    clock.now += WINDOW
    gov.update(served=30)


def test_an_overloaded_loop_lowers_the_rate_to_the_floor_and_a_light_one_raises_it():
    clock = Clock()
    gov = Governor(clock=clock)
    assert gov.fps == 60.0 and gov.scale == 1.0
    rates = []
    for _ in range(16):
        _window(gov, clock, 0.99)
        rates.append(gov.fps)
    assert rates == sorted(rates, reverse=True) and rates[0] < 60.0
    assert gov.fps == FLOOR_FPS
    assert gov.saturated  # at the floor and still over HIGH for SATURATED_AFTER windows
    for _ in range(30):
        _window(gov, clock, 0.1)
    assert gov.fps == 60.0 and not gov.saturated
    steady = gov.fps
    _window(gov, clock, (HIGH + LOW) / 2)  # in the band: nothing moves
    assert gov.fps == steady
    _window(gov, clock, 0.99, given=steady)  # busy all the time, yet keeping up: kept
    assert gov.fps == steady


def test_a_short_burst_does_not_saturate():
    clock = Clock()
    gov = Governor(clock=clock)
    for _ in range(16):
        _window(gov, clock, 0.99)
    assert gov.fps == FLOOR_FPS
    gov2 = Governor(clock=clock)
    gov2.fps = FLOOR_FPS
    for _ in range(SATURATED_AFTER - 1):
        _window(gov2, clock, 0.99)
    assert not gov2.saturated
    _window(gov2, clock, 0.3)
    _window(gov2, clock, 0.99)
    assert not gov2.saturated  # not in a row


def test_a_follower_s_slow_loop_keeps_its_own_rate():
    gov = Governor(clock=Clock())
    gov.fps = FLOOR_FPS
    assert gov.period_of(1 / 60) == pytest.approx(1 / FLOOR_FPS)
    assert gov.period_of(1 / 8) == pytest.approx(1 / 8)
    assert gov.period_of(1 / 240) == pytest.approx(1 / 60)  # a fast session, scaled alike


class Costly:
    """A session whose every frame takes ``cost`` seconds of the fake wall clock."""

    def __init__(self, clock: Clock, cost: float) -> None:
        self.clock = clock
        self.cost = cost
        self.period = 1 / 60
        self.turns: list[float] = []
        self.stopping = False

    def _turn(self, now: float) -> bool:
        self.turns.append(now)
        self.clock.now += self.cost
        return True

    def _end(self) -> None:
        pass


def _run(scheduler: Scheduler, clock: Clock, seconds: float) -> None:
    end = clock.now + seconds
    while clock.now < end:
        due = scheduler.next_due()
        assert due is not None
        clock.now = max(clock.now, due)
        scheduler.run_due()


def test_thirty_sessions_too_costly_for_60_frames_share_an_even_lower_rate():
    """30 sessions of 0.8 ms a frame need 1.44 s of loop per second at 60 frames/s: the
    governor lowers them all alike, so that every one gets the same frames, at least 15
    a second, and the loop keeps time for the websocket's sending."""
    clock = Clock()
    scheduler = Scheduler(clock=clock, threaded=False)
    sessions = [Costly(clock, 0.8e-3) for _ in range(30)]
    for s in sessions:
        scheduler.add(s)
    _run(scheduler, clock, 5.0)  # settles
    for s in sessions:
        s.turns.clear()
    _run(scheduler, clock, 10.0)
    counts = [len(s.turns) / 10.0 for s in sessions]
    assert min(counts) >= FLOOR_FPS
    assert max(counts) <= 1.5 * min(counts)
    assert max(counts) < 45  # lowered: 60 frames/s would take more than the whole loop
    assert scheduler.governor.share <= HIGH + 0.05
    assert not scheduler.governor.saturated


def test_far_too_costly_sessions_saturate_at_the_floor():
    clock = Clock()
    scheduler = Scheduler(clock=clock, threaded=False)
    sessions = [Costly(clock, 3e-3) for _ in range(30)]  # 1.35 s a second even at 15
    for s in sessions:
        scheduler.add(s)
    _run(scheduler, clock, 10.0)
    assert scheduler.governor.fps == FLOOR_FPS
    assert scheduler.governor.saturated


def test_simulated_time_keeps_real_time_at_the_floor_frame_rate(monkeypatch):
    """At 15 frames a second each frame steps a fifteenth of a second: the heavy top's RK4
    at 0.5 ms is 133 steps a frame. On a machine where a step takes 100 µs (a fake CPU
    clock), that is 13 ms a frame, more than the 5 ms a 60 frames/s frame may spend: the
    budget grows with the frame (30 % of its wall time), so the motion keeps real time."""
    import sandbox.web.loop.pacing as pacing

    cpu = [0.0]
    monkeypatch.setattr(pacing.time, "thread_time", lambda: cpu[0])
    clock = Clock()
    sim = Simulation(get_scene("heavy_gyroscope"))
    real_step = sim.step

    def step(n: int = 1) -> None:
        cpu[0] += 100e-6 * n
        real_step(n)

    monkeypatch.setattr(sim, "step", step)
    ctl = Controller(sim, clock=clock)
    ctl.frame()
    start = ctl.sim.data.time
    for _ in range(30):  # two seconds at 15 frames/s
        clock.now += 1 / FLOOR_FPS
        ctl.frame()
    rate = (ctl.sim.data.time - start) / 2.0
    assert rate >= 0.98
    assert not ctl.slowed()


def test_frames_held_for_the_browsers_senders_lower_the_rate_evenly():
    """The loop has time to spare but the websocket's thread cannot send every frame: a
    quarter of the frames are held back (each session draws nothing while its sender
    holds three frames). The rate goes down to what the browsers got, for every session
    alike, and is not raised while frames are still held."""
    clock = Clock()
    gov = Governor(clock=clock)
    gov.spent(0.5 * WINDOW, frames=30 * 60, held=30 * 15)
    clock.now += WINDOW
    gov.update(served=30)
    assert gov.fps == pytest.approx(45.0)
    gov.spent(0.3 * WINDOW, frames=30 * 45, held=30 * 9)  # still held: not raised
    clock.now += WINDOW
    gov.update(served=30)
    assert gov.fps <= 45.0
    gov.spent(0.3 * WINDOW, frames=30 * 40, held=0)  # sent again: raised
    clock.now += WINDOW
    gov.update(served=30)
    assert gov.fps > 40.0
