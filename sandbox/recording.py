"""Recordings of a session: one self-contained, versioned, crash-tolerant file.

Format (version 1, documented in README): a gzip stream of JSON lines.

- line 1, the header: ``{"format": "sandbox-recording", "version": 1, "created": ISO date,
  "target": scene name or file name, "scene": scene name or null, "mjcf": MJCF text of the
  model as first built, "values": parameters, "integrator", "timestep", "state_spec": the
  MuJoCo ``mjtState`` bits of the recorded states, "state_size", "readouts": [names],
  "units": [units], "lesson": lesson name or null}``;
- then one record per line, in time order, each with ``"k"`` (kind) and ``"t"`` (sim time):
  ``frame`` (``"s"``: full integration state, floats), ``readouts`` (``"r"``: values in
  header order, null for non-finite), ``set`` (``"name"``, ``"value"``), ``integrator``
  (``"value"``), ``timestep`` (``"value"``), ``reset``, ``lesson`` (``"step"``);
- last line ``{"k": "end", "t": ..., "frames": n}``.

Floats are written with ``repr`` so states round-trip exactly (``--verify`` expects 0).
The writer flushes the gzip stream (``Z_SYNC_FLUSH``) at least every :data:`FLUSH_EVERY`
seconds, so a crash loses at most that much; such a file lacks the end line and is
replayed with ``--salvage``.
"""

from __future__ import annotations

import datetime as _dt
import gzip
import json
import math
import time
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import SandboxError

FORMAT = "sandbox-recording"
VERSION = 1
FLUSH_EVERY = 5.0
"""Longest wall-clock time [s] between two flushes of a recording in progress."""

STATE_SPEC = int(mujoco.mjtState.mjSTATE_INTEGRATION)
"""Everything ``mj_step`` reads: a replay from it re-simulates bit for bit."""

EVENT_KINDS = ("set", "integrator", "timestep", "reset", "lesson")


class BadRecording(SandboxError):
    """The file is not a usable recording (truncated, corrupted, foreign, too new)."""


