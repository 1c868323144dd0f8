"""The read-only face of a :class:`~sandbox.physics.simulation.Simulation`: what a page's
panel, a table or an accuracy check reads of it, and nothing that changes it.

Panels are typed against :class:`ReadOnlySimulation`; they change the simulation only by
a request to their session (which the loop thread applies between frames). A
``Simulation`` satisfies the protocol as it is. Its ``snapshot`` brings derived
quantities up to date on the live data but restores the solver's warm start, so reading
never changes the motion.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from contextlib import AbstractContextManager
from typing import Any, Protocol

import mujoco

from sandbox.physics.readouts import ReadoutInfo
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import Scene


class ReadOnlySimulation(Protocol):
    """A simulation as something that only shows it sees it."""

    @property
    def scene(self) -> Scene | None:
        """The scene's spec (None: a user's MJCF file)."""

    @property
    def values(self) -> Mapping[str, float]:
        """The parameter values in force."""

    @property
    def model(self) -> mujoco.MjModel:
        """The compiled model (a rebuild replaces it)."""

    @property
    def data(self) -> mujoco.MjData:
        """The physics state (read, never written, outside the loop thread)."""

    @property
    def lock(self) -> AbstractContextManager[Any]:
        """Held while the loop thread changes the model or its values."""

    @property
    def label(self) -> str:
        """Scene name or file name."""

    @property
    def integrator(self) -> str:
        """The integrator's name."""

    @property
    def timestep(self) -> float:
        """The timestep in force [s]."""

    @property
    def timestep_chosen(self) -> bool:
        """The user chose the timestep (else the scene's default follows the values)."""

    @property
    def max_timestep(self) -> float:
        """The largest timestep [s] accepted."""

    @property
    def motion(self) -> str:
        """ "imposed" (computed exactly) or "free" (simulated)."""

    @property
    def motions(self) -> tuple[str, ...]:
        """The ways this simulation can compute its motion."""

    def readout_infos(self) -> list[ReadoutInfo]:
        """Every readout available."""

    def readout_names(self) -> list[str]:
        """Names of the readouts, in column order."""

    def snapshot(self, names: Iterable[str] = ..., *, forces: bool = ...) -> Snapshot:
        """Derived quantities for ``names`` brought up to date, the motion unchanged."""

    def reference(self) -> dict[str, float]:
        """The course's closed-form values for the parameters in force."""

    def check_value(self, name: object, value: object) -> float:
        """``value`` checked for parameter ``name``, nothing changed."""

    def check_timestep(self, value: object) -> float:
        """``value`` checked as the timestep, nothing changed."""
