"""The seams of sandbox.web.loop made public by its split: the timestep refusal shared by
pacing and the checks, and the scheduler's view of a session."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.errors import BadOption
from sandbox.physics.simulation import Simulation
from sandbox.recording import load
from sandbox.web.loop import Controller, Scheduler, Session, check_timestep
from sandbox.web.loop.frame import Source
from sandbox.web.loop.requests import (
    Advance,
    Button,
    Challenge,
    Integrator,
    Motion,
    Pause,
    Play,
    Record,
    Request,
    Reset,
    Seek,
    SetValue,
    Speed,
    Steps,
    StopRecord,
    Timestep,
    Toggle,
    Unknown,
    command,
)
from sandbox.web.loop.scheduler import Turns
from sandbox.web.replay.player import ReplayController


def test_the_timestep_refusal_gives_the_range_in_french_and_english():
    """One check of a timestep, by the simulation: its refusal speaks English to the
    command line and, as ``french``, gives the page the range; the page's parse of a
    typed text refuses a word with the same range."""
    sim = Simulation("rotor")
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
    session = Session(Controller(Simulation("rotor")), Blank(), scheduler=scheduler)
    turns: Turns = session
    assert not turns.stopping
    session.request_stop()
    assert turns.stopping


@pytest.mark.parametrize(
    ("request_", "typed"),
    [
        (Request("play"), Play()),
        (Request("pause"), Pause()),
        (Request("toggle"), Toggle()),
        (Request("reset"), Reset()),
        (Request("step"), Steps(None)),
        (Request("step", 3), Steps(3)),
        (Request("advance", 0.02, name="s"), Advance(0.02, "s")),
        (Request("speed", "2"), Speed("2")),
        (Request("set_value", 40, name="mass1_g"), SetValue("mass1_g", 40)),
        (Request("integrator", "RK4"), Integrator("RK4")),
        (Request("timestep", 1e-4), Timestep(1e-4)),
        (Request("motion", "imposed"), Motion("imposed")),
        (Request("challenge", None), Challenge(None)),
        (Request("record"), Record()),
        (Request("stop_record"), StopRecord()),
        (Request("button", "Lancer"), Button("Lancer")),
        (Request("launch_missiles"), Unknown("launch_missiles")),
        (Request("seek", 1.0), Seek(1.0)),  # a replay's scrubber (the live loop refuses it)
        (Request(["not", "a", "kind"]), Unknown(["not", "a", "kind"])),  # type: ignore[arg-type]
    ],
)
def test_a_request_reads_as_its_typed_request(request_, typed):
    assert command(request_) == typed


def test_a_live_controller_and_a_replay_are_read_through_one_protocol(tmp_path):
    """A session asks the same of both sources (frame.Source): the live one draws
    between its physics steps and records; a replay draws its recorded frame, shows its
    recorded row, records nothing and has no secret."""
    ctl = Controller(Simulation("rotor"), record_dir=tmp_path)
    ctl.submit(Request("pause"))
    ctl.submit(Request("advance", 0.0011, name="s"))  # drawn between two physics steps
    ctl.submit(Request("record"))
    for _ in range(30):
        ctl.frame()
    ctl.submit(Request("stop_record"))
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
    ctl = Controller(Simulation("rotor"))
    assert not ctl.pending()
    ctl.submit(Request("pause"))
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
