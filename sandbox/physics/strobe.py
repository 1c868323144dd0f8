"""Numbers a reader can read on a fast rotation: held at one input angle, turn after turn.

At 3000 tr/min a crank turns 50 times a second; the page's tables and overlay are written
10 times a second, each time at another angle (the pilon read 301,9 N, then −42,7 N, then
170,5 N), and a canvas that draws its labels a frame later shows yet another instant. A
stroboscope solves it as a workshop does: while an imposed rotation at constant speed
turns faster than once in :data:`HELD_PERIOD` seconds of wall time, every number the
page writes is read at the last instant the input passed its scene's angle
(:attr:`~sandbox.physics.imposed.Imposed.held_at`), the state there placed exactly on a
scratch ``MjData`` (closure and inverse dynamics, :meth:`~sandbox.physics.motion_choice.
MotionChoice.put_at`). At constant speed that state is the same every turn: the numbers
stand still, the same in every view, and they change when the speed or a parameter does.
The 3D view keeps drawing the motion as it is.
"""

from __future__ import annotations

import math

import mujoco

from sandbox.physics.imposed import ImposedMotion, Values
from sandbox.physics.simulation import Simulation
from sandbox.physics.snapshot import Snapshot

HELD_PERIOD = 2.0
"""Wall seconds per turn below which the numbers are held [s]: a value that changes
faster than that cannot be read."""

TURN = 2.0 * math.pi

STEADY = 1e-6
"""Relative change of the speed over a turn below which the rotation counts as steady
(a speed reached through a lag creeps on for minutes): held."""

HELD_ANGLE = "theta"
"""The readout that names the angle the numbers are held at (the overlay writes it)."""


def held_time(
    imposed: ImposedMotion, values: Values, data: mujoco.MjData, t: float, speed: float = 1.0
) -> float | None:
    """The last instant at or before ``t`` [s] at which the input passed its held angle,
    or None when the numbers are not held: the scene holds none, the law's speed is not
    steady there (:data:`STEADY`), or a turn takes :data:`HELD_PERIOD` s of wall time or
    more at the playback ``speed``."""
    at = imposed.spec.held_at
    if at is None:
        return None
    theta, omega, alpha = imposed.motion(values, data, t)
    if not math.isfinite(theta + omega + alpha):
        return None
    if not abs(omega) * abs(speed) * HELD_PERIOD > TURN:
        return None
    period = TURN / abs(omega)
    if abs(alpha) * period > STEADY * abs(omega):  # still reaching its speed
        return None
    back = ((theta - at) % TURN) / omega if omega > 0 else ((at - theta) % TURN) / -omega
    # the law must have turned at that speed since (not a speed step within the turn)
    before = imposed.motion(values, data, t - back)[1]
    if abs(before - omega) > STEADY * abs(omega):
        return None
    return t - back


class Held:
    """The state one simulation's page reads its numbers from while they are held: a
    scratch ``MjData`` placed at :func:`held_time`. At constant speed the mechanism is in
    the same state at that angle every turn (its input's unwrapped angle apart, which
    every view writes modulo a turn): only the time moves on, the state is placed again
    when the model, the parameters or the law's anchor change (:attr:`generation` then
    changes: what was computed from the old one is stale).

    Args:
        sim: The simulation (only read; its model may be swapped at any time).
    """

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self._data: mujoco.MjData | None = None
        self._model: mujoco.MjModel | None = None
        self._key: tuple[object, ...] | None = None
        self._snap: Snapshot | None = None
        self.generation = 0

    def snapshot(self, t: float, speed: float = 1.0) -> Snapshot | None:
        """The state at the held instant before drawn time ``t`` [s] (its forces up to
        date), or None when the numbers are not held (a simulated motion, a slow or
        varying speed)."""
        sim = self.sim
        with sim.lock:
            imposed = sim.imposed
            if imposed is None:
                return None
            at = held_time(imposed, sim.values, sim.data, t, speed)
            if at is None:
                return None
            model = sim.model
            if self._model is not model or self._data is None:
                self._model, self._data = model, mujoco.MjData(model)
            key = (id(model), tuple(sim.values.items()), sim.data.userdata.tobytes())
            if key != self._key or self._snap is None:
                data = self._data
                data.userdata[:] = sim.data.userdata  # the law's anchor
                sim.put_at(data, at, forces=True)
                self._snap = Snapshot(model, data, dict(sim.values), imposed=imposed)
                self._key = key
                self.generation += 1
            self._snap.data.time = at  # the same state, this turn's instant
            return self._snap
