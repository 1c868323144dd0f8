"""Recordings: exact round trip, crash tolerance, clear errors, size."""

from __future__ import annotations

import gzip
import json

import numpy as np
import pytest

from sandbox.physics.simulation import Simulation
from sandbox.recording import FORMAT, VERSION, BadRecording, Recorder, get_state, load, write_csv


def _record(path, sim, frames=120, steps=10, change_at=None):
    rec = Recorder(path, sim)
    for k in range(frames):
        sim.step(steps)
        rec.frame(sim.readouts() if k % 6 == 0 else None)
        if k == change_at:
            sim.set_value("mass1_g", 25)
    rec.close()
    return rec


def test_round_trip_is_exact(tmp_path):
    sim = Simulation("rotor")
    path = tmp_path / "r.sbx"
    _record(path, sim, change_at=40)
    rec = load(path)
    assert rec.complete and rec.header["format"] == FORMAT and rec.header["version"] == VERSION
    assert rec.states.shape == (120, rec.header["state_size"])
    assert np.array_equal(rec.states[-1], get_state(sim.model, sim.data))  # bit for bit
    assert [e["k"] for e in rec.events] == ["set"] and rec.events[0]["index"] == 41
    assert rec.values_at(10)["mass1_g"] == 0.0 and rec.values_at(60)["mass1_g"] == 25.0
    assert rec.readouts.shape == (20, len(sim.readout_names()))
    assert rec.readouts_of_frame(len(rec.times) - 1)["time"] == rec.readout_times[-1]
    assert rec.readouts_of_frame(5)["time"] == rec.times[0]  # every 6th frame has readouts
    out = tmp_path / "r.csv"
    assert write_csv(rec, out) == 20
    assert out.read_text().splitlines()[0].split(",") == sim.readout_names()


def test_file_target_keeps_its_own_mjcf(tmp_path, pendulum_xml):
    sim = Simulation(pendulum_xml)
    _record(tmp_path / "p.sbx", sim, frames=10)
    rec = load(tmp_path / "p.sbx")
    assert rec.header["scene"] is None and rec.header["mjcf"] == pendulum_xml.read_text()


def test_a_crash_loses_at_most_the_last_flush(tmp_path, monkeypatch):
    """The recorder flushes at least every 5 s; a process that dies leaves a readable
    file (without end line) that --salvage replays."""
    clock = [0.0]
    sim = Simulation("rotor")
    path = tmp_path / "crash.sbx"
    rec = Recorder(path, sim, clock=lambda: clock[0])
    for _ in range(50):
        sim.step(10)
        rec.frame()
        clock[0] += 0.2  # 10 s of wall time in all: two flushes
    flushed = path.read_bytes()  # what a power cut would leave on disk
    crashed = tmp_path / "crashed.sbx"
    crashed.write_bytes(flushed)
    with pytest.raises(BadRecording, match="truncated.*--salvage"):
        load(crashed)
    partial = load(crashed, salvage=True)
    assert not partial.complete and len(partial.times) >= 50 - 5 / 0.2 - 1
    rec.close()


@pytest.mark.parametrize("cut", [10, 200, 2000])
def test_truncated_files_name_the_problem(tmp_path, cut):
    sim = Simulation("rotor")
    path = tmp_path / "r.sbx"
    _record(path, sim, frames=40)
    bad = tmp_path / "cut.sbx"
    bad.write_bytes(path.read_bytes()[:cut])
    with pytest.raises(BadRecording, match="truncated|empty"):
        load(bad)


def test_corrupted_foreign_and_newer_files(tmp_path):
    sim = Simulation("rotor")
    path = tmp_path / "r.sbx"
    _record(path, sim, frames=40)
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    (tmp_path / "flip.sbx").write_bytes(bytes(data))
    with pytest.raises(BadRecording, match="corrupted|truncated"):
        load(tmp_path / "flip.sbx")
    (tmp_path / "x.csv").write_text("time,T\n0,1\n")
    with pytest.raises(BadRecording, match="not a sandbox recording"):
        load(tmp_path / "x.csv")
    with gzip.open(tmp_path / "other.gz", "wt") as fh:
        fh.write(json.dumps({"format": "something-else"}) + "\n")
    with pytest.raises(BadRecording, match="not a sandbox recording"):
        load(tmp_path / "other.gz")
    lines = gzip.decompress(path.read_bytes()).decode().splitlines()
    head = json.loads(lines[0])
    head["version"] = VERSION + 1
    with gzip.open(tmp_path / "new.sbx", "wt") as fh:
        fh.write("\n".join([json.dumps(head), *lines[1:]]) + "\n")
    with pytest.raises(BadRecording, match=f"version {VERSION + 1}.*version {VERSION}"):
        load(tmp_path / "new.sbx")
    lines[5] = lines[5][:-3]
    with gzip.open(tmp_path / "badline.sbx", "wt") as fh:
        fh.write("\n".join(lines) + "\n")
    with pytest.raises(BadRecording, match="corrupted at line 6"):
        load(tmp_path / "badline.sbx")
    with pytest.raises(BadRecording, match="directory"):
        load(tmp_path)


def test_ten_minutes_at_60_hz_stay_under_50_mb(tmp_path):
    """Size of a 10-minute web recording (60 Hz states, 10 Hz readouts), extrapolated
    from 30 s of the rotor: the stream is written the same way throughout."""
    sim = Simulation("rotor")
    path = tmp_path / "long.sbx"
    rec = Recorder(path, sim)
    for k in range(30 * 60):
        sim.step(17)
        rec.frame(sim.readouts() if k % 6 == 0 else None)
    rec.close()
    per_minute = path.stat().st_size / 0.5
    print(f"recording size: {per_minute * 10 / 1e6:.1f} MB for 10 min")
    assert per_minute * 10 < 50e6
