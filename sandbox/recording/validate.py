"""Checking the lines of a recording against its schema, before anything uses them.

The header and every record are checked against the format of
:mod:`sandbox.recording.format` (types, finite numbers, sizes, times in order, timesteps
within the model's bounds, nothing after the end) and the caps of
:mod:`sandbox.recording.limits`; a line that breaks them raises :class:`Refused`, which
the reader turns into one :class:`~sandbox.recording.format.BadRecording` line naming the
problem and the fix.
"""

from __future__ import annotations

import array
import json
import math
import re
from pathlib import Path
from typing import Any

from sandbox.errors import choices
from sandbox.physics.imposed import FREE, MOTIONS
from sandbox.physics.limits import MAX_MJCF_BYTES, MAX_TIMESTEP, MIN_TIMESTEP
from sandbox.physics.model import INTEGRATORS
from sandbox.recording import limits
from sandbox.recording.format import EVENT_KINDS, FIX, FORMAT, STATE_SPEC, VERSION, BadRecording

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")


class Refused(ValueError):
    """A line that breaks the schema (becomes a :class:`BadRecording` with its number)."""


def _refuse_constant(name: str) -> float:
    raise Refused(f"{name} is not a number a recording holds")


_DECODER = json.JSONDecoder(parse_constant=_refuse_constant)
_NUMBER_TYPES = frozenset({float, int, type(None)})


def _json(line: bytes) -> Any:
    try:
        return _DECODER.decode(line.decode("utf-8"))
    except UnicodeDecodeError:
        raise Refused("not UTF-8 text") from None
    except RecursionError:
        raise Refused("nested too deeply") from None
    except json.JSONDecodeError as exc:
        raise Refused(f"not JSON: {exc.msg} at column {exc.colno}") from None
    except ValueError as exc:  # an integer of more than 4300 digits
        raise Refused(f"not a usable number ({str(exc)[:60]})") from None


def _is_number(v: object) -> bool:
    return type(v) is float or type(v) is int


def _finite(value: object, what: str, *, low: float = -math.inf, high: float = math.inf) -> float:
    if not _is_number(value):
        raise Refused(f"{what} is {_short(value)}, not a number")
    try:
        number = float(value)  # type: ignore[arg-type]
    except OverflowError:
        raise Refused(f"{what} is too large") from None
    if not math.isfinite(number):
        raise Refused(f"{what} is not finite")
    if not low <= number <= high:
        raise Refused(f"{what} = {number!r} lies outside {low:g}..{high:g}")
    return number


def _text(
    value: object, what: str, *, none: bool = False, limit: int = limits.MAX_TEXT
) -> str | None:
    if value is None and none:
        return None
    if not isinstance(value, str):
        raise Refused(f"{what} is {_short(value)}, not a text")
    if len(value) > limit:
        raise Refused(f"{what} is {len(value)} characters long (at most {limit})")
    if limit <= limits.MAX_TEXT and not value.isprintable():
        raise Refused(f"{what} holds control characters")
    return value


def _name(value: object, what: str) -> str:
    if not isinstance(value, str) or not _NAME.fullmatch(value):
        raise Refused(f"{what} {_short(value)} is not a name (letters, digits, _)")
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
_OPTIONAL_KEYS = {"motion": FREE}
"""Header fields added after version 1 came out, and their value in a file without them."""


def check_header(path: Path, line: bytes) -> dict[str, Any]:
    """The validated header (only the keys of :data:`_HEADER_KEYS`)."""
    try:
        head = _json(line)
    except Refused as exc:
        if (
            f'"format": "{FORMAT}"'.encode() in line[:100]
            or f'"format":"{FORMAT}"'.encode() in line[:100]
        ):
            raise BadRecording(f"recording {str(path)!r} has a bad header ({exc}); {FIX}") from None
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
            f"sandbox writes and reads version {VERSION}); {FIX}"
        )
    missing = [k for k in _HEADER_KEYS if k not in head]
    if missing:
        raise BadRecording(
            f"recording {str(path)!r} has an incomplete header (missing "
            f"{', '.join(missing)}); {FIX}"
        )
    extra = sorted(set(head) - set(_HEADER_KEYS) - set(_OPTIONAL_KEYS))
    if extra:
        raise BadRecording(
            f"recording {str(path)!r} has unknown header fields {_short(extra)}; {FIX}"
        )
    try:
        _text(head["created"], "'created'")
        _text(head["target"], "'target'")
        _text(head["scene"], "'scene'", none=True)
        _text(head["lesson"], "'lesson'", none=True)
        _text(head["mjcf"], "'mjcf'", limit=MAX_MJCF_BYTES)
        values = head["values"]
        if not isinstance(values, dict) or len(values) > limits.MAX_VALUES:
            raise Refused(f"'values' is {_short(values)}, not a table of parameters")
        for key, value in values.items():
            _finite(value, f"parameter {_name(key, 'parameter')}")
        if not isinstance(head["integrator"], str) or head["integrator"] not in INTEGRATORS:
            raise Refused(
                f"'integrator' is {_short(head['integrator'])}, not one of {choices(INTEGRATORS)}"
            )
        _timestep(head["timestep"], "'timestep'")
        motion = head.get("motion", FREE)
        if not isinstance(motion, str) or motion not in MOTIONS:
            raise Refused(f"'motion' is {_short(motion)}, not one of {choices(MOTIONS)}")
        if head["state_spec"] != STATE_SPEC or type(head["state_spec"]) is not int:
            raise Refused(f"'state_spec' is {_short(head['state_spec'])}, not {STATE_SPEC}")
        size = head["state_size"]
        if type(size) is not int or not 0 < size <= limits.MAX_STATE_SIZE:
            raise Refused(f"'state_size' is {_short(size)}, not a count of numbers")
        names, units = head["readouts"], head["units"]
        if not isinstance(names, list) or len(names) > limits.MAX_READOUTS:
            raise Refused(f"'readouts' is {_short(names)}, not a list of names")
        for name in names:
            _name(name, "readout")
        if len(set(names)) != len(names):
            raise Refused("'readouts' names a readout twice")
        if not isinstance(units, list) or len(units) != len(names):
            raise Refused("'units' does not give one unit per readout")
        for unit in units:
            _text(unit, "unit", limit=32)
    except Refused as exc:
        raise BadRecording(f"recording {str(path)!r} has a bad header ({exc}); {FIX}") from None
    out = {k: head[k] for k in _HEADER_KEYS}
    out.update({k: head.get(k, default) for k, default in _OPTIONAL_KEYS.items()})
    return out


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
        "motion": ("value",),
        "end": ("frames",),
    }.items()
}
"""The fields of each record kind (:mod:`sandbox.recording.format`)."""


