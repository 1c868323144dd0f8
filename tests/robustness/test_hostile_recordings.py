"""Hostile recordings: every crafted ``.sbx`` is refused in one line, never a traceback.

Recordings are files students exchange. Each case below is built inline from a real
recording (gzip of JSON lines) and is refused by :func:`sandbox.recording.load` or
:func:`sandbox.replay.open_simulation` with a :class:`BadRecording` naming the problem,
and by every ``sandbox replay`` mode with exit 2 and one ``sandbox: error:`` line. The
bombs (1 GB of zeros, 1 GB of newlines, a million records...) are gzip streams made of
one deflate block repeated (about 1 MB on disk) and run in a child process whose time
and peak memory are measured.
"""

from __future__ import annotations

import copy
import gzip
import json
import os
import struct
import time
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hostile import assert_refused, run_cli

from sandbox.cli import main
from sandbox.physics.simulation import Simulation
from sandbox.recording import (
    MAX_EVENTS,
    MAX_LINE_BYTES,
    MAX_RECORDS,
    MAX_TEXT_BYTES,
    BadRecording,
    Recorder,
    load,
)
from sandbox.replay import open_simulation, resimulate
from sandbox.scenes import get_scene

GIB = 2**30

Lines = list[dict[str, Any]]

PENDULUM = """<mujoco><option timestep="0.001"/><worldbody><body name="arm">
<joint type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 .3 0 0" size=".02"/>
</body></worldbody><keyframe><key qpos="0.5"/></keyframe></mujoco>"""
"""A 1 kg arm on a hinge started at 0.5 rad by its keyframe (an MJCF file's recording)."""


# -- building recordings ----------------------------------------------------------------
def _record(path: Path, sim: Simulation, frames: int = 12) -> Lines:
    rec = Recorder(path, sim)
    for k in range(frames):
        sim.step(5)
        rec.frame(sim.readouts() if k % 3 == 0 else None)
        if k == 4 and sim.scene is not None:
            sim.set_value("mass1_g", 10)
        if k == 8:
            sim.reset()
    rec.close()
    return [json.loads(line) for line in gzip.decompress(path.read_bytes()).splitlines()]


@pytest.fixture(scope="module")
def rotor(tmp_path_factory) -> Lines:
    """A valid rotor recording: header, frames, readouts, a 'set', a 'reset', the end."""
    return _record(tmp_path_factory.mktemp("rotor") / "r.sbx", Simulation(get_scene("rotor")))


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory) -> Lines:
    """A valid recording of an MJCF file (the model travels as MJCF text)."""
    folder = tmp_path_factory.mktemp("pendulum")
    (folder / "pendulum.xml").write_text(PENDULUM)
    return _record(folder / "p.sbx", Simulation(folder / "pendulum.xml"))


def _text(lines: list[Any]) -> bytes:
    """JSON lines; NaN stays the literal ``NaN``, an infinity is written ``1e999`` (a
    number JSON reads as inf)."""
    return "".join(
        (x if isinstance(x, str) else json.dumps(x).replace("Infinity", "1e999")) + "\n"
        for x in lines
    ).encode()


def _write(path: Path, payload: bytes) -> Path:
    path.write_bytes(payload)
    return path


def _bomb(prefix: bytes, block: bytes, copies: int, suffix: bytes = b"") -> bytes:
    """A valid gzip stream of ``prefix + block * copies + suffix``, about
    ``copies * len(block) / 1000`` bytes: the deflate block of ``block`` (after a full
    flush, which resets the window) is computed once and repeated."""
    c = zlib.compressobj(9, zlib.DEFLATED, 31)
    head = c.compress(prefix) + c.flush(zlib.Z_FULL_FLUSH)
    one = c.compress(block) + c.flush(zlib.Z_FULL_FLUSH)
    assert one == c.compress(block) + c.flush(zlib.Z_FULL_FLUSH)  # the block repeats
    tail = c.compress(suffix) + c.flush(zlib.Z_FINISH)
    crc = zlib.crc32(prefix)
    for _ in range(copies):
        crc = zlib.crc32(block, crc)
    crc = zlib.crc32(suffix, crc)
    size = (len(prefix) + len(block) * copies + len(suffix)) & 0xFFFFFFFF
    return head + one * copies + tail[:-8] + struct.pack("<II", crc, size)


