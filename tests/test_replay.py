"""Replaying a recording: bit-for-bit re-simulation, CSV, static export, the player."""

from __future__ import annotations

import csv
import hashlib
import time

import numpy as np
import pytest

from sandbox.cli import main
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, load
from sandbox.replay import resimulate
from sandbox.web.export import export_static
from sandbox.web.player import ReplayController
from sandbox.web.session import Request


@pytest.fixture
def recording(tmp_path):
    """Two seconds of the rotor with every kind of change a user can make."""
    sim = Simulation("rotor")
    path = tmp_path / "lesson.sbx"
    rec = Recorder(path, sim)
    changes = {
        20: lambda: sim.set_value("mass1_g", 40),
        40: lambda: sim.set_value("speed_rpm", 2000),
        60: lambda: sim.set_integrator("implicitfast"),
        80: lambda: sim.set_timestep(5e-4),
        100: sim.reset,
    }
    for k in range(120):
        sim.step(17)
        rec.frame(sim.readouts())
        if k in changes:
            changes[k]()
    rec.close()
    return path


def test_verify_reproduces_the_run_exactly(recording):
    worst, frames = resimulate(load(recording))
    assert frames == 120 and worst == 0.0


def test_verify_detects_a_tampered_state(recording, tmp_path):
    rec = load(recording)
    rec.states[50, 0] += 1e-6
    worst, _ = resimulate(rec)
    assert worst == pytest.approx(1e-6, rel=1e-3)


def test_cli_replay_verify_and_csv(recording, tmp_path, capsys):
    out = tmp_path / "students.csv"
    assert main(["replay", str(recording), "--verify", "--csv", str(out)]) == 0
    text = capsys.readouterr().out
    assert "maximum deviation 0" in text
    rows = list(csv.DictReader(out.open()))
    rec = load(recording)
    assert len(rows) == 120
    assert float(rows[30]["bearing_A"]) == pytest.approx(
        rec.readouts[30][rec.names.index("bearing_A")]
    )


def test_cli_run_record_then_replay_gives_identical_readouts(tmp_path, capsys):
    rec_path, csv_live, csv_replay = tmp_path / "r.sbx", tmp_path / "a.csv", tmp_path / "b.csv"
    assert (
        main(
            [
                "run",
                "rotor",
                "--duration",
                "0.5",
                "--record",
                str(rec_path),
                "--out",
                str(csv_live),
                "--set",
                "mass2_g=15",
            ]
        )
        == 0
    )
    assert main(["replay", str(rec_path), "--csv", str(csv_replay)]) == 0
    assert csv_live.read_text() == csv_replay.read_text()


@pytest.mark.parametrize(
    "args, needle",
    [
        (["replay", "missing.sbx"], "cannot read recording"),
        (["replay", "."], "directory"),
        (["run", "rotor", "--record", "/nonexistent/dir/r.sbx"], "does not exist"),
    ],
)
def test_cli_bad_input_is_one_line_exit_2(args, needle, capsys):
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err


def test_player_seeks_steps_and_shows_recorded_readouts(recording):
    rec = load(recording)
    clock = [0.0]
    ctl = ReplayController(rec, clock=lambda: clock[0])
    ctl.submit(Request("seek", float(rec.timeline[60])))
    ctl.frame()
    assert ctl.index == 60
    assert np.array_equal(ctl.sim.data.qpos, rec.states[60][1 : 1 + ctl.sim.model.nq])
    assert ctl.sim.values["mass1_g"] == 40 and ctl.sim.values["speed_rpm"] == 2000
    shown = ctl.values()
    assert shown["bearing_A"] == rec.readouts[60][rec.names.index("bearing_A")]
    ctl.submit(Request("pause"))
    ctl.submit(Request("step", -1))
    ctl.frame()
    assert ctl.index == 59 and not ctl.playing
    ctl.submit(Request("seek", 0.0))
    ctl.frame()
    assert ctl.sim.values["mass1_g"] == 0  # back before the change
    ctl.submit(Request("speed", 4))
    ctl.submit(Request("play"))
    ctl.frame()
    clock[0] += 10.0
    ctl.frame()
    assert ctl.index == len(rec.times) - 1 and not ctl.playing  # stops at the end
    ctl.submit(Request("speed", "fast"))
    assert ctl.frame()[0].level == "error"


@pytest.mark.browser
def test_static_export_plays_without_python(recording, tmp_path, browser):
    index = export_static(load(recording), tmp_path / "export")
    assert (tmp_path / "export" / "readouts.csv").exists()
    page = browser.new_page(viewport={"width": 800, "height": 600})
    try:
        page.goto(index.as_uri())
        page.locator("canvas").first.wait_for(timeout=20_000)
        time.sleep(1.5)
        first = hashlib.md5(page.screenshot()).hexdigest()
        time.sleep(1.0)
        second = hashlib.md5(page.screenshot()).hexdigest()
    finally:
        page.close()
    assert first != second, "the exported replay does not animate"
