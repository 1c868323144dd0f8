"""Readouts sampled between the frames of a session, for a plot of one readout against
another ("Tracé X–Y") that must follow motions faster than the panels' 10 Hz.

The pilon of the compressor turns at 50 revolutions a second: read at the panels' rate it
would be one point every five revolutions, always near the same angle. A :class:`Probe`
asks the session to stop its stepping at sample instants and reads the wanted readouts on
the physics state there. It costs a readout evaluation per sample (about 0.1 ms on the
compressor), so it samples only while a view wants it, at most :data:`RATE` times per
second of wall time, and only the readouts asked for. The instants are spaced unevenly (a
low-discrepancy sequence around the mean spacing) so that a periodic motion is met at
every phase rather than at the same few.

No viser here: the session loop owns the probe; views read what it sampled.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from collections.abc import Collection, Hashable, Iterator, Mapping

RATE = 200.0
"""Samples per second of wall time, at most (whatever the speed of the simulation)."""

MAX_SAMPLES = 4096
"""Samples kept for the views to read (about 20 s at :data:`RATE`)."""

_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


class Probe:
    """The readouts a session samples between frames, and the samples.

    Views call :meth:`want` and :meth:`release` (from the loop thread) and read with
    :meth:`since`; the session's stepping asks :meth:`chunks` how to split its steps and
    calls :meth:`add` after each chunk that ends on a sample instant.
    """

    def __init__(self, maxlen: int = MAX_SAMPLES) -> None:
        self._wants: dict[Hashable, tuple[str, ...]] = {}
        self.names: tuple[str, ...] = ()
        self._samples: deque[tuple[int, float, Mapping[str, float]]] = deque(maxlen=maxlen)
        self._seq = 0
        self._left = 0  # steps until the next sample
        self._k = 0  # index in the low-discrepancy sequence
        self._lock = threading.Lock()

    def want(self, key: Hashable, names: Collection[str]) -> None:
        """``key`` (a view) wants ``names`` sampled from now on."""
        wanted = tuple(sorted(set(names)))
        if self._wants.get(key) == wanted:
            return
        self._wants[key] = wanted
        self._update()

    def release(self, key: Hashable) -> None:
        """``key`` no longer wants samples (nothing is sampled when nobody does)."""
        if self._wants.pop(key, None) is not None:
            self._update()

    def _update(self) -> None:
        self.names = tuple(sorted({n for names in self._wants.values() for n in names}))
        self._left = 0

    @property
    def active(self) -> bool:
        """True when some view wants samples."""
        return bool(self.names)

    def spacing(self, timestep: float, speed: float) -> float:
        """Mean number of timesteps between two samples: :data:`RATE` per wall second at
        ``speed`` × real time, at least 1."""
        if not (timestep > 0 and math.isfinite(timestep)):
            return 1.0
        return max(1.0, abs(speed) / (RATE * timestep))

    def chunks(self, n: int, timestep: float, speed: float) -> Iterator[tuple[int, bool]]:
        """Split ``n`` timesteps into (steps, sample after them) pieces."""
        mean = self.spacing(timestep, speed)
        while n > 0:
            if self._left <= 0:  # spacings between 0.5 and 1.5 times the mean
                self._k += 1
                jitter = 0.5 + (self._k * _GOLDEN) % 1.0
                self._left = max(1, round(mean * jitter))
            m = min(n, self._left)
            n -= m
            self._left -= m
            yield m, self._left == 0

    def add(self, time: float, values: Mapping[str, float]) -> None:
        """One sample of the wanted readouts at simulated ``time``."""
        with self._lock:
            self._seq += 1
            self._samples.append((self._seq, float(time), dict(values)))

    def since(self, seq: int) -> tuple[int, list[tuple[float, Mapping[str, float]]]]:
        """Samples added after number ``seq`` (0: all kept), and the last number."""
        with self._lock:
            if not self._samples or self._samples[-1][0] <= seq:
                return self._seq, []
            new = [(t, v) for k, t, v in self._samples if k > seq]
            return self._seq, new