def _edit(fn: Callable[[Lines], object]) -> Callable[[Lines], bytes]:
    def build(base: Lines) -> bytes:
        lines = copy.deepcopy(base)
        fn(lines)
        return gzip.compress(_text(lines))

    return build


def _header(**changes: object) -> Callable[[Lines], bytes]:
    def fn(lines: Lines) -> None:
        lines[0].update(changes)

    return _edit(fn)


def _drop(key: str) -> Callable[[Lines], bytes]:
    return _edit(lambda lines: lines[0].pop(key))


def _first(kind: str, **changes: object) -> Callable[[Lines], bytes]:
    """Change the first record of ``kind``."""

    def fn(lines: Lines) -> None:
        rec = next(r for r in lines[1:] if r["k"] == kind)
        rec.update(changes)

    return _edit(fn)


def _insert(record: object, at: int = 3) -> Callable[[Lines], bytes]:
    """Insert a line; a record with ``"t": None`` takes the time of the line before."""

    def build(base: Lines) -> bytes:
        lines: list[Any] = copy.deepcopy(base)
        if isinstance(record, dict) and record.get("t", 0) is None:
            lines.insert(at, {**record, "t": lines[at - 1]["t"]})
        else:
            lines.insert(at, record)
        return gzip.compress(_text(lines))

    return build


def _raw(fn: Callable[[Lines], bytes]) -> Callable[[Lines], bytes]:
    return fn


