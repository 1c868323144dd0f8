"""The pieces of sandbox.recording that its modules share: opening, inflating, checking."""

from __future__ import annotations

import gzip
import json
import zlib

import pytest

from sandbox.physics.simulation import Simulation
from sandbox.recording import BadRecording, Recorder, limits
from sandbox.recording.format import FIX, FORMAT
from sandbox.recording.untrusted import GzipLines, open_regular
from sandbox.recording.validate import RecordReader, Refused, check_header
from sandbox.scenes import get_scene


def _header_line(tmp_path) -> bytes:
    """The header line of a short rotor recording, as written."""
    path = tmp_path / "r.sbx"
    sim = Simulation(get_scene("rotor"))
    rec = Recorder(path, sim)
    rec.close()
    return gzip.decompress(path.read_bytes()).splitlines()[0]


def test_open_regular_reads_a_file_and_refuses_a_directory(tmp_path):
    path = tmp_path / "f.bin"
    path.write_bytes(b"abc")
    with open_regular(path) as fh:
        assert fh.read() == b"abc"
    with pytest.raises(BadRecording, match="is a directory"):
        open_regular(tmp_path)
    with pytest.raises(BadRecording, match="cannot read recording .*check the path"):
        open_regular(tmp_path / "missing.sbx")


def test_gzip_lines_numbers_complete_lines_and_tells_a_stream_that_stops_short(tmp_path):
    path = tmp_path / "l.gz"
    path.write_bytes(gzip.compress(b"one\ntwo\n"))
    with open_regular(path) as fh:
        lines = GzipLines(path, fh)
        assert list(lines) == [(1, b"one"), (2, b"two")]
    assert lines.ended
    cut = tmp_path / "cut.gz"
    deflate = zlib.compressobj(wbits=31)
    cut.write_bytes(deflate.compress(b"one\ntw") + deflate.flush(zlib.Z_SYNC_FLUSH))
    with open_regular(cut) as fh:
        lines = GzipLines(cut, fh)
        assert list(lines) == [(1, b"one")]  # the partial last line is never yielded
    assert not lines.ended


def test_gzip_lines_refuses_what_is_not_gzip(tmp_path):
    path = tmp_path / "x.csv"
    path.write_text("time,T\n")
    with open_regular(path) as fh, pytest.raises(BadRecording, match="not a gzip stream"):
        list(GzipLines(path, fh))


def test_check_header_keeps_a_written_header_and_refuses_a_foreign_one(tmp_path):
    line = _header_line(tmp_path)
    header = check_header(tmp_path / "r.sbx", line)
    assert header["format"] == FORMAT and header["scene"] == "rotor"
    with pytest.raises(BadRecording, match="not a sandbox recording"):
        check_header(tmp_path / "r.sbx", b'{"format": "other"}')
    broken = json.loads(line)
    broken["state_size"] = -1
    with pytest.raises(BadRecording, match=f"bad header .*'state_size'.*; {FIX}"):
        check_header(tmp_path / "r.sbx", json.dumps(broken).encode())


def test_record_reader_collects_frames_and_refuses_a_bad_record(tmp_path):
    header = check_header(tmp_path / "r.sbx", _header_line(tmp_path))
    reader = RecordReader(header)
    state = [0.0] * header["state_size"]
    reader.add(json.dumps({"k": "frame", "t": 0.5, "s": state}).encode())
    reader.add(json.dumps({"k": "reset", "t": 0.0}).encode())
    assert list(reader.times) == [0.5] and reader.events[0]["index"] == 1
    with pytest.raises(Refused, match="time goes back"):
        reader.add(json.dumps({"k": "frame", "t": -1.0, "s": state}).encode())
    reader.add(json.dumps({"k": "end", "t": 0.0, "frames": 1}).encode())
    assert reader.end == 1
    with pytest.raises(Refused, match="after the end line"):
        reader.add(json.dumps({"k": "reset", "t": 0.0}).encode())
    assert issubclass(Refused, ValueError)


def test_limits_are_read_at_the_time_of_use(tmp_path, monkeypatch):
    """One patch of sandbox.recording.limits moves the writer's and the reader's cap."""
    monkeypatch.setattr(limits, "MAX_FILE_BYTES", 10)
    path = tmp_path / "big.bin"
    path.write_bytes(b"x" * 20)
    with pytest.raises(BadRecording, match="more than the 0 MiB a recording may take"):
        open_regular(path)
