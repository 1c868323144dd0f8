"""Recordings of a session: one self-contained, versioned, crash-tolerant file.

One module per concept, lowest first:

- :mod:`~sandbox.recording.format`: the file format (gzip of JSON lines, version 1,
  documented in docs/reference.md), the recorded state and :class:`BadRecording`;
- :mod:`~sandbox.recording.limits`: the caps a reader puts on an untrusted file, which
  the writer stays under;
- :mod:`~sandbox.recording.writer`: :func:`create_unique` and the :class:`Recorder`;
- :mod:`~sandbox.recording.untrusted`: opening and inflating a file that may be crafted,
  in bounded chunks;
- :mod:`~sandbox.recording.validate`: the header and every record checked against the
  schema;
- :mod:`~sandbox.recording.reader`: :func:`load` (a :class:`Recording` for replay) and
  :func:`write_csv`.

Recordings are files students exchange: :func:`load` treats them as untrusted and names
the problem and the fix in one :class:`BadRecording` line.
"""

from __future__ import annotations

from sandbox.recording.format import (
    EVENT_KINDS,
    FLUSH_EVERY,
    FORMAT,
    STATE_SPEC,
    VERSION,
    BadRecording,
    get_state,
    set_state,
)
from sandbox.recording.limits import (
    MAX_EVENTS,
    MAX_FILE_BYTES,
    MAX_LINE_BYTES,
    MAX_NUMBERS,
    MAX_RECORDS,
    MAX_TEXT_BYTES,
)
from sandbox.recording.reader import Recording, load, write_csv
from sandbox.recording.writer import Recorder, create_unique

__all__ = [
    "EVENT_KINDS",
    "FLUSH_EVERY",
    "FORMAT",
    "MAX_EVENTS",
    "MAX_FILE_BYTES",
    "MAX_LINE_BYTES",
    "MAX_NUMBERS",
    "MAX_RECORDS",
    "MAX_TEXT_BYTES",
    "STATE_SPEC",
    "VERSION",
    "BadRecording",
    "Recorder",
    "Recording",
    "create_unique",
    "get_state",
    "load",
    "set_state",
    "write_csv",
]