# (id, builder from the rotor lines, words the message must hold)
SCHEMA_CASES: list[tuple[str, Callable[[Lines], bytes], str]] = [
    ("version-0", _header(version=0), "invalid format version 0"),
    ("version-minus-1", _header(version=-1), "invalid format version -1"),
    ("version-string", _header(version="1"), "invalid format version '1'"),
    ("version-true", _header(version=True), "invalid format version True"),
    ("version-float", _header(version=1.0), "invalid format version 1.0"),
    ("version-2", _header(version=2), "version 2, newer than this sandbox reads"),
    ("no-state_size", _drop("state_size"), "missing state_size"),
    ("no-readouts", _drop("readouts"), "missing readouts"),
    ("no-integrator", _drop("integrator"), "missing integrator"),
    ("no-timestep", _drop("timestep"), "missing timestep"),
    ("no-values", _drop("values"), "missing values"),
    ("no-mjcf", _drop("mjcf"), "missing mjcf"),
    ("unknown-header-field", _header(extra=1), "unknown header fields ['extra']"),
    ("state_size-string", _header(state_size="18"), "'state_size' is '18'"),
    ("state_size-huge", _header(state_size=10**12), "'state_size' is 1000000000000"),
    ("header-timestep-tiny", _header(timestep=1e-300), "'timestep' = 1e-300 lies outside"),
    ("header-timestep-5e-324", _header(timestep=5e-324), "'timestep' = 5e-324 lies outside"),
    ("header-timestep-zero", _header(timestep=0), "'timestep' = 0.0 lies outside"),
    ("header-timestep-100", _header(timestep=100), "'timestep' = 100.0 lies outside"),
    ("header-timestep-nan", _header(timestep=float("nan")), "NaN is not a number"),
    ("header-timestep-string", _header(timestep="0.001"), "'timestep' is '0.001'"),
    ("integrator-unknown", _header(integrator="warp"), "'integrator' is 'warp'"),
    ("integrator-list", _header(integrator=["rk4"]), "'integrator' is ['rk4']"),
    ("target-5000-chars", _header(target="x" * 5000), "'target' is 5000 characters"),
    ("created-control-chars", _header(created="2026\x1b[2J"), "'created' holds control"),
    ("lesson-number", _header(lesson=3), "'lesson' is 3, not a text"),
    ("readout-markup", _header(readouts=["<script>alert(1)</script>"]), "is not a name"),
    ("units-mismatch", _header(units=["s"]), "one unit per readout"),
    ("value-string", _header(values={"mass1_g": "10"}), "parameter mass1_g is '10'"),
    ("value-inf", _header(values={"mass1_g": 1e999}), "parameter mass1_g is not finite"),
    ("header-a-list", _raw(lambda b: gzip.compress(b"[1, 2]\n")), "not a sandbox recording"),
    ("state-strings", _first("frame", s=["0.1"] * 21), "holds something else than numbers"),
    ("state-nested", _first("frame", s=[[0.1]] * 21), "holds something else than numbers"),
    ("state-bools", _first("frame", s=[True] * 21), "true/false"),
    ("state-null", _first("frame", s=[None] * 21), "not 21 numbers"),
    ("state-short", _first("frame", s=[0.0] * 20), "is 20 numbers, not 21"),
    ("state-a-dict", _first("frame", s={"a": 1}), "not 21 numbers"),
    ("state-inf", _first("frame", s=[1e999] * 21), "not finite"),
    ("state-4000-digits", _first("frame", s=[int("9" * 4000)] * 21), "number too large"),
    ("state-4400-digits", _raw(lambda b: _digits(b)), "not a usable number"),
    ("time-nan", _first("frame", t=float("nan")), "NaN is not a number"),
    ("time-string", _first("frame", t="0.1"), "time 't' is '0.1'"),
    ("time-huge", _first("frame", t=1e300), "lies outside"),
    ("time-goes-back", _insert({"k": "frame", "t": -1.0, "s": [0.0] * 21}), "time goes back"),
    ("motion-crafted", _header(motion="<b>x</b>"), "'motion' is '<b>x</b>', not one of"),
    ("event-motion-crafted", _insert({"k": "motion", "t": 1.0, "value": "fly"}), "neither imposed"),
    ("event-timestep-tiny", _insert({"k": "timestep", "t": 1.0, "value": 1e-9}), "lies outside"),
    ("event-timestep-string", _insert({"k": "timestep", "t": 1, "value": "1"}), "not a number"),
    ("event-set-unknown", _insert({"k": "set", "t": 1.0, "name": "x", "value": 1}), "'set' of"),
    ("event-set-list-name", _insert({"k": "set", "t": 1, "name": [], "value": 1}), "'set' of"),
    ("event-integrator", _insert({"k": "integrator", "t": 1.0, "value": {}}), "integrator {}"),
    ("event-lesson-step", _insert({"k": "lesson", "t": 1.0, "step": -1}), "lesson step -1"),
    ("unknown-kind", _insert({"k": "boom", "t": 1.0}), "unknown record kind 'boom'"),
    ("unknown-field", _insert({"k": "reset", "t": 0.0, "x": "y" * 100}), "unknown fields"),
    ("record-a-list", _insert([1, 2, 3]), "is not a record"),
    ("empty-line", _insert("", at=2), "not JSON"),
    ("not-utf8", _raw(lambda b: _bytes_line(b, b"\xff\xfe{}")), "not UTF-8"),
    ("nested-deep", _insert("[" * 100_000 + "]" * 100_000), "nested too deeply"),
    ("readouts-wrong-count", _first("readouts", r=[0.0]), "readouts 'r' are 1 values"),
    ("readouts-inf", _raw(lambda b: _readout_inf(b)), "not finite"),
    ("end-count-wrong", _edit(lambda lines: lines[-1].update(frames=999)), "counts 999"),
    ("after-end", _edit(lambda lines: lines.append(lines[-1])), "a record after the end"),
    ("trailing-garbage", _raw(lambda b: gzip.compress(_text(b)) + b"garbage"), "trailing"),
    ("two-gzip-members", _raw(lambda b: gzip.compress(_text(b)) * 2), "trailing garbage"),
    ("not-closed", _edit(lambda lines: lines.pop()), "truncated"),
]


def _digits(base: Lines) -> bytes:
    lines = [json.dumps(x) for x in base]
    frame = next(i for i, x in enumerate(base) if x.get("k") == "frame")
    lines[frame] = '{"k": "frame", "t": 0.0, "s": [' + "9" * 4400 + "]}"
    return gzip.compress(("\n".join(lines) + "\n").encode())


def _bytes_line(base: Lines, line: bytes) -> bytes:
    text = _text(base).split(b"\n")
    text.insert(2, line)
    return gzip.compress(b"\n".join(text))


def _readout_inf(base: Lines) -> bytes:
    lines = copy.deepcopy(base)
    rec = next(r for r in lines[1:] if r["k"] == "readouts")
    rec["r"][0] = 1e999
    return gzip.compress(_text(lines))


