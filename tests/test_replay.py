"""Replaying a recording: bit-for-bit re-simulation, CSV, static export, the player."""

from __future__ import annotations

import csv
import gzip
import hashlib
import json
import math
import tempfile

import numpy as np
import pytest
from conftest import wait_for

from sandbox.cli import main
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, load
from sandbox.replay import open_simulation, planned_steps, resimulate
from sandbox.scenes import get_scene
from sandbox.web.loop.requests import Pause, Play, Seek, Speed, Steps
from sandbox.web.replay.export import export_static
from sandbox.web.replay.player import ReplayController


@pytest.fixture
def recording(tmp_path):
    """Two seconds of the rotor with every kind of change a user can make."""
    sim = Simulation(get_scene("rotor"))
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
    ctl.submit(Seek(float(rec.timeline[60])))
    ctl.frame()
    assert ctl.index == 60
    assert np.array_equal(ctl.sim.data.qpos, rec.states[60][1 : 1 + ctl.sim.model.nq])
    assert ctl.sim.values["mass1_g"] == 40 and ctl.sim.values["speed_rpm"] == 2000
    shown = ctl.values()
    assert shown["bearing_A"] == rec.readouts[60][rec.names.index("bearing_A")]
    ctl.submit(Pause())
    ctl.submit(Steps(-1))
    ctl.frame()
    assert ctl.index == 59 and not ctl.playing
    ctl.submit(Seek(0.0))
    ctl.frame()
    assert ctl.sim.values["mass1_g"] == 0  # back before the change
    ctl.submit(Speed(4))
    ctl.submit(Play())
    ctl.frame()
    clock[0] += 10.0
    ctl.frame()
    assert ctl.index == len(rec.times) - 1 and not ctl.playing  # stops at the end
    ctl.submit(Speed("fast"))
    assert ctl.frame()[0].level == "error"


def test_static_export_speaks_french_beside_the_mechanism_and_shows_it_is_loading(
    recording, tmp_path
):
    """Issue 22: the export's overlay read "closure_error = 4.466e-07 m" (code names, a
    decimal point) over the mechanism, on a page blank for 6-15 s."""
    from sandbox.web.replay.export import LOADING_ID, overlay_text

    rec = load(recording)
    values = {"time": 1.25, "omega": 1500 * math.pi / 30, "bearing_A": 54.4175}
    words = {"omega": "ω", "bearing_A": "Palier A"}
    text = overlay_text(rec, values, ["omega", "bearing_A"], words, {"bearing_A": 1e-9})
    assert text.splitlines() == [
        "t = 1,25\u00a0s",
        "ω = 1\u202f500\u00a0tr/min",
        "Palier A = 54,42\u00a0N",
    ]
    html = export_static(rec, tmp_path / "export").read_text(encoding="utf-8")
    assert f"id='{LOADING_ID}'" in html and "Chargement de l'animation" in html
    assert html.index(LOADING_ID) < html.index("</body>") and "<title>Dynamique des solides" in html


@pytest.mark.browser
@pytest.mark.slow
def test_static_export_plays_without_python(recording, tmp_path, browser):
    index = export_static(load(recording), tmp_path / "export")
    assert (tmp_path / "export" / "readouts.csv").exists()
    page = browser.new_page(viewport={"width": 800, "height": 600})
    try:
        page.goto(index.as_uri())
        page.locator("canvas").first.wait_for(timeout=20_000)
        first = hashlib.md5(page.screenshot()).hexdigest()
        animates = wait_for(lambda: hashlib.md5(page.screenshot()).hexdigest() != first, 20)
    finally:
        page.close()
    assert animates, "the exported replay does not animate"


@pytest.fixture
def mjcf_recording(tmp_path, pendulum_xml, monkeypatch):
    """A recording of an MJCF file; the temporary folder is tmp_path/tmp (counted)."""
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    sim = Simulation(pendulum_xml)
    path = tmp_path / "p.sbx"
    rec = Recorder(path, sim)
    for _ in range(30):
        sim.step(10)
        rec.frame(sim.readouts())
    rec.close()
    return path


def _leftovers(tmp_path):
    return sorted(p.name for p in (tmp_path / "tmp").glob("sandbox-replay-*"))


def test_replaying_an_mjcf_recording_leaves_no_folder(mjcf_recording, tmp_path, capsys):
    rec = load(mjcf_recording)
    sim = open_simulation(rec)
    assert sim.label == "pendulum.xml" and _leftovers(tmp_path) == []
    assert resimulate(rec) == (0.0, 30) and _leftovers(tmp_path) == []
    ctl = ReplayController(rec)
    ctl.submit(Seek(float(rec.timeline[20])))
    ctl.frame()
    assert ctl.index == 20 and _leftovers(tmp_path) == []
    for _ in range(3):
        assert main(["replay", str(mjcf_recording), "--verify"]) == 0
    assert "maximum deviation 0" in capsys.readouterr().out
    assert _leftovers(tmp_path) == [] and list((tmp_path / "tmp").iterdir()) == []


def test_a_refused_mjcf_recording_leaves_no_folder(mjcf_recording, tmp_path, capsys):
    lines = gzip.decompress(mjcf_recording.read_bytes()).decode().splitlines()
    head = json.loads(lines[0])
    head["mjcf"] = "<mujoco><worldbody><body>"  # not XML MuJoCo reads
    bad = tmp_path / "bad.sbx"
    bad.write_bytes(gzip.compress(("\n".join([json.dumps(head), *lines[1:]]) + "\n").encode()))
    assert main(["replay", str(bad), "--verify"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sandbox: error: recording ") and "cannot load MJCF" in err
    assert len(err.splitlines()) == 1 and _leftovers(tmp_path) == []


def test_a_crafted_target_name_cannot_reach_the_label(mjcf_recording, tmp_path):
    lines = gzip.decompress(mjcf_recording.read_bytes()).decode().splitlines()
    head = json.loads(lines[0])
    head["target"] = "../../<img src=x onerror=alert(1)>.xml"
    path = tmp_path / "t.sbx"
    path.write_bytes(gzip.compress(("\n".join([json.dumps(head), *lines[1:]]) + "\n").encode()))
    sim = open_simulation(load(path))
    assert sim.label == "img_src_x_onerror_alert_1.xml" and _leftovers(tmp_path) == []


def test_planned_steps_count_what_the_recording_stepped(recording):
    """The fixture took 17 steps before each of its 120 frames, across a timestep change
    (1e-3 s -> 5e-4 s) and a reset: re-simulating from frame 0 takes 119 x 17 = 2023."""
    assert planned_steps(load(recording)) == pytest.approx(2023, abs=1e-6)
