"""The recording file format: its name, version, state, event kinds and errors.

Format (version 1, documented in docs/reference.md): a gzip stream of JSON lines.

- line 1, the header: ``{"format": "sandbox-recording", "version": 1, "created": ISO date,
  "target": scene name or file name, "scene": scene name or null, "mjcf": MJCF text of the
  model as first built, "values": parameters, "integrator", "timestep", "state_spec": the
  MuJoCo ``mjtState`` bits of the recorded states, "state_size", "readouts": [names],
  "units": [units], "lesson": lesson name or null, "motion": "imposed" or "free"}`` (a
  recording without "motion", made before it existed, is a free simulation);
- then one record per line, in time order, each with ``"k"`` (kind) and ``"t"`` (sim time):
  ``frame`` (``"s"``: full integration state, floats), ``readouts`` (``"r"``: values in
  header order, null for non-finite), ``set`` (``"name"``, ``"value"``), ``integrator``
  (``"value"``), ``timestep`` (``"value"``), ``reset``, ``lesson`` (``"step"``), ``motion``
  (``"value"``: "imposed" or "free");
- last line ``{"k": "end", "t": ..., "frames": n}``.

Floats are written with ``repr`` so states round-trip exactly (``--verify`` expects 0).
The writer flushes the gzip stream (``Z_SYNC_FLUSH``) at least every :data:`FLUSH_EVERY`
seconds, so a crash loses at most that much; such a file lacks the end line and is
replayed with ``--salvage``.
"""

from __future__ import annotations

import mujoco
import numpy as np

from sandbox.errors import SandboxError

FORMAT = "sandbox-recording"
VERSION = 1
FLUSH_EVERY = 5.0
"""Longest wall-clock time [s] between two flushes of a recording in progress."""

STATE_SPEC = int(mujoco.mjtState.mjSTATE_INTEGRATION)
"""Everything ``mj_step`` reads: a replay from it re-simulates bit for bit."""

EVENT_KINDS = ("set", "integrator", "timestep", "reset", "lesson", "motion")


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


FIX = "the file was altered or damaged after it was written: use the original file"
"""The fix a refusal names when a recording's content breaks the format."""
