"""The seams of sandbox.web.loop made public by its split: the timestep refusal shared by
pacing and the checks, and the scheduler's view of a session."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.errors import BadOption
from sandbox.physics.simulation import Simulation
from sandbox.recording import load
from sandbox.scenes import get_scene
from sandbox.web.loop import Controller, Scheduler, Session, check_timestep
from sandbox.web.loop.frame import Source
from sandbox.web.loop.requests import (
    WORDS,
    Advance,
    Button,
    Challenge,
    Integrator,
    Motion,
    Pause,
    Play,
    Record,
    Reset,
    Seek,
    SetValue,
    Speed,
    Steps,
    StopRecord,
    Timestep,
    Toggle,
    merged,
    words,
)
from sandbox.web.loop.scheduler import Turns
from sandbox.web.panels.controls import COMMAND_KINDS, command
from sandbox.web.replay.player import ReplayController


def test_the_timestep_refusal_gives_the_range_in_french_and_english():
    """One check of a timestep, by the simulation: its refusal speaks English to the
    command line and, as ``french``, gives the page the range; the page's parse of a
    typed text refuses a word with the same range."""
    sim = Simulation(get_scene("rotor"))
    with pytest.raises(BadOption) as err:
        sim.check_timestep(0.5)
    words = err.value.french
    assert words is not None
    assert words.startswith("Pas de temps dt = 0,5 s refusé : choisissez un pas entre 1×10⁻⁶ s")
    assert words.endswith(" s.") and "0,5" not in words.split("entre")[1]
    assert "timestep 0.5 s is too large" in str(err.value) and "--timestep" in str(err.value)
    assert 0 < sim.max_timestep < 0.5
    with pytest.raises(BadOption) as err:
        check_timestep(sim, 0.5)
    assert err.value.french == words
    with pytest.raises(BadOption) as err:
        check_timestep(sim, "abc")
    assert str(err.value.french).startswith("Pas de temps dt = abc s refusé")
    assert check_timestep(sim, "0.0005") == 0.0005


class Blank:
    draws = False

    def wants(self, now: float) -> None:
        return None

    def render(self, frame: object) -> None:
        pass

    def notify(self, notice: object) -> None:
        pass


def test_a_session_is_what_the_scheduler_runs_and_says_when_it_stops():
    scheduler = Scheduler(threaded=False)
    session = Session(Controller(Simulation(get_scene("rotor"))), Blank(), scheduler=scheduler)
    turns: Turns = session
    assert not turns.stopping
    session.request_stop()
    assert turns.stopping


def test_repeated_settings_merge_to_the_last_value_at_its_place():
    """Of several values of one slider (by name), of the speed, the timestep, the
    integrator, the motion or a replay's position, only the last is applied; actions are
    all kept, in order."""
    queued = [
        SetValue("speed_rpm", 100),
        Play(),
        SetValue("mass1_g", 40),
        Speed(2),
        SetValue("speed_rpm", 200),
        Steps(),
        Steps(),
        Speed(0.5),
        Integrator("RK4"),
        Timestep(1e-4),
        Motion("free"),
        Seek(1.0),
        Seek(2.0),
        Integrator("Euler"),
    ]
    assert merged(queued) == [
        Play(),
        SetValue("mass1_g", 40),
        SetValue("speed_rpm", 200),
        Steps(),
        Steps(),
        Speed(0.5),
        Timestep(1e-4),
        Motion("free"),
        Seek(2.0),
        Integrator("Euler"),
    ]


@pytest.mark.parametrize(
    ("label", "typed"),
    [
        ("Pause", Pause()),
        ("Lecture", Play()),
        ("Pas", Steps()),
        ("Réinitialiser", Reset()),
        ("launch_missiles", Button("launch_missiles")),
        (["not", "a", "label"], Button(["not", "a", "label"])),
    ],
)
def test_a_button_label_reads_as_its_command(label, typed):
    """A browser may send any label: an unknown one is a Button, which the loop refuses."""
    assert command(COMMAND_KINDS, label) == typed


def test_every_command_has_french_words_for_its_messages():
    kinds = [Play(), Pause(), Toggle(), Reset(), Steps(), Advance(1, "s"), Speed(1)]
    kinds += [Seek(0), SetValue("x", 1), Integrator("RK4"), Timestep(1e-3), Motion("free")]
    kinds += [Challenge(None), Record(), StopRecord(), Button("x")]
    assert len({type(k) for k in kinds}) == len(WORDS)
    assert all(words(k) and "_" not in words(k) for k in kinds)


def test_a_live_controller_and_a_replay_are_read_through_one_protocol(tmp_path):
    """A session asks the same of both sources (frame.Source): the live one draws
    between its physics steps and records; a replay draws its recorded frame, shows its
    recorded row, records nothing and has no secret."""
    ctl = Controller(Simulation(get_scene("rotor")), record_dir=tmp_path)
    ctl.submit(Pause())
    ctl.submit(Advance(0.0011, "s"))  # drawn between two physics steps
    ctl.submit(Record())
    for _ in range(30):
        ctl.frame()
    ctl.submit(StopRecord())
    path = next(n.text for n in ctl.frame() if n.level == "file")
    live: Source = ctl
    assert live.drawn(forces=True).data.time == pytest.approx(ctl.drawn_time)
    assert live.drawn_time != float(ctl.sim.data.time)  # between two physics steps

    replay: Source = ReplayController(load(path))
    names = ["omega", "T"]
    assert replay.drawn_time == float(replay.sim.data.time)
    assert replay.drawn(forces=True).data.time == replay.sim.data.time
    row = ReplayController(load(path)).values()
    assert replay.readouts(names) == replay.shown_readouts(names) == row
    assert not replay.readouts_due() and replay.secret is None and replay.step_cpu_total == 0
    replay.record()  # nothing happens
    assert replay.stop_recording() is None
    assert replay.frame(record=False) == []


def test_what_a_panel_may_do_goes_through_the_session_state():
    ctl = Controller(Simulation(get_scene("rotor")))
    assert not ctl.pending()
    ctl.submit(Pause())
    assert ctl.pending()  # queued for the loop, not applied by the panel
    closed: list[int] = []
    ctl.on_close(lambda: closed.append(1))
    assert len(ctl.cleanups) == 1
    web = Path(__file__).resolve().parents[2] / "sandbox" / "web"
    for path in [*sorted((web / "panels").glob("*.py")), web / "video" / "export.py"]:
        text = path.read_text()
        assert "Controller" not in text, f"{path.name} names the Controller: use SessionState"
        assert "physics.simulation import" not in text, (
            f"{path.name} types the simulation as mutable: use ReadOnlySimulation"
        )
