"""A reusable scratch ``MjData`` per model, for readouts and controls that evaluate another
state of the same model (a derivative by finite differences, the loads at the current
state before a step): allocating an ``MjData`` costs more than using it."""

from __future__ import annotations

import mujoco

KEPT = 64
"""Models whose scratch data is kept: more than a worker's sessions (a class of 30 on two
workers is 15 each; keeping 16 and clearing them all once made one MjData a frame each);
past it the oldest model's is dropped."""

_DATA: dict[int, tuple[mujoco.MjModel, mujoco.MjData]] = {}


def scratch_data(model: mujoco.MjModel) -> mujoco.MjData:
    """The scratch ``MjData`` of ``model`` (its contents are whatever the last user left)."""
    entry = _DATA.get(id(model))
    if entry is None or entry[0] is not model:
        while len(_DATA) >= KEPT:
            del _DATA[next(iter(_DATA))]
        entry = _DATA[id(model)] = (model, mujoco.MjData(model))
    return entry[1]
