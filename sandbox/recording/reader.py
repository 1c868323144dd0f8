"""Loading a recording for replay: the checked file read back as arrays, and its CSV.

Recordings are files students exchange: :func:`load` treats them as untrusted. It reads
regular files only, inflates in bounded chunks under size, line and record caps, checks
the header and every record against the schema (types, finite numbers, sizes, times in
order, timesteps within the model's bounds, nothing after the end), and names the
problem and the fix in one :class:`~sandbox.recording.format.BadRecording` line.
"""

from __future__ import annotations

import csv
import functools
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sandbox.recording import limits
from sandbox.recording.format import FIX, BadRecording
from sandbox.recording.untrusted import GzipLines, open_regular
from sandbox.recording.validate import RecordReader, Refused, check_header
from sandbox.runner import csv_cell


@dataclass
class Recording:
    """A recording read back.

    Attributes:
        path: The file.
        header: The header line (see :mod:`sandbox.recording.format`).
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

    def motion_at(self, index: int) -> str:
        """How the motion was computed at frame ``index`` ("imposed" or "free"): the
        header's, changed by every ``motion`` event recorded before that frame."""
        motion = str(self.header.get("motion", "free"))
        for ev in self.events:
            if ev["index"] > index:
                break
            if ev["k"] == "motion":
                motion = str(ev["value"])
        return motion

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


def load(path: str | Path, *, salvage: bool = False) -> Recording:
    """Read and check a recording.

    The file is read in bounded chunks and every record is checked against the format
    (:mod:`sandbox.recording.format`) before anything uses it; the limits
    (:data:`MAX_TEXT_BYTES`, :data:`MAX_LINE_BYTES`, :data:`MAX_RECORDS`,
    :data:`MAX_NUMBERS`...) keep a crafted file under a few hundred MB of memory and a
    few seconds.

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
    reader: RecordReader | None = None
    with open_regular(path) as fh:
        lines = GzipLines(path, fh)
        for number, line in lines:
            if reader is None:
                header = check_header(path, line)
                reader = RecordReader(header)
                continue
            if number > limits.MAX_RECORDS:
                raise BadRecording(
                    f"recording {str(path)!r} has more than {limits.MAX_RECORDS} lines (the most a "
                    "recording holds); record shorter sessions"
                )
            try:
                reader.add(line)
            except Refused as exc:
                raise BadRecording(
                    f"recording {str(path)!r} is corrupted at line {number} ({exc}); {FIX}"
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
    cols = list(names or recording.names)
    idx = [recording.names.index(n) for n in cols]
    with Path(out).open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(cols)
        for row in recording.readouts:
            writer.writerow([csv_cell(float(row[i])) for i in idx])
    return len(recording.readouts)
