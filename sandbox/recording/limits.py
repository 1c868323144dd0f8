"""The limits a recording keeps: what a reader accepts from an untrusted file.

Recordings are files students exchange: the reader refuses a file past any of these
limits (a crafted file stays under a few hundred MB of memory and a few seconds), and
the writer closes its file before reaching them, so what was recorded stays replayable.
Both read them from this module at the time of use (``limits.MAX_RECORDS``), so one
change here moves the writer's and the reader's limit together.
"""

from __future__ import annotations

from sandbox.physics.limits import MAX_MJCF_BYTES

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
