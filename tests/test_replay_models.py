"""Replays in time linear in the recording, and the model a replay uses (issue 22 item 4).

Costs are asserted as counts (model compilations, event scans), not times.
"""

from __future__ import annotations

import gzip
import json

import numpy as np
import pytest

import sandbox.physics.simulation as simulation_module
from sandbox.cli import main
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, load
from sandbox.replay import open_replay, verify
from sandbox.scenes import get_scene
from sandbox.web.loop.requests import Seek
from sandbox.web.replay.player import ReplayController

FLOOD = 20_000


def _lines(path):
    return [json.loads(line) for line in gzip.decompress(path.read_bytes()).decode().splitlines()]


def _write(path, records):
    text = "\n".join(json.dumps(r, separators=(",", ":")) for r in records) + "\n"
    path.write_bytes(gzip.compress(text.encode()))
    return path


@pytest.fixture
def builds(monkeypatch):
    """Counts the models compiled (every rebuild of a simulation goes through build)."""
    calls = []
    real = simulation_module.build

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(simulation_module, "build", counting)
    return calls


def _rotor(path, *, frames=12, steps=10, changes=None):
    """The rotor recorded ``frames`` frames; ``changes[k] = [(name, value)...]`` set
    after frame k."""
    sim = Simulation(get_scene("rotor"))
    rec = Recorder(path, sim)
    for k in range(frames):
        sim.step(steps)
        rec.frame(sim.readouts())
        for name, value in (changes or {}).get(k, []):
            sim.set_value(name, value)
    rec.close()
    return path


# -- (b) verify: one rebuild per instant, none for a live parameter -----------------------
def test_a_flood_of_same_instant_sets_rebuilds_once_and_still_verifies_exactly(tmp_path, builds):
    """20,000 non-live sets at one instant, the last one being the value the session
    really set there: one rebuild, and the re-simulation is still bit for bit (before:
    20,000 rebuilds, 24 s)."""
    path = _rotor(tmp_path / "r.sbx", changes={5: [("mass1_g", 40)]})
    records = _lines(path)
    at = next(i for i, r in enumerate(records) if r.get("k") == "set")
    t = records[at]["t"]
    flood = [{"k": "set", "t": t, "name": "mass1_g", "value": 10.0 + k % 2} for k in range(FLOOD)]
    flooded = _write(tmp_path / "flood.sbx", records[:at] + flood + records[at:])
    assert path.stat().st_size < flooded.stat().st_size < 20_000  # a small file
    recording = load(flooded)
    assert sum(e["k"] == "set" for e in recording.events) == FLOOD + 1
    builds.clear()
    result = verify(recording)
    assert result.rebuilds == 1
    assert len(builds) == 2  # the scene at the first frame, then the one coalesced rebuild
    assert result.deviation == 0.0 and result.frames == 12


def test_a_flood_of_live_sets_at_distinct_instants_never_rebuilds(tmp_path, builds):
    """speed_rpm is live: 20,000 sets, one per timestep, take no compilation."""
    path = _rotor(tmp_path / "r.sbx", frames=3, steps=FLOOD + 10)
    records = _lines(path)
    head, first = records[0], records[1]
    dt, t0 = head["timestep"], first["t"]
    flood = [
        {"k": "set", "t": t0 + (k + 1) * dt, "name": "speed_rpm", "value": 1500.0}
        for k in range(FLOOD)
    ]
    at = next(i for i, r in enumerate(records[2:], 2) if r.get("k") == "frame")
    recording = load(_write(tmp_path / "live.sbx", records[:at] + flood + records[at:]))
    builds.clear()
    result = verify(recording)
    assert result.rebuilds == 0 and len(builds) == 1  # the scene at the first frame only
    assert result.deviation == 0.0


# -- (a) the player: values indexed once -------------------------------------------------
class _NoScan(list):
    def __iter__(self):
        raise AssertionError("values_at scanned the events")


def test_values_at_reads_the_index_not_the_events(tmp_path):
    records = _lines(_rotor(tmp_path / "r.sbx", frames=30))
    frames = [i for i, r in enumerate(records) if r.get("k") == "frame"]
    extra = []
    for k, (name, value) in enumerate([("mass1_g", 30.0), ("speed_rpm", 900.0), ("mass1_g", 7.0)]):
        extra.append((frames[5 + 7 * k] + 2, {"name": name, "value": value}))
    for at, fields in reversed(extra):
        records.insert(at, {"k": "set", "t": records[at - 2]["t"], **fields})
    rec = load(_write(tmp_path / "e.sbx", records))

    def naive(index):
        values = dict(rec.header["values"])
        for ev in rec.events:
            if ev["index"] <= index and ev["k"] == "set":
                values[ev["name"]] = ev["value"]
        return values

    expected = [naive(i) for i in range(len(rec.times))]
    assert expected[0] != expected[10] != expected[-1]
    assert rec.values_at(0) == expected[0]  # builds the index
    rec.events = _NoScan(rec.events)
    assert [rec.values_at(i) for i in range(len(rec.times))] == expected


