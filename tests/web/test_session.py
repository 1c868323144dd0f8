"""The session loop without a browser: pacing, requests, refusals and divergence."""

from __future__ import annotations

import pytest

from sandbox.physics.simulation import Simulation
from sandbox.web.session import MAX_LAG, Controller, Notice, Request, Session


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class Recorder:
    """A View that remembers what it was asked to show."""

    def __init__(self) -> None:
        self.frames = 0
        self.notices: list[Notice] = []

    def wants(self, now):
        return None

    def render(self, frame):
        self.frames += 1

    def notify(self, notice):
        self.notices.append(notice)


@pytest.fixture
def ctl():
    return Controller(Simulation("rotor"), clock=Clock())


def _run(ctl: Controller, seconds: float, fps: float = 60.0) -> list[Notice]:
    notices = []
    for _ in range(round(seconds * fps)):
        ctl.clock.now += 1.0 / fps
        notices += ctl.frame()
    return notices


def test_simulated_time_follows_the_wall_clock(ctl):
    _run(ctl, 1.0)
    assert ctl.sim.data.time == pytest.approx(1.0, abs=3 * ctl.sim.timestep)


def test_speed_factor_and_pause(ctl):
    ctl.submit(Request("speed", "2"))
    ctl.frame()
    _run(ctl, 0.5)
    assert ctl.sim.data.time == pytest.approx(1.0, abs=3 * ctl.sim.timestep)
    ctl.submit(Request("pause"))
    ctl.frame()
    _run(ctl, 0.5)
    assert ctl.sim.data.time == pytest.approx(1.0, abs=3 * ctl.sim.timestep)
    t = ctl.sim.data.time
    ctl.submit(Request("step", 3))
    _run(ctl, 0.1)
    assert ctl.sim.data.time == pytest.approx(t + 3 * ctl.sim.timestep, abs=1e-9)


def test_a_stalled_loop_resyncs_instead_of_racing(ctl):
    ctl.clock.now += 30.0  # the laptop slept
    ctl.frame()
    assert ctl.sim.data.time <= MAX_LAG + 2 * ctl.sim.timestep
    _run(ctl, 0.5)
    assert ctl.sim.data.time < 0.5 + MAX_LAG + 2 * ctl.sim.timestep


@pytest.mark.parametrize(
    "request_, needle",
    [
        (Request("set_value", "abc", name="mass1_g"), "needs a number"),
        (Request("set_value", 1e6, name="mass1_g"), "out of range"),
        (Request("set_value", 1, name="nope"), "nope"),
        (Request("timestep", 0), "timestep"),
        (Request("timestep", "nan"), "finite"),
        (Request("integrator", "leapfrog"), "rk4"),
        (Request("speed", 100), "speed"),
        (Request("launch_missiles"), "unknown request"),
    ],
)
def test_bad_requests_are_refused_with_a_message(ctl, request_, needle):
    values, dt = dict(ctl.sim.values), ctl.sim.timestep
    ctl.submit(request_)
    notices = ctl.frame()
    assert len(notices) == 1 and notices[0].level == "error"
    assert needle in notices[0].text
    assert ctl.sim.values == values and ctl.sim.timestep == dt
    _run(ctl, 0.2)
    assert ctl.sim.data.time > 0.15  # still running


def test_a_parameter_change_keeps_the_motion_going(ctl):
    _run(ctl, 0.3)
    t = ctl.sim.data.time
    ctl.submit(Request("set_value", "40", name="mass1_g"))
    assert ctl.frame() == []
    assert ctl.sim.values["mass1_g"] == 40.0
    assert ctl.sim.data.time >= t
    assert ctl.sim.readouts(["omega"])["omega"] == pytest.approx(50 * 3.14159265, rel=1e-3)


def test_divergence_pauses_with_an_explanation_and_reset_recovers(diverging_xml):
    ctl = Controller(Simulation(diverging_xml), clock=Clock())
    notices = _run(ctl, 3.0)
    assert [n.level for n in notices] == ["diverged"]
    assert "pas de temps" in notices[0].text and "Réinitialiser" in notices[0].text
    assert not ctl.playing and ctl.diverged
    ctl.submit(Request("play"))
    assert ctl.frame()[0].level == "error"  # must reset first
    ctl.submit(Request("timestep", 1e-5))  # ω dt = 0.3: stable
    ctl.submit(Request("reset"))
    assert ctl.frame() == []
    assert ctl.diverged is None and ctl.sim.data.time == 0.0
    ctl.submit(Request("play"))
    assert _run(ctl, 0.2) == []


def test_session_survives_a_view_that_fails():
    class Broken(Recorder):
        def render(self, frame):
            super().render(frame)
            if self.frames == 1:
                raise RuntimeError("boom")

    view = Broken()
    session = Session(Controller(Simulation("rotor")), view, fps=200)
    session.start()
    try:
        session.controller.submit(Request("set_value", "x", name="mass1_g"))
        import time

        time.sleep(0.3)
        assert session.running and view.frames > 5
        texts = [n.text for n in view.notices]
        assert any("boom" in t for t in texts) and any("needs a number" in t for t in texts)
    finally:
        session.stop()
    assert not session.running


