"""The revolution a scene simulates ahead for its orders and cycle plots, kept per model.

A driven crank (compressor, engine) turns the same revolution over and over at constant
speed: one simulated revolution serves every reading until the model, the parameters,
the timestep or the speed change. It is kept per compiled model (weakly: a session that
leaves frees it), one at a time, so thirty sessions of one process never evict each
other's; the speed counts as unchanged within :data:`SPEED_TOLERANCE` (relative), compared
with the one it was simulated at rather than rounded (a speed at a rounding boundary would
simulate again at every reading).

An imposed motion's revolution is not simulated but placed, exactly, at fixed angles a
turn apart (:func:`imposed_turn`): it depends on nothing but the parameters and the speed,
so it is also shared by every session of the process (:data:`SHARED`): thirty students at
the lesson's values place it once, and a slider moved back and forth finds it again.
It is never provisional.

Right after a change (a new model, new parameters) the motion settles: a revolution
simulated then is provisional and simulated once more :data:`SETTLE` simulated seconds
later (the engine cut from four cylinders to two read a first order of 0.18 N, a leak of
its spin-up, for as long as it was kept; settled, 0.001 N).
"""

from __future__ import annotations

import math
import threading
import weakref
from collections import OrderedDict
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import mujoco

from sandbox.physics.snapshot import Snapshot

T = TypeVar("T")

SPEED_TOLERANCE = 1e-3
"""Relative change of the crank speed below which a kept revolution still serves."""

SHARED = 64
"""Imposed revolutions kept for every session of a process (the most recently used)."""

SETTLE = 1.0
"""Simulated seconds after a change during which a revolution is provisional [s]."""


@dataclass
class _Kept(Generic[T]):
    inputs: tuple[Any, ...]
    omega: float
    result: T | None
    since: float  # simulated time the inputs were first seen [s]
    at: float  # simulated time the result was simulated from [s]


class PerModel(Generic[T]):
    """One result per compiled model, valid while its inputs stay.

    Args:
        tolerance: Relative change of the speed below which a result still serves
            (:data:`SPEED_TOLERANCE`; 0 for an exact result that must not be reused at
            another speed, an imposed motion's).
        shared: Also keep up to this many results for every model of the process, by
            parameters and exact speed (an exact result, which depends on nothing else:
            an imposed motion's); 0: per model only.
    """

    def __init__(self, tolerance: float = SPEED_TOLERANCE, *, shared: int = 0) -> None:
        self.tolerance = tolerance
        self._kept: weakref.WeakKeyDictionary[Any, _Kept[T]] = weakref.WeakKeyDictionary()
        self._shared: OrderedDict[tuple[Any, ...], T] = OrderedDict()
        self._shared_size = shared
        self._lock = threading.Lock()
        self.misses = 0  # results computed (the counted guard of the tests)

    @staticmethod
    def _inputs(model: mujoco.MjModel, values: Mapping[str, float]) -> tuple[Any, ...]:
        return (tuple(sorted(values.items())), float(model.opt.timestep))

    def get(
        self,
        model: mujoco.MjModel,
        values: Mapping[str, float],
        omega: float,
        time: float = math.inf,
    ) -> T | None:
        """The kept result for ``model`` at these parameter ``values``, speed ``omega``
        [rad/s] and simulated ``time`` [s], or None (simulate one, then :meth:`put`)."""
        kept = self._kept.get(model)
        if kept is None or kept.result is None or kept.inputs != self._inputs(model, values):
            return self._from_shared(model, values, omega)
        if not math.isclose(
            omega, kept.omega, rel_tol=self.tolerance, abs_tol=1e-9 * (self.tolerance > 0)
        ):
            return None
        provisional = kept.at - kept.since < SETTLE
        if provisional and time - kept.at >= SETTLE:
            return None  # simulated while the motion settled: once more, now
        return kept.result

    def put(
        self,
        model: mujoco.MjModel,
        values: Mapping[str, float],
        omega: float,
        result: T,
        time: float = math.inf,
    ) -> T:
        """Keep ``result``, simulated from simulated ``time`` [s], for ``model``
        (replacing the one it had) and return it."""
        self.misses += 1
        inputs = self._inputs(model, values)
        if self._shared_size > 0:
            key = (inputs, float(omega))
            with self._lock:
                self._shared[key] = result
                self._shared.move_to_end(key)
                while len(self._shared) > self._shared_size:
                    self._shared.popitem(last=False)
        old = self._kept.get(model)
        since = old.since if old is not None and old.inputs == inputs else time
        if not math.isfinite(since):
            since = -math.inf  # no clock: as settled
        self._kept[model] = _Kept(inputs, float(omega), result, since, time)
        return result

    def _from_shared(
        self, model: mujoco.MjModel, values: Mapping[str, float], omega: float
    ) -> T | None:
        """Another model's result at the same parameters and exact speed, now kept for
        ``model`` too; None when there is none (or nothing is shared)."""
        if self._shared_size == 0:
            return None
        inputs = self._inputs(model, values)
        key = (inputs, float(omega))
        with self._lock:
            result = self._shared.get(key)
            if result is None:
                return None
            self._shared.move_to_end(key)
        self._kept[model] = _Kept(inputs, float(omega), result, -math.inf, math.inf)
        return result

    def seen(self, model: mujoco.MjModel, values: Mapping[str, float], time: float) -> None:
        """Note that ``model`` reads at these ``values`` at simulated ``time``: the start of
        its settling when they are new (a reading that simulates nothing, at rest)."""
        inputs = self._inputs(model, values)
        old = self._kept.get(model)
        if old is None or old.inputs != inputs:
            self._kept[model] = _Kept(inputs, math.nan, None, time, time)

    def clear(self) -> None:
        """Forget every kept result."""
        self._kept.clear()
        with self._lock:
            self._shared.clear()


def imposed_turn(
    s: Snapshot, samples: int, row: Callable[[mujoco.MjData], Sequence[float]]
) -> list[Sequence[float]]:
    """One revolution of an imposed motion at the current speed, exactly: the mechanism
    placed at ``samples`` input angles 2πk/``samples`` (constant speed, no acceleration)
    on a scratch copy, each with its forces (inverse dynamics), read by ``row``. Nothing
    is simulated: the revolution the crank turns at that speed, the same whatever the
    current angle (so that every session at these parameters may share it).

    Args:
        s: A snapshot of an imposed motion (``s.imposed`` set).
        samples: Angles per turn.
        row: Reads one sample from the placed state (its forces up to date).
    """
    imposed = s.imposed
    assert imposed is not None
    model = s.model
    data = mujoco.MjData(model)
    mujoco.mj_copyData(data, model, s.data)
    _, omega = imposed.input(s.data)
    turn = math.copysign(2.0 * math.pi, omega if omega != 0.0 else 1.0)
    rows = []
    for k in range(samples):
        imposed.place(model, data, s.values, (turn * k / samples, omega, 0.0))
        rows.append(row(data))
    return rows
