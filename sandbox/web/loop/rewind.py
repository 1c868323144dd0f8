"""The last seconds of a session, kept so that a page can make a video of them without a
recording in progress (« Exporter une vidéo »).

A ring of full states (MuJoCo's integration state, a few hundred numbers at most) at
:data:`RATE` a second of simulated time, :data:`SECONDS` long: about 0.1 ms of CPU a
second and 0.3 MB per session. Only states of the current model are written out (a
parameter that rebuilds the model starts the ring again), as a recording file with the
session's current header: :mod:`sandbox.web.video.render` re-simulates between its frames.

No viser here: the session loop keeps the ring; the page's folder writes it.
"""

from __future__ import annotations

from collections import deque
from pathlib import Path
from typing import Any

import numpy as np

from sandbox.recording import Recorder, get_state

SECONDS = 20.0
RATE = 30.0
"""States kept a second of simulated time (the video's frame rate)."""


class Rewind:
    """The last :data:`SECONDS` of a simulation's states."""

    def __init__(self, seconds: float = SECONDS, rate: float = RATE) -> None:
        self.rate = rate
        self.states: deque[tuple[float, np.ndarray]] = deque(maxlen=int(seconds * rate) + 1)
        self._model: object = None
        self._last = -np.inf

    def keep(self, sim: Any) -> None:
        """Called once a frame: a state when 1/rate s of simulated time went by (time
        going back, a reset, or a new model starts the ring again)."""
        t = float(sim.data.time)
        if sim.model is not self._model or t < self._last:
            self.states.clear()
            self._model, self._last = sim.model, -np.inf
        if t - self._last >= 1.0 / self.rate - 1e-9:
            self.states.append((t, get_state(sim.model, sim.data)))
            self._last = t

    @property
    def seconds(self) -> float:
        """Simulated seconds the ring holds."""
        return self.states[-1][0] - self.states[0][0] if len(self.states) > 1 else 0.0

    def write(self, path: Path, sim: Any, lesson: str | None = None) -> bool:
        """The ring as a recording file at ``path`` (the session's parameters in its
        header); False (nothing written) when it holds under two states."""
        if len(self.states) < 2 or sim.model is not self._model:
            return False
        rec = Recorder(path, sim, lesson=lesson)
        try:
            for t, state in list(self.states):
                rec.frame(state=state, time=t)
        finally:
            rec.close()
        return True