def _one_line(err: str) -> str:
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("sandbox: error: ")
    return lines[0]


@pytest.fixture
def no_server(monkeypatch):
    """A replay that got past its checks would open a server: make that fail loudly."""
    import sandbox.web.replay.export
    import sandbox.web.replay.player

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("a hostile recording reached the server")

    monkeypatch.setattr(sandbox.web.replay.player, "open_server", refuse)
    monkeypatch.setattr(sandbox.web.replay.export.viser, "ViserServer", refuse)


MODES = [[], ["--verify"], ["--csv", "OUT"], ["--export", "DIR"], ["--salvage", "--verify"]]


def _argv(path: Path, mode: list[str], tmp_path: Path) -> list[str]:
    swap = {"OUT": str(tmp_path / "out.csv"), "DIR": str(tmp_path / "export")}
    return ["replay", str(path), "--port", "0", *(swap.get(a, a) for a in mode)]


# -- schema: load() refuses, every CLI mode gives one line, exit 2 ----------------------
@pytest.mark.parametrize("name, build, needle", SCHEMA_CASES, ids=[c[0] for c in SCHEMA_CASES])
def test_load_refuses_a_crafted_recording(name, build, needle, rotor, tmp_path):
    path = _write(tmp_path / f"{name}.sbx", build(rotor))
    with pytest.raises(BadRecording) as info:
        load(path)
    message = str(info.value)
    assert needle in message and "\n" not in message and len(message) < 400
    assert ("newer" in message) == (name == "version-2")


@pytest.mark.parametrize("mode", MODES, ids=lambda m: " ".join(m) or "serve")
@pytest.mark.parametrize("name, build, needle", SCHEMA_CASES, ids=[c[0] for c in SCHEMA_CASES])
def test_cli_refuses_a_crafted_recording(
    name, build, needle, mode, rotor, tmp_path, capsys, no_server
):
    path = _write(tmp_path / f"{name}.sbx", build(rotor))
    if name == "not-closed" and "--salvage" in mode:
        pytest.skip("--salvage replays an unclosed recording: that is its purpose")
    assert main(_argv(path, mode, tmp_path)) == 2
    captured = capsys.readouterr()
    assert needle in _one_line(captured.err)
    assert not (tmp_path / "out.csv").exists() and not (tmp_path / "export").exists()


def test_the_valid_recordings_behind_the_cases_load(rotor, pendulum, tmp_path):
    """The cases differ from a valid file only by what they name (a reset goes back in
    time, the MJCF one replays)."""
    for name, lines in (("r", rotor), ("p", pendulum)):
        rec = load(_write(tmp_path / f"{name}.sbx", gzip.compress(_text(lines))))
        assert [e["k"] for e in rec.events if e["k"] == "reset"] == ["reset"]
        assert resimulate(rec)[0] == 0.0


# -- the model: schema-valid files that do not fit their model ---------------------------
def _pendulum_mjcf(mjcf: str) -> Callable[[Lines], bytes]:
    return _header(mjcf=mjcf)


MODEL_CASES: list[tuple[str, str, Callable[[Lines], bytes], str]] = [
    (
        "state-size-not-the-model",
        "rotor",
        _edit(
            lambda ls: (
                [ls[0].update(state_size=5)] + [r.update(s=[0.0] * 5) for r in ls if "s" in r]
            )
        ),
        "holds states of 5 numbers, but its model has 21",
    ),
    (
        "set-out-of-range",
        "rotor",
        _first("set", value=1e9),
        "cannot be replayed",
    ),
    (
        "header-value-out-of-range",
        "rotor",
        _edit(lambda ls: ls[0]["values"].update(speed_rpm=-1e9)),
        "cannot be replayed",
    ),
    (
        "mjcf-include-dev-zero",
        "pendulum",
        _pendulum_mjcf('<mujoco><include file="/dev/zero"/></mujoco>'),
        "reads the file '/dev/zero'",
    ),
    (
        "mjcf-mesh-file",
        "pendulum",
        _pendulum_mjcf(
            '<mujoco><asset><mesh name="m" file="/etc/passwd"/></asset><worldbody/></mujoco>'
        ),
        "reads the file '/etc/passwd'",
    ),
    (
        "mjcf-hfield-10GB",
        "pendulum",
        _pendulum_mjcf(
            '<mujoco><asset><hfield name="h" nrow="100000" ncol="100000" size="1 1 1 1"/>'
            "</asset><worldbody/></mujoco>"
        ),
        "cannot be replayed",
    ),
    (
        "mjcf-not-xml",
        "pendulum",
        _pendulum_mjcf("<mujoco><worldbody>"),
        "cannot be replayed (cannot load MJCF",
    ),
    (
        "mjcf-other-model",
        "pendulum",
        _pendulum_mjcf(
            "<mujoco><worldbody><body><freejoint/><geom size='1'/></body></worldbody></mujoco>"
        ),
        "but its model has",
    ),
]