class RecordReader:
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
            raise Refused("a record after the end line")
        rec = _json(line)
        if not isinstance(rec, dict):
            raise Refused(f"{_short(rec)} is not a record")
        kind = rec.get("k")
        if not isinstance(kind, str) or kind not in _RECORD_KEYS:
            raise Refused(f"unknown record kind {_short(kind)}")
        extra = set(rec) - _RECORD_KEYS[kind]
        if extra:
            raise Refused(f"a {kind!r} record with unknown fields {_short(sorted(extra))}")
        t = _finite(rec.get("t"), "time 't'", low=-limits.MAX_TIME, high=limits.MAX_TIME)
        if t < self.last_t and kind != "reset":
            raise Refused(f"time goes back from {self.last_t!r} s to {t!r} s")
        self.last_t = t
        if kind == "frame":
            self._frame(rec, t)
        elif kind == "readouts":
            self._readouts(rec, t)
        elif kind == "end":
            frames = rec.get("frames")
            if type(frames) is not int or frames != len(self.times):
                raise Refused(f"the end line counts {_short(frames)} frames, not {len(self.times)}")
            self.end = frames
        elif kind in EVENT_KINDS:
            if len(self.events) >= limits.MAX_EVENTS:
                raise Refused(f"more than {limits.MAX_EVENTS} events")
            self.events.append(
                {**self._event(kind, rec), "k": kind, "t": t, "index": len(self.times)}
            )
        else:
            raise Refused(f"unknown record kind {_short(kind)}")

    def _frame(self, rec: dict[str, Any], t: float) -> None:
        s = rec.get("s")
        if type(s) is not list or len(s) != self.size or None in s:
            what = f"{len(s)} numbers" if type(s) is list else _short(s)
            raise Refused(f"the state 's' is {what}, not {self.size} numbers")
        if len(self.states) + self.size > limits.MAX_NUMBERS:
            raise Refused(f"more than {limits.MAX_NUMBERS} state and readout numbers")
        self._numbers(self.states, s, "the state 's'")
        self.times.append(t)

    def _readouts(self, rec: dict[str, Any], t: float) -> None:
        r = rec.get("r")
        if type(r) is not list or len(r) != len(self.names):
            what = f"{len(r)} values" if type(r) is list else _short(r)
            raise Refused(f"the readouts 'r' are {what}, not {len(self.names)}")
        if not self.times:
            raise Refused("readouts before the first frame")
        if len(self.states) + len(self.rows) + len(r) > limits.MAX_NUMBERS:
            raise Refused(f"more than {limits.MAX_NUMBERS} state and readout numbers")
        self._numbers(self.rows, r, "the readouts 'r'")
        self.rtimes.append(t)
        self.rframes.append(len(self.times) - 1)

    @staticmethod
    def _numbers(store: array.array[float], values: list[Any], what: str) -> None:
        """Append ``values`` (numbers; None for a readout that was not finite) to ``store``."""
        kinds = set(map(type, values))
        if not kinds <= _NUMBER_TYPES:
            if bool in kinds:
                raise Refused(f"{what} holds true/false, not numbers")
            raise Refused(f"{what} holds something else than numbers")
        if type(None) in kinds:
            values = [math.nan if v is None else v for v in values]
        n = len(store)
        try:
            store.extend(values)
        except OverflowError:
            del store[n:]
            raise Refused(f"{what} holds a number too large") from None
        if (
            not math.isfinite(sum(store[n:]))
            and any(  # sum: one C loop when all is well
                not math.isfinite(v) and v == v for v in store[n:]
            )
        ):
            del store[n:]
            raise Refused(f"{what} holds a number that is not finite")

    def _event(self, kind: str, rec: dict[str, Any]) -> dict[str, Any]:
        if kind == "set":
            name = rec.get("name")
            if not isinstance(name, str) or name not in self.params:
                raise Refused(f"'set' of {_short(name)}, a parameter the header does not list")
            return {"name": name, "value": _finite(rec.get("value"), f"the value of {name}")}
        if kind == "integrator":
            if not isinstance(rec.get("value"), str) or rec["value"] not in INTEGRATORS:
                raise Refused(f"integrator {_short(rec.get('value'))} is not one MuJoCo has")
            return {"value": rec["value"]}
        if kind == "timestep":
            return {"value": _timestep(rec.get("value"), "the timestep")}
        if kind == "motion":
            if not isinstance(rec.get("value"), str) or rec["value"] not in MOTIONS:
                raise Refused(f"motion {_short(rec.get('value'))} is neither imposed nor free")
            return {"value": rec["value"]}
        if kind == "lesson":
            step = rec.get("step")
            if type(step) is not int or not 0 <= step <= 10_000:
                raise Refused(f"lesson step {_short(step)} is not a step number")
            return {"step": step}
        return {}  # reset
