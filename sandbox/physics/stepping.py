"""Stepping a scene's model: MuJoCo's batched ``mj_step``, or a per-step control before
each step (:func:`step_model`), and the finiteness check of a row of readouts."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import mujoco


def step_model(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    nstep: int,
    control: Callable[[mujoco.MjModel, mujoco.MjData, Mapping[str, float]], None] | None = None,
    values: Mapping[str, float] | None = None,
) -> None:
    """Advance ``nstep`` timesteps: ``mj_step(model, data, nstep)`` in one call without a
    control; with one, ``control(model, data, values)`` then ``mj_step(model, data)`` at
    every timestep (a time-varying command held over each step), and the control once more
    at the end, so that the state left (read, drawn, recorded) carries the command of its
    own time, as after a reset (a pure control computes the same again before the next
    step). Every loop that steps a scene's model goes through here, so that a scene's
    control is never skipped."""
    if control is None:
        mujoco.mj_step(model, data, nstep)
        return
    values = values if values is not None else {}
    for _ in range(nstep):
        control(model, data, values)
        mujoco.mj_step(model, data)
    if nstep > 0:
        control(model, data, values)


def finite(values: Mapping[str, float]) -> bool:
    """True when every value is a finite number."""
    return all(math.isfinite(v) for v in values.values())