def test_recording_from_the_web_session_replays_identically(tmp_path):
    from sandbox.recording import load
    from sandbox.replay import resimulate

    ctl = Controller(Simulation("rotor"), clock=Clock(), record_dir=tmp_path)
    ctl.submit(Request("record"))
    assert ctl.frame()[0].level == "info"
    _run(ctl, 0.5)
    ctl.submit(Request("set_value", 30, name="mass2_g"))
    _run(ctl, 0.5)
    ctl.submit(Request("stop_record"))
    notice = ctl.frame()[0]
    assert notice.level == "file"
    rec = load(notice.text)
    assert rec.complete and len(rec.times) >= 55  # ~60 frames per second of sim time
    assert len(rec.readouts) >= 9  # readouts at 10 Hz
    assert resimulate(rec)[0] == 0.0


def test_leaving_the_page_closes_the_recording(tmp_path):
    from sandbox.recording import load

    ctl = Controller(Simulation("rotor"), record_dir=tmp_path)
    session = Session(ctl, Recorder(), fps=100)
    session.start()
    ctl.submit(Request("record"))
    import time

    time.sleep(0.4)
    session.stop()  # what the app does when the browser disconnects
    (path,) = tmp_path.glob("*.sbx")
    assert load(path).complete


def test_a_recording_notes_the_lesson_and_its_steps(tmp_path):
    from sandbox.recording import load

    ctl = Controller(Simulation("rotor"), clock=Clock(), record_dir=tmp_path)
    ctl.lesson = "equilibrage"
    ctl.submit(Request("record"))
    ctl.frame()
    ctl.recorder.event("lesson", step=2)  # what the lesson panel does on "Suivant"
    _run(ctl, 0.2)
    ctl.submit(Request("stop_record"))
    rec = load(ctl.frame()[0].text)
    assert rec.header["lesson"] == "equilibrage"
    assert [e["step"] for e in rec.events if e["k"] == "lesson"] == [2]


class Wanting(Recorder):
    """A view that asks for a few readouts at every tick and keeps the frames."""

    def __init__(self, names):
        super().__init__()
        self.names = names
        self.seen = []

    def wants(self, now):
        return self.names

    def render(self, frame):
        super().render(frame)
        self.seen.append(frame)


def test_a_frame_computes_readouts_once_and_only_those_asked(tmp_path, monkeypatch):
    ctl = Controller(Simulation("rotor"), clock=Clock(), record_dir=tmp_path)
    view = Wanting({"bearing_A", "time"})
    session = Session(ctl, view)
    calls = []
    real = ctl.sim.readouts

    def counting(names=None):
        calls.append(None if names is None else tuple(sorted(names)))
        return real(names)

    monkeypatch.setattr(ctl.sim, "readouts", counting)
    ctl.clock.now += 1 / 60
    session.run_once()
    assert calls == [("bearing_A", "time")]
    frame = view.seen[-1]
    assert set(frame.readouts) == {"bearing_A", "time"} and frame.readouts["bearing_A"] > 1.0
    # recording: one computation of every readout serves the recorder and the view
    ctl.submit(Request("record"))
    ctl.clock.now += 1 / 60
    session.run_once()
    full = 0
    for _ in range(24):
        calls.clear()
        ctl.clock.now += 1 / 60
        session.run_once()
        assert len(calls) == 1, calls  # one computation a tick, whoever consumes it
        if calls == [None]:
            full += 1
            assert "T" in view.seen[-1].readouts  # the view got the recorder's full row
    assert full >= 3  # readouts recorded at 10 Hz of simulated time
    ctl.stop_recording()


def test_a_view_that_wants_nothing_costs_no_readout(monkeypatch):
    ctl = Controller(Simulation("rotor"), clock=Clock())
    view = Recorder()  # wants() -> None
    session = Session(ctl, view)
    monkeypatch.setattr(ctl.sim, "readouts", lambda names=None: pytest.fail("computed"))
    for _ in range(5):
        ctl.clock.now += 1 / 60
        session.run_once()
    assert view.frames == 5 and not view.notices


def test_one_scheduler_thread_serves_many_sessions():
    import threading
    import time

    sessions = [Session(Controller(Simulation("rotor")), Recorder(), fps=50) for _ in range(12)]
    before = threading.active_count()
    for s in sessions:
        s.start()
    try:
        time.sleep(0.5)
        assert threading.active_count() <= before + 1
        assert all(s.view.frames >= 5 for s in sessions), [s.view.frames for s in sessions]
    finally:
        for s in sessions:
            s.request_stop()
        for s in sessions:
            s.stop()
    assert not any(s.running for s in sessions)