def get_state(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """The full integration state of ``data`` as a float array."""
    state = np.empty(mujoco.mj_stateSize(model, STATE_SPEC))
    mujoco.mj_getState(model, data, state, STATE_SPEC)
    return state


def set_state(model: mujoco.MjModel, data: mujoco.MjData, state: np.ndarray) -> None:
    """Restore a state taken by :func:`get_state` (then ``mj_forward`` for derived data)."""
    mujoco.mj_setState(model, data, np.asarray(state, dtype=float), STATE_SPEC)
    mujoco.mj_forward(model, data)


def _number(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


class Recorder:
    """Writes a recording of one simulation as it runs.

    Parameter, integrator and timestep changes and resets are captured by observing the
    simulation; frames and readouts are added by the caller at its own rate.

    Args:
        path: File to write (created or overwritten).
        sim: The simulation being recorded (a :class:`~sandbox.physics.simulation.Simulation`).
        lesson: Name of the lesson being followed, if any.
        clock: Wall clock used for the flush period.
    """

    def __init__(
        self,
        path: str | Path,
        sim: Any,
        *,
        lesson: str | None = None,
        clock: Any = time.monotonic,
    ) -> None:
        self.path = Path(path)
        self.sim = sim
        self.names = list(sim.readout_names())
        self.frames = 0
        self.closed = False
        self._clock = clock
        try:
            self._fh = gzip.open(self.path, "wt", encoding="utf-8", compresslevel=6)
        except OSError as exc:
            raise BadRecording(
                f"cannot write recording {str(self.path)!r} ({exc.strerror or exc}); "
                "choose a writable file"
            ) from None
        units = {r.name: r.unit for r in sim.readout_infos()}
        header = {
            "format": FORMAT,
            "version": VERSION,
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "target": sim.label,
            "scene": sim.scene.name if sim.scene is not None else None,
            "mjcf": sim.mjcf(),
            "values": dict(sim.values),
            "integrator": sim.integrator,
            "timestep": sim.timestep,
            "state_spec": STATE_SPEC,
            "state_size": int(mujoco.mj_stateSize(sim.model, STATE_SPEC)),
            "readouts": self.names,
            "units": [units[n] for n in self.names],
            "lesson": lesson,
        }
        self._write(header)
        self._last_flush = -math.inf
        self.flush()
        sim.observers.append(self._observe)

    def _write(self, record: Mapping[str, Any]) -> None:
        self._fh.write(json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n")

    def _observe(self, kind: str, fields: Mapping[str, Any]) -> None:
        if not self.closed:
            self.event(kind, **fields)

    def event(self, kind: str, **fields: Any) -> None:
        """Record an event at the current simulated time (``set``, ``lesson``...)."""
        if kind not in EVENT_KINDS:
            raise ValueError(f"unknown event {kind!r}; one of {EVENT_KINDS}")
        self._write({"k": kind, "t": float(self.sim.data.time), **fields})
        self._maybe_flush()

    def frame(self, readouts: Mapping[str, float] | None = None) -> None:
        """Record the current full state, and the readouts shown with it if given."""
        sim = self.sim
        state = get_state(sim.model, sim.data)
        t = float(sim.data.time)
        self._write({"k": "frame", "t": t, "s": [float(x) for x in state]})
        if readouts is not None:
            self._write({"k": "readouts", "t": t, "r": [_number(readouts[n]) for n in self.names]})
        self.frames += 1
        self._maybe_flush()

    def _maybe_flush(self) -> None:
        if self._clock() - self._last_flush >= FLUSH_EVERY:
            self.flush()

    def flush(self) -> None:
        """Push everything written so far to disk (readable if the process dies)."""
        self._fh.flush()  # gzip: Z_SYNC_FLUSH, then the file's own flush
        self._last_flush = self._clock()

    def close(self) -> None:
        """Write the end line and close the file (idempotent)."""
        if self.closed:
            return
        self.closed = True
        if self._observe in self.sim.observers:
            self.sim.observers.remove(self._observe)
        self._write({"k": "end", "t": float(self.sim.data.time), "frames": self.frames})
        self._fh.close()


@dataclass
class Recording:
    """A recording read back.

    Attributes:
        path: The file.
        header: The header line (see the module doc).
        times: Time of each frame [s].
        states: Full integration state of each frame (frames × state_size).
        readout_times: Time of each readouts record [s].
        readouts: Values (records × names), NaN for non-finite.
        readout_frames: Index of the frame each readouts record belongs to.
        events: Non-frame records in order, each with ``index``: the number of frames
            recorded before it.
        complete: False when the end line is missing (the recording was not closed).
    """

    path: Path
    header: dict[str, Any]
    times: np.ndarray
    states: np.ndarray
    readout_times: np.ndarray
    readouts: np.ndarray
    readout_frames: np.ndarray
    events: list[dict[str, Any]] = field(default_factory=list)
    complete: bool = True

    @property
    def timeline(self) -> np.ndarray:
        """Playback clock of each frame [s]: simulated time made monotonic (a reset
        goes back to t = 0; on the timeline it just continues)."""
        steps = np.diff(self.times)
        typical = float(np.median(steps[steps > 0])) if (steps > 0).any() else 0.0
        steps = np.where(steps > 0, steps, typical)
        return np.concatenate([[0.0], np.cumsum(steps)]) if len(self.times) else self.times

    def readouts_of_frame(self, index: int) -> dict[str, float]:
        """The readouts shown at frame ``index`` (last record at or before it)."""
        i = int(np.searchsorted(self.readout_frames, index, side="right")) - 1
        if i < 0:
            return {}
        return dict(zip(self.names, (float(v) for v in self.readouts[i]), strict=True))

    @property
    def names(self) -> list[str]:
        """Readout names, in column order."""
        return list(self.header["readouts"])

    @property
    def duration(self) -> float:
        """Simulated time covered [s]."""
        return float(self.times[-1] - self.times[0]) if len(self.times) else 0.0

    def values_at(self, index: int) -> dict[str, float]:
        """Parameter values in force at frame ``index``."""
        values = dict(self.header["values"])
        for ev in self.events:
            if ev["index"] > index:
                break
            if ev["k"] == "set":
                values[ev["name"]] = float(ev["value"])
        return values


def _decompress(path: Path, raw: bytes) -> tuple[bytes, bool]:
    """Decompressed bytes and whether the gzip stream ended properly."""
    if raw[:2] != b"\x1f\x8b":
        head = raw[:40].decode("utf-8", "replace").strip().splitlines()
        raise BadRecording(
            f"{str(path)!r} is not a sandbox recording (it starts with "
            f"{(head[0] if head else '')[:30]!r}, not a gzip stream); give a file written "
            "by 'sandbox run --record' or the web app's record button"
        )
    dec = zlib.decompressobj(wbits=31)
    try:
        out = dec.decompress(raw) + dec.flush()
    except zlib.error as exc:
        raise BadRecording(
            f"recording {str(path)!r} is corrupted ({exc}); the file was damaged after it "
            "was written: use another copy"
        ) from None
    return out, dec.eof


def load(path: str | Path, *, salvage: bool = False) -> Recording:
    """Read and check a recording.

    Args:
        path: The file.
        salvage: Accept a recording that was never closed (crash, power cut) and keep
            every complete line it holds.

    Raises:
        BadRecording: missing, foreign, corrupted, truncated (unless ``salvage``),
            or written by a newer format version; the message names the problem and the fix.
    """
    path = Path(path)
    if path.is_dir():
        raise BadRecording(f"{str(path)!r} is a directory; give a recording file")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise BadRecording(
            f"cannot read recording {str(path)!r} ({exc.strerror or exc}); check the path"
        ) from None
    text, ended = _decompress(path, raw)
    lines = text.decode("utf-8", "replace").split("\n")
    partial_tail = lines[-1] != ""
    lines = lines[:-1]
    if not lines:
        raise BadRecording(f"recording {str(path)!r} is empty or truncated before its header")
    try:
        header = json.loads(lines[0])
    except json.JSONDecodeError:
        header = None
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise BadRecording(
            f"{str(path)!r} is not a sandbox recording (no '{FORMAT}' header); give a file "
            "written by 'sandbox run --record' or the web app's record button"
        )
    version = header.get("version")
    if not isinstance(version, int) or version > VERSION:
        raise BadRecording(
            f"recording {str(path)!r} has format version {version}, newer than this sandbox "
            f"reads (version {VERSION}); upgrade sandbox (pip install -U .) to replay it"
        )
    size = int(header["state_size"])
    names = header["readouts"]
    times: list[float] = []
    states: list[list[float]] = []
    rtimes: list[float] = []
    rows: list[list[float]] = []
    rframes: list[int] = []
    events: list[dict[str, Any]] = []
    complete = False
    for number, line in enumerate(lines[1:], start=2):
        try:
            rec = json.loads(line)
            kind = rec["k"]
            t = float(rec["t"])
            if kind == "frame":
                if len(rec["s"]) != size:
                    raise ValueError("state size")
                states.append(rec["s"])
                times.append(t)
            elif kind == "readouts":
                if len(rec["r"]) != len(names):
                    raise ValueError("readout count")
                rows.append([math.nan if v is None else float(v) for v in rec["r"]])
                rtimes.append(t)
                rframes.append(len(times) - 1)
            elif kind == "end":
                complete = True
            elif kind in EVENT_KINDS:
                events.append({**rec, "index": len(times)})
            else:
                raise ValueError(f"kind {kind!r}")
        except (ValueError, KeyError, TypeError) as exc:
            raise BadRecording(
                f"recording {str(path)!r} is corrupted at line {number} ({exc}); use another copy"
            ) from None
    if not (complete and ended and not partial_tail) and not salvage:
        last = f"t = {times[-1]:.3f} s" if times else "no frame"
        raise BadRecording(
            f"recording {str(path)!r} is truncated (it was not closed; last complete frame "
            f"{last}); add --salvage to replay what it holds"
        )
    if not times:
        raise BadRecording(f"recording {str(path)!r} holds no frame; record for longer")
    return Recording(
        path=path,
        header=header,
        times=np.asarray(times, dtype=float),
        states=np.asarray(states, dtype=float),
        readout_times=np.asarray(rtimes, dtype=float),
        readouts=np.asarray(rows, dtype=float).reshape(len(rows), len(names)),
        readout_frames=np.asarray(rframes, dtype=int),
        events=events,
        complete=complete and ended and not partial_tail,
    )


def write_csv(recording: Recording, out: str | Path, names: Sequence[str] | None = None) -> int:
    """Write the recorded readouts as CSV (header = names); returns the row count."""
    import csv

    cols = list(names or recording.names)
    idx = [recording.names.index(n) for n in cols]
    with Path(out).open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(cols)
        for row in recording.readouts:
            writer.writerow(["" if math.isnan(row[i]) else f"{row[i]:.10g}" for i in idx])
    return len(recording.readouts)
