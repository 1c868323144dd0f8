"""Recordings: exact round trip, crash tolerance, clear errors, size."""

from __future__ import annotations

import gzip
import json
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from sandbox.physics.simulation import Simulation
from sandbox.recording import (
    FORMAT,
    VERSION,
    BadRecording,
    Recorder,
    create_unique,
    get_state,
    load,
    write_csv,
)
from sandbox.scenes import get_scene


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
    sim = Simulation(get_scene("rotor"))
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
    sim = Simulation(get_scene("rotor"))
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
    sim = Simulation(get_scene("rotor"))
    path = tmp_path / "r.sbx"
    _record(path, sim, frames=40)
    bad = tmp_path / "cut.sbx"
    bad.write_bytes(path.read_bytes()[:cut])
    with pytest.raises(BadRecording, match="truncated|empty"):
        load(bad)


def test_corrupted_foreign_and_newer_files(tmp_path):
    sim = Simulation(get_scene("rotor"))
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
    sim = Simulation(get_scene("rotor"))
    path = tmp_path / "long.sbx"
    rec = Recorder(path, sim)
    for k in range(30 * 60):
        sim.step(17)
        rec.frame(sim.readouts() if k % 6 == 0 else None)
    rec.close()
    per_minute = path.stat().st_size / 0.5
    print(f"recording size: {per_minute * 10 / 1e6:.1f} MB for 10 min")
    assert per_minute * 10 < 50e6


def test_create_unique_never_reuses_a_name(tmp_path):
    """Two browsers recording in the same second get two files (O_EXCL, then -2, -3)."""
    first = create_unique(tmp_path, "rotor-20261123-101500")
    second = create_unique(tmp_path, "rotor-20261123-101500")
    third = create_unique(tmp_path, "rotor-20261123-101500")
    assert [p.name for p in (first, second, third)] == [
        "rotor-20261123-101500.sbx",
        "rotor-20261123-101500-2.sbx",
        "rotor-20261123-101500-3.sbx",
    ]
    assert all(p.exists() and p.stat().st_size == 0 for p in (first, second, third))


def test_create_unique_from_many_threads_at_once(tmp_path):
    barrier = threading.Barrier(12)

    def reserve(_: int) -> str:
        barrier.wait()
        return create_unique(tmp_path, "same").name

    with ThreadPoolExecutor(12) as pool:
        names = list(pool.map(reserve, range(12)))
    assert len(set(names)) == 12 and sorted(p.name for p in tmp_path.iterdir()) == sorted(names)


def test_create_unique_keeps_the_name_in_its_folder(tmp_path):
    path = create_unique(tmp_path, "../../etc/x y<script>")
    assert path.parent == tmp_path and path.name == "_.._etc_x_y_script_.sbx"
    assert create_unique(tmp_path, "...").name == "recording.sbx"


def test_create_unique_then_record_two_sessions(tmp_path):
    paths = []
    for speed in (1000, 2000):
        sim = Simulation(get_scene("rotor"), values={"speed_rpm": speed})
        path = create_unique(tmp_path, "rotor-same-second")
        _record(path, sim, frames=5)
        paths.append(path)
    assert [load(p).header["values"]["speed_rpm"] for p in paths] == [1000, 2000]


def test_create_unique_in_a_missing_folder_is_one_clear_error(tmp_path):
    with pytest.raises(BadRecording, match=r"cannot write a recording in .*missing.*writable"):
        create_unique(tmp_path / "missing", "r")


def test_version_must_be_the_integer_1(tmp_path):
    sim = Simulation(get_scene("rotor"))
    path = tmp_path / "r.sbx"
    _record(path, sim, frames=5)
    lines = gzip.decompress(path.read_bytes()).decode().splitlines()
    for version, needle in [(0, "invalid format version 0"), ("1", "invalid format version '1'")]:
        head = json.loads(lines[0])
        head["version"] = version
        bad = tmp_path / "v.sbx"
        bad.write_bytes(gzip.compress(("\n".join([json.dumps(head), *lines[1:]]) + "\n").encode()))
        with pytest.raises(BadRecording, match=needle) as info:
            load(bad)
        assert "newer" not in str(info.value)


def test_a_reset_may_go_back_in_time_but_nothing_else(tmp_path):
    sim = Simulation(get_scene("rotor"))
    path = tmp_path / "r.sbx"
    rec = Recorder(path, sim)
    for k in range(6):
        sim.step(5)
        rec.frame()
        if k == 2:
            sim.reset()
    rec.close()
    loaded = load(path)
    assert list(loaded.times) == pytest.approx([0.05, 0.1, 0.15, 0.05, 0.1, 0.15])
    lines = gzip.decompress(path.read_bytes()).decode().splitlines()
    no_reset = [line for line in lines if '"reset"' not in line]
    (tmp_path / "b.sbx").write_bytes(gzip.compress(("\n".join(no_reset) + "\n").encode()))
    with pytest.raises(BadRecording, match=r"line 5 \(time goes back from 0\.15 s to 0\.05 s\)"):
        load(tmp_path / "b.sbx")


@pytest.mark.parametrize(
    "limit, value",
    [("MAX_RECORDS", 120), ("MAX_NUMBERS", 2_000), ("MAX_TEXT_BYTES", 60_000)],
)
def test_a_recording_that_reaches_a_reader_limit_is_closed_and_stays_replayable(
    tmp_path, monkeypatch, limit, value
):
    """The reader refuses files past its limits (untrusted input); the writer stops just
    before them, so what was recorded is never lost."""
    from sandbox import recording
    from sandbox.recording import limits

    monkeypatch.setattr(limits, limit, value)
    sim = Simulation(get_scene("rotor"))
    rec = recording.Recorder(tmp_path / "r.sbx", sim)
    for _ in range(400):
        sim.step(10)
        rec.frame(sim.readouts())
    assert rec.full and rec.closed and 10 < rec.frames < 400
    assert rec.stopped_at == pytest.approx(rec.frames * 10 * sim.timestep, abs=20 * sim.timestep)
    back = recording.load(tmp_path / "r.sbx")
    assert back.complete and len(back.times) == rec.frames


def test_a_flood_of_events_closes_the_recording_before_the_event_limit(tmp_path, monkeypatch):
    from sandbox import recording
    from sandbox.recording import limits

    monkeypatch.setattr(limits, "MAX_EVENTS", 50)
    sim = Simulation(get_scene("rotor"))
    rec = recording.Recorder(tmp_path / "r.sbx", sim)
    for i in range(100):
        sim.set_value("mass2_g", 10 + i % 5)
        rec.frame()
    assert rec.full
    back = recording.load(tmp_path / "r.sbx")
    assert back.complete and len(back.events) <= 50
