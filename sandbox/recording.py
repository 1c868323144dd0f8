"""Recordings of a session: one self-contained, versioned, crash-tolerant file.

Format (version 1, documented in docs/reference.md): a gzip stream of JSON lines.

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

Recordings are files students exchange: :func:`load` treats them as untrusted. It reads
regular files only, inflates in bounded chunks under size, line and record caps, checks
the header and every record against the schema above (types, finite numbers, sizes,
times in order, timesteps within the model's bounds, nothing after the end), and names
the problem and the fix in one :class:`BadRecording` line.
"""

from __future__ import annotations

import array
import datetime as _dt
import functools
import gzip
import json
import math
import os
import re
import stat
import time
import zlib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

import mujoco
import numpy as np

from sandbox.errors import SandboxError, choices
from sandbox.physics.limits import MAX_MJCF_BYTES, MAX_TIMESTEP, MIN_TIMESTEP
from sandbox.physics.model import INTEGRATORS
from sandbox.runner import csv_cell, special_file

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


def create_unique(folder: str | Path, stem: str, *, suffix: str = ".sbx") -> Path:
    """Create an empty file ``folder/stem.sbx`` that no one else can have taken, and
    return its path; if the name exists, ``stem-2.sbx``, ``stem-3.sbx``... (the file is
    created with ``O_CREAT | O_EXCL``, so two browsers recording in the same second get
    two files). :class:`Recorder` then writes into it.

    Args:
        folder: An existing folder.
        stem: Name without suffix; characters other than letters, digits, ``_``, ``-``
            and ``.`` become ``_`` and it is cut to 100 characters.
        suffix: File suffix.

    Raises:
        BadRecording: the folder cannot be written (the message names it and the fix).
    """
    folder = Path(folder)
    clean = re.sub(r"[^A-Za-z0-9_.-]", "_", stem)[:100].strip(".") or "recording"
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)
    for n in range(1, 10_000):
        path = folder / (f"{clean}{suffix}" if n == 1 else f"{clean}-{n}{suffix}")
        try:
            os.close(os.open(path, flags, 0o644))
        except FileExistsError:
            continue
        except OSError as exc:
            raise BadRecording(
                f"cannot write a recording in {str(folder)!r} ({exc.strerror or exc}); "
                "choose a writable folder"
            ) from None
        return path
    raise BadRecording(
        f"{str(folder)!r} already holds 10000 recordings named {clean!r}; empty the folder"
    )