@pytest.mark.parametrize("name, base, build, needle", MODEL_CASES, ids=[c[0] for c in MODEL_CASES])
def test_a_recording_that_does_not_fit_its_model_is_refused(
    name, base, build, needle, rotor, pendulum, tmp_path, capsys, no_server, monkeypatch
):
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    lines = rotor if base == "rotor" else pendulum
    path = _write(tmp_path / f"{name}.sbx", build(lines))
    rec = load(path)  # the schema holds
    with pytest.raises(BadRecording, match="^recording .*; ") as info:
        open_simulation(rec)
    assert needle in str(info.value)
    for mode in ([], ["--verify"], ["--export", "DIR"]):
        assert main(_argv(path, mode, tmp_path)) == 2
        assert needle in _one_line(capsys.readouterr().err)
    assert not list(tmp_path.glob("sandbox-replay-*"))


def test_a_recorded_mjcf_with_timestep_zero_replays_at_the_recorded_timestep(
    pendulum, tmp_path, monkeypatch
):
    """The header's timestep (checked) is the one used: the file's own is overridden."""
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    mjcf = PENDULUM.replace('timestep="0.001"', 'timestep="0"')
    path = _write(tmp_path / "z.sbx", _pendulum_mjcf(mjcf)(pendulum))
    rec = load(path)
    assert open_simulation(rec).timestep == rec.header["timestep"] == 0.001
    assert resimulate(rec)[0] == 0.0 and not list(tmp_path.glob("sandbox-replay-*"))


def test_verify_refuses_a_recording_that_asks_for_billions_of_steps(rotor, tmp_path, capsys):
    """A tiny file: two frames 10^5 s apart at 1 µs steps (10^11 steps, days of CPU)."""
    lines = copy.deepcopy(rotor)
    frames = [r for r in lines if r.get("k") == "frame"]
    for r in frames[1:]:
        r["t"] = 1e5
    step = {"k": "timestep", "t": frames[0]["t"], "value": 1e-6}
    lines = [lines[0], frames[0], step, *frames[1:]]
    lines.append({"k": "end", "t": 1e5, "frames": len(frames)})
    path = _write(tmp_path / "slow.sbx", gzip.compress(_text(lines)))
    start = time.perf_counter()
    assert main(["replay", str(path), "--verify"]) == 2
    assert time.perf_counter() - start < 5
    assert "takes 1e+11 steps, more than" in _one_line(capsys.readouterr().err)


# -- files that are not recordings at all -----------------------------------------------
def _fifo(tmp_path: Path) -> Path:
    os.mkfifo(tmp_path / "fifo.sbx")
    return tmp_path / "fifo.sbx"


def _symlink(tmp_path: Path) -> Path:
    (tmp_path / "link.sbx").symlink_to("/dev/zero")
    return tmp_path / "link.sbx"


def _sparse(tmp_path: Path) -> Path:
    """A 300 MiB file that takes no disk (a hole): refused by its size, unread."""
    with open(tmp_path / "big.sbx", "wb") as fh:
        fh.write(b"\x1f\x8b")
        fh.truncate(300 * 2**20)
    return tmp_path / "big.sbx"


