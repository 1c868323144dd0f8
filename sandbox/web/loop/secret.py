"""What a student's session keeps from their page while a challenge runs.

A challenge's secret lives in the student's own simulation (its bearing forces are what
the student measures); the page is built from a public twin instead: the 3D picture from
a model built with the secret parameters' stand-ins
(:func:`sandbox.physics.picture.picture`'s ``shown``), the readouts without those that
give the secret away (:attr:`sandbox.challenges.Challenge.withheld`), and no control of a
secret parameter, nor a recording (it would hold the model). The session's
:class:`~sandbox.web.loop.Controller` applies it (a ``challenge`` request, built by the
server only) and refuses any change of a locked parameter.
"""

from __future__ import annotations

from collections.abc import Mapping

import mujoco

from sandbox.challenges import Attempt
from sandbox.physics.model import build
from sandbox.physics.picture import check_twin
from sandbox.physics.simulation import Simulation


class Secret:
    """A student's challenge as their session applies it.

    Args:
        attempt: The student's attempt (its secret values are set on the simulation).
    """

    def __init__(self, attempt: Attempt) -> None:
        c = attempt.challenge
        self.attempt = attempt
        self.values = {**dict(c.fixed), **attempt.secret}
        self.locked = frozenset(self.values)
        self.withheld = frozenset(c.withheld)
        self.public = c.public()
        self._twin: tuple[int, mujoco.MjModel] | None = None

    def apply(self, sim: Simulation) -> None:
        """Set the fixed and secret values on ``sim`` (loop thread)."""
        for name, value in self.values.items():
            sim.set_value(name, value)

    def twin(self, sim: Simulation) -> mujoco.MjModel:
        """The model the page is drawn with: ``sim``'s values, the secret ones replaced
        by their stand-ins (built again when the student's changes rebuilt the model)."""
        key = id(sim.model)
        if self._twin is None or self._twin[0] != key:
            model = build(sim.source, {**sim.values, **self.public})
            check_twin(sim.model, model)
            self._twin = (key, model)
        return self._twin[1]

    def hide(self, values: Mapping[str, float]) -> Mapping[str, float]:
        """``values`` without the withheld readouts."""
        if not self.withheld.intersection(values):
            return values
        return {k: v for k, v in values.items() if k not in self.withheld}
