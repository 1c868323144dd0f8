"""Writing a recording: a file no one else has taken, then one simulation as it runs.

The writer flushes the gzip stream (``Z_SYNC_FLUSH``) at least every
:data:`~sandbox.recording.format.FLUSH_EVERY` seconds, so a crash loses at most that
much; such a file lacks the end line and is replayed with ``--salvage``. It closes its
file before any limit of :mod:`sandbox.recording.limits`, so what was recorded stays
replayable.
"""

from __future__ import annotations

import datetime as _dt
import gzip
import json
import math
import os
import re
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from sandbox.recording import limits
from sandbox.recording.format import (
    EVENT_KINDS,
    FLUSH_EVERY,
    FORMAT,
    STATE_SPEC,
    VERSION,
    BadRecording,
    get_state,
)
from sandbox.runner import special_file


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
            "motion": sim.motion,
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
            self._bytes + (records + 1) * 2 * line <= margin * limits.MAX_TEXT_BYTES
            and self._records + records + 1 <= margin * limits.MAX_RECORDS
            and self._numbers + numbers <= margin * limits.MAX_NUMBERS
            and self._events + events <= margin * limits.MAX_EVENTS
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