SPECIAL_FILES: list[tuple[str, Callable[[Path], Path], str]] = [
    ("dev-zero", lambda tmp: Path("/dev/zero"), "is not a regular file"),
    ("dev-urandom", lambda tmp: Path("/dev/urandom"), "is not a regular file"),
    ("fifo", _fifo, "is not a regular file"),
    ("directory", lambda tmp: tmp, "is a directory"),
    ("missing", lambda tmp: tmp / "missing.sbx", "cannot read recording"),
    ("symlink-to-dev-zero", _symlink, "is not a regular file"),
    ("300MiB-sparse", _sparse, "is 300 MiB, more than the 256 MiB"),
    ("empty", lambda tmp: _write(tmp / "e.sbx", b""), "not a gzip stream"),
    ("empty-gzip", lambda tmp: _write(tmp / "e.sbx", gzip.compress(b"")), "empty or truncated"),
    ("csv-file", lambda tmp: _write(tmp / "x.csv", b"time,T\n0,1\n"), "not a gzip stream"),
]


@pytest.mark.parametrize("name, make, needle", SPECIAL_FILES, ids=[c[0] for c in SPECIAL_FILES])
def test_special_files_are_refused_at_once(name, make, needle, tmp_path, capsys, no_server):
    path = make(tmp_path)
    start = time.perf_counter()
    with pytest.raises(BadRecording, match=needle):
        load(path)
    for mode in MODES:
        assert main(_argv(path, mode, tmp_path)) == 2
        assert needle in _one_line(capsys.readouterr().err)
    assert time.perf_counter() - start < 2


# -- bombs, in a child process: time and peak memory measured ---------------------------
def _header_line(base: Lines) -> bytes:
    return (json.dumps(base[0]) + "\n").encode()


def _frame_line(base: Lines) -> bytes:
    frame = next(r for r in base if r.get("k") == "frame")
    return (json.dumps({"k": "frame", "t": 0.0, "s": [0] * len(frame["s"])}) + "\n").encode()


BOMBS: list[tuple[str, Callable[[Lines], bytes], str]] = [
    (
        "1GB-of-zeros",
        lambda b: _bomb(b"", b"\0" * 2**20, GIB // 2**20),
        f"its first line is longer than {MAX_LINE_BYTES // 2**20} MiB",
    ),
    (
        "1GB-of-newlines",
        lambda b: _bomb(b"", b"\n" * 2**20, GIB // 2**20),
        "not a sandbox recording",
    ),
    (
        "header-then-1GB-of-newlines",
        lambda b: _bomb(_header_line(b), b"\n" * 2**20, GIB // 2**20),
        "corrupted at line 2 (not JSON",
    ),
    (
        "header-then-1GB-of-zeros",
        lambda b: _bomb(_header_line(b), b"\0" * 2**20, GIB // 2**20),
        "its line 2 is longer than",
    ),
    (
        "header-then-1GB-of-resets",
        lambda b: _bomb(_header_line(b), b'{"k":"reset","t":0}\n' * 50_000, 1000),
        f"more than {MAX_EVENTS} events",
    ),
    (
        "header-then-4M-frames",
        lambda b: _bomb(_header_line(b), _frame_line(b) * 10_000, 400),
        f"more than {MAX_RECORDS} lines",
    ),
    (
        "header-then-1GB-of-long-frames",
        lambda b: _bomb(
            (json.dumps({**b[0], "state_size": 250_000}) + "\n").encode(),
            (
                '{"k":"frame","t":0,"s":['
                + ",".join(["1.00000000000000000000001"] * 250_000)
                + "]}\n"
            ).encode(),
            160,
        ),
        f"expands to more than {MAX_TEXT_BYTES // 2**20} MiB",
    ),
]


@pytest.mark.slow
@pytest.mark.parametrize("name, build, needle", BOMBS, ids=[c[0] for c in BOMBS])
def test_bombs_are_refused_within_20_s_and_1_gb(name, build, needle, rotor, tmp_path):
    path = _write(tmp_path / f"{name}.sbx", build(rotor))
    assert path.stat().st_size < 2**22  # a small file...
    for mode in (["--verify"], []):
        assert_refused(run_cli("replay", str(path), "--port", "0", *mode), needle)


@pytest.mark.parametrize(
    "name, make, needle", SPECIAL_FILES[:4], ids=[c[0] for c in SPECIAL_FILES[:4]]
)
def test_special_files_in_a_child_process(name, make, needle, tmp_path):
    assert_refused(run_cli("replay", str(make(tmp_path)), "--verify"), needle)