class Recorder:
    """Writes a recording of one simulation as it runs.

    Parameter, integrator and timestep changes and resets are captured by observing the
    simulation; frames and readouts are added by the caller at its own rate.

    Args:
        path: File to write (created or overwritten; :func:`create_unique` gives a name
            no other recording has).
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
        self.full = False
        """True once the file reached a reader's limit and was closed (see :meth:`fits`)."""
        self._bytes = self._records = self._numbers = self._events = 0
        self.stopped_at = math.nan  # simulated time at which a full file was closed
        self._clock = clock
        special = special_file(self.path)
        if special is not None:  # opening a named pipe would wait for a reader
            raise BadRecording(
                f"cannot write recording {str(self.path)!r}: it is {special}, not a file; "
                "choose a file name"
            )
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
        line = json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n"
        self._fh.write(line)
        self._bytes += len(line.encode("utf-8"))
        self._records += 1

    def fits(self, records: int = 2, numbers: int = 0, events: int = 0) -> bool:
        """Whether ``records`` more lines still leave the file readable: every limit that
        :func:`load` puts on an untrusted file (:data:`MAX_TEXT_BYTES`, :data:`MAX_RECORDS`,
        :data:`MAX_NUMBERS`, :data:`MAX_EVENTS`) keeps a 2 % margin (and room for the end
        line). A recorder that would pass one closes its file instead (:attr:`full`):
        what was recorded stays replayable."""
        margin = 0.98
        line = self._bytes / max(self._records, 1)
        return (
            self._bytes + (records + 1) * 2 * line <= margin * MAX_TEXT_BYTES
            and self._records + records + 1 <= margin * MAX_RECORDS
            and self._numbers + numbers <= margin * MAX_NUMBERS
            and self._events + events <= margin * MAX_EVENTS
        )

    def _close_full(self) -> None:
        self.full = True
        self.stopped_at = float(self.sim.data.time)
        self.close()

    def _observe(self, kind: str, fields: Mapping[str, Any]) -> None:
        if not self.closed:
            self.event(kind, **fields)

    def event(self, kind: str, **fields: Any) -> None:
        """Record an event at the current simulated time (``set``, ``lesson``...)."""
        if kind not in EVENT_KINDS:
            raise ValueError(f"unknown event {kind!r}; one of {EVENT_KINDS}")
        if self.closed:
            return
        if not self.fits(records=1, events=1):
            self._close_full()
            return
        self._write({"k": kind, "t": float(self.sim.data.time), **fields})
        self._events += 1
        self._maybe_flush()

    def frame(
        self,
        readouts: Mapping[str, float] | None = None,
        *,
        state: np.ndarray | None = None,
        time: float | None = None,
    ) -> None:
        """Record the current full state, and the readouts shown with it if given; or a
        state taken earlier (``state`` at simulated ``time``, of the same model: the last
        seconds a page kept, written after the fact)."""
        sim = self.sim
        if self.closed:
            return
        if state is None:
            state = get_state(sim.model, sim.data)
        numbers = len(state) + (len(self.names) if readouts is not None else 0)
        if not self.fits(records=2, numbers=numbers):
            self._close_full()
            return
        t = float(sim.data.time) if time is None else float(time)
        self._write({"k": "frame", "t": t, "s": [float(x) for x in state]})
        if readouts is not None:
            self._write({"k": "readouts", "t": t, "r": [_number(readouts[n]) for n in self.names]})
        self._numbers += numbers
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
        """Parameter values in force at frame ``index`` (the header's, changed by every
        ``set`` recorded before that frame): a binary search per parameter in the
        timeline :attr:`value_changes` built once, O(parameters x log events)."""
        values = {name: float(v) for name, v in self.header["values"].items()}
        for name, (frames, numbers) in self.value_changes.items():
            i = int(np.searchsorted(frames, index, side="right")) - 1
            if i >= 0:
                values[name] = float(numbers[i])
        return values

    @functools.cached_property
    def value_changes(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """For each parameter a recording changes: the frame index of each ``set`` event
        (frames recorded before it, non-decreasing) and the value it set, as two arrays
        built once from :attr:`events` (memory linear in the events)."""
        frames: dict[str, list[int]] = {}
        numbers: dict[str, list[float]] = {}
        for ev in self.events:
            if ev["k"] == "set":
                frames.setdefault(ev["name"], []).append(int(ev["index"]))
                numbers.setdefault(ev["name"], []).append(float(ev["value"]))
        return {
            name: (np.array(frames[name], dtype=np.int64), np.array(numbers[name], dtype=float))
            for name in frames
        }


MAX_FILE_BYTES = 256 * 2**20
"""Largest recording file read [bytes] (10 minutes of a web session take under 50 MB)."""

MAX_TEXT_BYTES = 256 * 2**20
"""Largest decompressed text [bytes]: a gzip bomb is refused when it passes this size."""

MAX_LINE_BYTES = 2 * MAX_MJCF_BYTES
"""Longest line [bytes]: the header holds the model's MJCF text (at most
:data:`~sandbox.physics.limits.MAX_MJCF_BYTES`), longer once escaped in JSON."""

MAX_RECORDS = 500_000
"""Most lines in a recording (about 2 hours of a web session: 60 frames and 10 readouts
a second)."""

MAX_NUMBERS = 2**25
"""Most state and readout numbers in all (256 MiB once read)."""

MAX_EVENTS = 100_000
"""Most parameter, integrator, timestep, reset and lesson records."""

MAX_STATE_SIZE = 1_000_000
"""Largest ``state_size`` in a header."""

MAX_READOUTS = 1_000
MAX_VALUES = 1_000
MAX_TEXT = 256
"""Longest name, unit, date or label in a header [characters]."""

MAX_TIME = 1e7
"""Largest simulated time in a recording [s] (about 4 months)."""

_CHUNK = 1 << 16
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")
_FIX = "the file was altered or damaged after it was written: use the original file"


class _Refused(ValueError):
    """A line that breaks the schema (becomes a :class:`BadRecording` with its number)."""


def _open(path: Path) -> BinaryIO:
    """Open a regular file for reading (never blocks on a FIFO, never reads a device)."""
    if path.is_dir():
        raise BadRecording(f"{str(path)!r} is a directory; give a recording file (.sbx)")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise BadRecording(
            f"cannot read recording {str(path)!r} ({exc.strerror or exc}); check the path"
        ) from None
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise BadRecording(f"{str(path)!r} is a directory; give a recording file (.sbx)")
        if not stat.S_ISREG(info.st_mode):
            raise BadRecording(
                f"{str(path)!r} is not a regular file (a device, pipe or socket); give a "
                "recording file (.sbx) written by 'sandbox run --record' or the web app"
            )
        if info.st_size > MAX_FILE_BYTES:
            raise BadRecording(
                f"recording {str(path)!r} is {info.st_size / 2**20:.0f} MiB, more than the "
                f"{MAX_FILE_BYTES // 2**20} MiB a recording may take; record shorter sessions"
            )
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


class _Lines:
    """Complete lines of a gzip stream (numbered from 1), read and inflated in bounded
    chunks. After iterating, :attr:`ended` tells whether the stream ended properly and
    its last line was complete (a partial last line is never yielded)."""

    def __init__(self, path: Path, fh: BinaryIO) -> None:
        self.path = path
        self.fh = fh
        self.ended = False

    def _refuse(self, problem: str, fix: str = _FIX) -> BadRecording:
        return BadRecording(f"recording {str(self.path)!r} {problem}; {fix}")

    def __iter__(self) -> Iterator[tuple[int, bytes]]:
        path, fh = self.path, self.fh
        head = fh.read(2)
        if head != b"\x1f\x8b":
            rest = (head + fh.read(38)).decode("utf-8", "replace").strip().splitlines()
            raise BadRecording(
                f"{str(path)!r} is not a sandbox recording (it starts with "
                f"{(rest[0] if rest else '')[:30]!r}, not a gzip stream); give a file written "
                "by 'sandbox run --record' or the web app's record button"
            )
        dec = zlib.decompressobj(wbits=31)
        pending: list[bytes] = []
        size = 0  # bytes in pending
        total = number = 0
        data = head
        while not dec.eof:
            if not data:
                data = fh.read(_CHUNK)
                if not data:
                    return  # the stream stops short: truncated
            try:
                out = dec.decompress(data, _CHUNK)  # at most _CHUNK bytes out at a time
            except zlib.error as exc:
                raise self._refuse(f"is corrupted ({exc})") from None
            data = dec.unconsumed_tail
            total += len(out)
            if total > MAX_TEXT_BYTES:
                raise self._refuse(
                    f"expands to more than {MAX_TEXT_BYTES // 2**20} MiB (a compression bomb, "
                    "or not a recording)",
                    "give a file written by 'sandbox run --record' or the web app",
                )
            parts = out.split(b"\n")
            pending.append(parts.pop())  # the start of a line yet to end
            size += len(pending[-1])
            if parts:  # pieces of a long line are joined once, when it ends
                parts[0] = b"".join([*pending[:-1], parts[0]])
                size = len(pending[-1])
                del pending[:-1]
            for line in parts:
                number += 1
                if len(line) > MAX_LINE_BYTES:
                    raise self._too_long(number)
                yield number, line
            if size > MAX_LINE_BYTES:
                raise self._too_long(number + 1)
        if dec.unused_data or data or fh.read(1):
            raise self._refuse("has data after the end of its gzip stream (trailing garbage)")
        self.ended = size == 0

    def _too_long(self, number: int) -> BadRecording:
        what = "its first line" if number == 1 else f"its line {number}"
        return self._refuse(
            f"is not usable: {what} is longer than {MAX_LINE_BYTES // 2**20} MiB (a "
            "compression bomb, or not a recording)",
            "give a file written by 'sandbox run --record' or the web app",
        )


def _refuse_constant(name: str) -> float:
    raise _Refused(f"{name} is not a number a recording holds")


_DECODER = json.JSONDecoder(parse_constant=_refuse_constant)
_NUMBER_TYPES = frozenset({float, int, type(None)})


def _json(line: bytes) -> Any:
    try:
        return _DECODER.decode(line.decode("utf-8"))
    except UnicodeDecodeError:
        raise _Refused("not UTF-8 text") from None
    except RecursionError:
        raise _Refused("nested too deeply") from None
    except json.JSONDecodeError as exc:
        raise _Refused(f"not JSON: {exc.msg} at column {exc.colno}") from None
    except ValueError as exc:  # an integer of more than 4300 digits
        raise _Refused(f"not a usable number ({str(exc)[:60]})") from None


def _is_number(v: object) -> bool:
    return type(v) is float or type(v) is int


def _finite(value: object, what: str, *, low: float = -math.inf, high: float = math.inf) -> float:
    if not _is_number(value):
        raise _Refused(f"{what} is {_short(value)}, not a number")
    try:
        number = float(value)  # type: ignore[arg-type]
    except OverflowError:
        raise _Refused(f"{what} is too large") from None
    if not math.isfinite(number):
        raise _Refused(f"{what} is not finite")
    if not low <= number <= high:
        raise _Refused(f"{what} = {number!r} lies outside {low:g}..{high:g}")
    return number


def _text(value: object, what: str, *, none: bool = False, limit: int = MAX_TEXT) -> str | None:
    if value is None and none:
        return None
    if not isinstance(value, str):
        raise _Refused(f"{what} is {_short(value)}, not a text")
    if len(value) > limit:
        raise _Refused(f"{what} is {len(value)} characters long (at most {limit})")
    if limit <= MAX_TEXT and not value.isprintable():
        raise _Refused(f"{what} holds control characters")
    return value


def _name(value: object, what: str) -> str:
    if not isinstance(value, str) or not _NAME.fullmatch(value):
        raise _Refused(f"{what} {_short(value)} is not a name (letters, digits, _)")
    return value


def _short(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _timestep(value: object, what: str) -> float:
    return _finite(value, what, low=MIN_TIMESTEP, high=MAX_TIMESTEP)


_HEADER_KEYS = (
    "format", "version", "created", "target", "scene", "mjcf", "values", "integrator",
    "timestep", "state_spec", "state_size", "readouts", "units", "lesson",
)  # fmt: skip


def _header(path: Path, line: bytes) -> dict[str, Any]:
    """The validated header (only the keys of :data:`_HEADER_KEYS`)."""
    try:
        head = _json(line)
    except _Refused as exc:
        if (
            f'"format": "{FORMAT}"'.encode() in line[:100]
            or f'"format":"{FORMAT}"'.encode() in line[:100]
        ):
            raise BadRecording(
                f"recording {str(path)!r} has a bad header ({exc}); {_FIX}"
            ) from None
        head = None
    if not isinstance(head, dict) or head.get("format") != FORMAT:
        raise BadRecording(
            f"{str(path)!r} is not a sandbox recording (no '{FORMAT}' header); give a file "
            "written by 'sandbox run --record' or the web app's record button"
        )
    version = head.get("version")
    if type(version) is int and version > VERSION:
        raise BadRecording(
            f"recording {str(path)!r} has format version {version}, newer than this sandbox "
            f"reads (version {VERSION}); upgrade sandbox (pip install -U .) to replay it"
        )
    if type(version) is not int or version != VERSION:
        raise BadRecording(
            f"recording {str(path)!r} has an invalid format version {_short(version)} (this "
            f"sandbox writes and reads version {VERSION}); {_FIX}"
        )
    missing = [k for k in _HEADER_KEYS if k not in head]
    if missing:
        raise BadRecording(
            f"recording {str(path)!r} has an incomplete header (missing "
            f"{', '.join(missing)}); {_FIX}"
        )
    extra = sorted(set(head) - set(_HEADER_KEYS))
    if extra:
        raise BadRecording(
            f"recording {str(path)!r} has unknown header fields {_short(extra)}; {_FIX}"
        )
    try:
        _text(head["created"], "'created'")
        _text(head["target"], "'target'")
        _text(head["scene"], "'scene'", none=True)
        _text(head["lesson"], "'lesson'", none=True)
        _text(head["mjcf"], "'mjcf'", limit=MAX_MJCF_BYTES)
        values = head["values"]
        if not isinstance(values, dict) or len(values) > MAX_VALUES:
            raise _Refused(f"'values' is {_short(values)}, not a table of parameters")
        for key, value in values.items():
            _finite(value, f"parameter {_name(key, 'parameter')}")
        if not isinstance(head["integrator"], str) or head["integrator"] not in INTEGRATORS:
            raise _Refused(
                f"'integrator' is {_short(head['integrator'])}, not one of {choices(INTEGRATORS)}"
            )
        _timestep(head["timestep"], "'timestep'")
        if head["state_spec"] != STATE_SPEC or type(head["state_spec"]) is not int:
            raise _Refused(f"'state_spec' is {_short(head['state_spec'])}, not {STATE_SPEC}")
        size = head["state_size"]
        if type(size) is not int or not 0 < size <= MAX_STATE_SIZE:
            raise _Refused(f"'state_size' is {_short(size)}, not a count of numbers")
        names, units = head["readouts"], head["units"]
        if not isinstance(names, list) or len(names) > MAX_READOUTS:
            raise _Refused(f"'readouts' is {_short(names)}, not a list of names")
        for name in names:
            _name(name, "readout")
        if len(set(names)) != len(names):
            raise _Refused("'readouts' names a readout twice")
        if not isinstance(units, list) or len(units) != len(names):
            raise _Refused("'units' does not give one unit per readout")
        for unit in units:
            _text(unit, "unit", limit=32)
    except _Refused as exc:
        raise BadRecording(f"recording {str(path)!r} has a bad header ({exc}); {_FIX}") from None
    return {k: head[k] for k in _HEADER_KEYS}


_RECORD_KEYS: dict[str, frozenset[str]] = {
    kind: frozenset({"k", "t", *fields})
    for kind, fields in {
        "frame": ("s",),
        "readouts": ("r",),
        "set": ("name", "value"),
        "integrator": ("value",),
        "timestep": ("value",),
        "reset": (),
        "lesson": ("step",),
        "end": ("frames",),
    }.items()
}
"""The fields of each record kind (module doc)."""


class _Reader:
    """Accumulates the validated records of one recording in compact arrays."""

    def __init__(self, header: dict[str, Any]) -> None:
        self.size: int = header["state_size"]
        self.names: list[str] = header["readouts"]
        self.params = set(header["values"])
        self.times = array.array("d")
        self.states = array.array("d")
        self.rtimes = array.array("d")
        self.rows = array.array("d")
        self.rframes = array.array("q")
        self.events: list[dict[str, Any]] = []
        self.last_t = -math.inf
        self.end: int | None = None

    def add(self, line: bytes) -> None:
        if self.end is not None:
            raise _Refused("a record after the end line")
        rec = _json(line)
        if not isinstance(rec, dict):
            raise _Refused(f"{_short(rec)} is not a record")
        kind = rec.get("k")
        if not isinstance(kind, str) or kind not in _RECORD_KEYS:
            raise _Refused(f"unknown record kind {_short(kind)}")
        extra = set(rec) - _RECORD_KEYS[kind]
        if extra:
            raise _Refused(f"a {kind!r} record with unknown fields {_short(sorted(extra))}")
        t = _finite(rec.get("t"), "time 't'", low=-MAX_TIME, high=MAX_TIME)
        if t < self.last_t and kind != "reset":
            raise _Refused(f"time goes back from {self.last_t!r} s to {t!r} s")
        self.last_t = t
        if kind == "frame":
            self._frame(rec, t)
        elif kind == "readouts":
            self._readouts(rec, t)
        elif kind == "end":
            frames = rec.get("frames")
            if type(frames) is not int or frames != len(self.times):
                raise _Refused(
                    f"the end line counts {_short(frames)} frames, not {len(self.times)}"
                )
            self.end = frames
        elif kind in EVENT_KINDS:
            if len(self.events) >= MAX_EVENTS:
                raise _Refused(f"more than {MAX_EVENTS} events")
            self.events.append(
                {**self._event(kind, rec), "k": kind, "t": t, "index": len(self.times)}
            )
        else:
            raise _Refused(f"unknown record kind {_short(kind)}")

    def _frame(self, rec: dict[str, Any], t: float) -> None:
        s = rec.get("s")
        if type(s) is not list or len(s) != self.size or None in s:
            what = f"{len(s)} numbers" if type(s) is list else _short(s)
            raise _Refused(f"the state 's' is {what}, not {self.size} numbers")
        if len(self.states) + self.size > MAX_NUMBERS:
            raise _Refused(f"more than {MAX_NUMBERS} state and readout numbers")
        self._numbers(self.states, s, "the state 's'")
        self.times.append(t)

    def _readouts(self, rec: dict[str, Any], t: float) -> None:
        r = rec.get("r")
        if type(r) is not list or len(r) != len(self.names):
            what = f"{len(r)} values" if type(r) is list else _short(r)
            raise _Refused(f"the readouts 'r' are {what}, not {len(self.names)}")
        if not self.times:
            raise _Refused("readouts before the first frame")
        if len(self.states) + len(self.rows) + len(r) > MAX_NUMBERS:
            raise _Refused(f"more than {MAX_NUMBERS} state and readout numbers")
        self._numbers(self.rows, r, "the readouts 'r'")
        self.rtimes.append(t)
        self.rframes.append(len(self.times) - 1)

    @staticmethod
    def _numbers(store: array.array[float], values: list[Any], what: str) -> None:
        """Append ``values`` (numbers; None for a readout that was not finite) to ``store``."""
        kinds = set(map(type, values))
        if not kinds <= _NUMBER_TYPES:
            if bool in kinds:
                raise _Refused(f"{what} holds true/false, not numbers")
            raise _Refused(f"{what} holds something else than numbers")
        if type(None) in kinds:
            values = [math.nan if v is None else v for v in values]
        n = len(store)
        try:
            store.extend(values)
        except OverflowError:
            del store[n:]
            raise _Refused(f"{what} holds a number too large") from None
        if (
            not math.isfinite(sum(store[n:]))
            and any(  # sum: one C loop when all is well
                not math.isfinite(v) and v == v for v in store[n:]
            )
        ):
            del store[n:]
            raise _Refused(f"{what} holds a number that is not finite")

    def _event(self, kind: str, rec: dict[str, Any]) -> dict[str, Any]:
        if kind == "set":
            name = rec.get("name")
            if not isinstance(name, str) or name not in self.params:
                raise _Refused(f"'set' of {_short(name)}, a parameter the header does not list")
            return {"name": name, "value": _finite(rec.get("value"), f"the value of {name}")}
        if kind == "integrator":
            if not isinstance(rec.get("value"), str) or rec["value"] not in INTEGRATORS:
                raise _Refused(f"integrator {_short(rec.get('value'))} is not one MuJoCo has")
            return {"value": rec["value"]}
        if kind == "timestep":
            return {"value": _timestep(rec.get("value"), "the timestep")}
        if kind == "lesson":
            step = rec.get("step")
            if type(step) is not int or not 0 <= step <= 10_000:
                raise _Refused(f"lesson step {_short(step)} is not a step number")
            return {"step": step}
        return {}  # reset


def load(path: str | Path, *, salvage: bool = False) -> Recording:
    """Read and check a recording.

    The file is read in bounded chunks and every record is checked against the format
    (module doc) before anything uses it; the limits (:data:`MAX_TEXT_BYTES`,
    :data:`MAX_LINE_BYTES`, :data:`MAX_RECORDS`, :data:`MAX_NUMBERS`...) keep a crafted
    file under a few hundred MB of memory and a few seconds.

    Args:
        path: The file.
        salvage: Accept a recording that was never closed (crash, power cut) and keep
            every complete line it holds.

    Raises:
        BadRecording: missing, not a regular file, foreign, corrupted, crafted (a bad
            value, a compression bomb), truncated (unless ``salvage``), or written by a
            newer format version; the message names the problem and the fix.
    """
    path = Path(path)
    header: dict[str, Any] | None = None
    reader: _Reader | None = None
    with _open(path) as fh:
        lines = _Lines(path, fh)
        for number, line in lines:
            if reader is None:
                header = _header(path, line)
                reader = _Reader(header)
                continue
            if number > MAX_RECORDS:
                raise BadRecording(
                    f"recording {str(path)!r} has more than {MAX_RECORDS} lines (the most a "
                    "recording holds); record shorter sessions"
                )
            try:
                reader.add(line)
            except _Refused as exc:
                raise BadRecording(
                    f"recording {str(path)!r} is corrupted at line {number} ({exc}); {_FIX}"
                ) from None
    if header is None or reader is None:
        raise BadRecording(f"recording {str(path)!r} is empty or truncated before its header")
    complete = lines.ended and reader.end is not None
    times = np.array(reader.times, dtype=float)
    if not complete and not salvage:
        last = f"t = {times[-1]:.3f} s" if len(times) else "no frame"
        raise BadRecording(
            f"recording {str(path)!r} is truncated (it was not closed; last complete frame "
            f"{last}); add --salvage to replay what it holds"
        )
    if not len(times):
        raise BadRecording(f"recording {str(path)!r} holds no frame; record for longer")
    names = reader.names
    return Recording(
        path=path,
        header=header,
        times=times,
        states=np.frombuffer(reader.states, dtype=float).reshape(len(times), reader.size),
        readout_times=np.array(reader.rtimes, dtype=float),
        readouts=np.array(reader.rows, dtype=float).reshape(len(reader.rtimes), len(names)),
        readout_frames=np.array(reader.rframes, dtype=int),
        events=reader.events,
        complete=complete,
    )


def write_csv(recording: Recording, out: str | Path, names: Sequence[str] | None = None) -> int:
    """Write the recorded readouts as CSV (header = names); returns the row count."""
    import csv

    cols = list(names or recording.names)
    idx = [recording.names.index(n) for n in cols]
    with Path(out).open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(cols)
        for row in recording.readouts:
            writer.writerow([csv_cell(float(row[i])) for i in idx])
    return len(recording.readouts)
