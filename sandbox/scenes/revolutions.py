"""The revolution a scene simulates ahead for its orders and cycle plots, kept per model.

A driven crank (compressor, engine) turns the same revolution over and over at constant
speed: one simulated revolution serves every reading until the model, the parameters,
the timestep or the speed change. It is kept per compiled model (weakly: a session that
leaves frees it), one at a time, so thirty sessions of one process never evict each
other's; the speed counts as unchanged within :data:`SPEED_TOLERANCE` (relative), compared
with the one it was simulated at rather than rounded (a speed at a rounding boundary would
simulate again at every reading).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping
from typing import Any, Generic, TypeVar

import mujoco

T = TypeVar("T")

SPEED_TOLERANCE = 1e-3
"""Relative change of the crank speed below which a kept revolution still serves."""


class PerModel(Generic[T]):
    """One result per compiled model, valid while its inputs stay."""

    def __init__(self) -> None:
        self._kept: weakref.WeakKeyDictionary[Any, tuple[tuple[Any, ...], float, T]] = (
            weakref.WeakKeyDictionary()
        )
        self.misses = 0  # results computed (the counted guard of the tests)

    @staticmethod
    def _inputs(model: mujoco.MjModel, values: Mapping[str, float]) -> tuple[Any, ...]:
        return (tuple(sorted(values.items())), float(model.opt.timestep))

    def get(self, model: mujoco.MjModel, values: Mapping[str, float], omega: float) -> T | None:
        """The kept result for ``model`` at these parameter ``values`` and speed ``omega``
        [rad/s], or None."""
        kept = self._kept.get(model)
        if kept is None or kept[0] != self._inputs(model, values):
            return None
        speed = kept[1]
        if not math.isclose(omega, speed, rel_tol=SPEED_TOLERANCE, abs_tol=1e-9):
            return None
        return kept[2]

    def put(self, model: mujoco.MjModel, values: Mapping[str, float], omega: float, result: T) -> T:
        """Keep ``result`` for ``model`` (replacing the one it had) and return it."""
        self.misses += 1
        self._kept[model] = (self._inputs(model, values), float(omega), result)
        return result

    def clear(self) -> None:
        """Forget every kept result."""
        self._kept.clear()