def test_seeking_across_several_changes_rebuilds_once(tmp_path, builds):
    path = _rotor(
        tmp_path / "c.sbx",
        frames=40,
        changes={5: [("mass1_g", 30)], 10: [("speed_rpm", 2000)], 20: [("mass2_g", 15)]},
    )
    rec = load(path)
    ctl = ReplayController(rec)
    ctl.submit(Seek(float(rec.timeline[-1])))
    ctl.frame()
    assert ctl.sim.values["mass2_g"] == 15.0
    builds.clear()
    ctl.submit(Seek(0.0))
    ctl.frame()
    assert ctl.index == 0 and len(builds) == 1  # mass1_g and mass2_g: one rebuild
    assert ctl.sim.values == rec.header["values"]
    assert np.array_equal(ctl.sim.data.qpos, load(path).states[0][1 : 1 + ctl.sim.model.nq])


# -- (c) which model: the recording's own, or a warning ----------------------------------
def _tampered(tmp_path, mjcf):
    records = _lines(_rotor(tmp_path / "r.sbx"))
    records[0]["mjcf"] = mjcf(records[0]["mjcf"])
    return _write(tmp_path / "t.sbx", records)


def test_an_unchanged_scene_recording_verifies_against_the_scene_without_warning(tmp_path, capsys):
    path = _rotor(tmp_path / "r.sbx")
    assert main(["replay", str(path), "--verify"]) == 0
    out, err = capsys.readouterr()
    assert "with the scene 'rotor' as built today (the same MJCF as the recording's)" in out
    assert "maximum deviation 0" in out and "warning" not in err


def test_a_header_mjcf_with_ten_times_the_defect_mass_is_replayed_with_it(tmp_path, capsys):
    """Before: 'maximum deviation 0', no warning (the scene's model was used silently).
    The servo holds the speed, so the states barely move (1e-27), but they do."""
    path = _tampered(tmp_path, lambda m: m.replace('mass="0.02"', 'mass="0.2"'))
    result = verify(load(path))
    assert result.model.own and result.deviation > 0.0
    assert main(["replay", str(path), "--verify"]) == 0
    out, err = capsys.readouterr()
    [warning] = [line for line in err.splitlines() if "differs from the scene" in line]
    assert "the recording's model differs from the scene 'rotor' built today" in warning
    assert "MJCF line " in warning and 'name="defect"' in warning
    assert 'mass="0.2"/>\' in the recording' in warning and 'mass="0.02"/>\' today' in warning
    assert "replayed with the recording's own model" in warning
    assert "with the recording's own MJCF" in out and "maximum deviation 0\n" not in out


def test_an_empty_header_mjcf_is_named_and_the_scene_is_used(tmp_path, capsys):
    """The empty model cannot hold the recorded states: the scene's model replays it, and
    the output says so instead of a silent 'maximum deviation 0'."""
    path = _tampered(tmp_path, lambda m: "<mujoco><worldbody/></mujoco>")
    sim, choice = open_replay(load(path))
    assert not choice.own and sim.model.nbody > 1
    assert main(["replay", str(path), "--verify"]) == 0
    out, err = capsys.readouterr()
    [warning] = [line for line in err.splitlines() if "differs from the scene" in line]
    assert "MJCF line 1: '<mujoco><worldbody/></mujoco>' in the recording" in warning
    assert "replayed with the scene's model: the recording's own model" in warning
    assert "with the scene 'rotor' as built today (not the recording's MJCF)" in out


def test_the_recorded_mjcf_with_the_scene_behaviour_follows_the_recording(tmp_path):
    """The header's MJCF, compiled with the scene's drive and disabled effects, follows
    the recording up to MuJoCo's 6-digit MJCF output (as a plain file it deviates by
    0.06: the effects are not in the MJCF)."""
    path = _tampered(tmp_path, lambda m: m + "<!-- the same model -->\n")
    result = verify(load(path))
    assert result.model.own and result.model.warning is not None
    assert 0.0 <= result.deviation < 1e-12


def test_a_recording_that_rebuilds_keeps_the_scene_and_says_why(tmp_path):
    records = _lines(_rotor(tmp_path / "r.sbx", changes={3: [("mass1_g", 9)]}))
    records[0]["mjcf"] += "<!-- edited -->"
    _, choice = open_replay(load(_write(tmp_path / "t.sbx", records)))
    assert not choice.own
    assert "cannot follow the recorded change of 'mass1_g'" in (choice.warning or "")
