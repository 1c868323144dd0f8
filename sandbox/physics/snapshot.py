"""A consistent view of the simulation at one instant, with lazily cached torsors.

Scene readouts and arrows receive a :class:`Snapshot`; several readouts that need the
same torsor (e.g. both bearing forces) share one computation.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from sandbox.physics import readouts
from sandbox.physics.kinematics import Kinematics, cached_kinematics

if TYPE_CHECKING:
    from sandbox.physics.imposed import ImposedMotion


class Snapshot:
    """Model, data and parameter values at one instant (after :func:`readouts.prepare`).

    ``imposed``: the imposed motion the state comes from (None: a simulated state), so
    that a readout looking ahead (a revolution's orders) evaluates the same law instead
    of simulating.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        values: Mapping[str, float],
        *,
        imposed: ImposedMotion | None = None,
    ) -> None:
        self.model = model
        self.data = data
        self.values = values
        self.imposed = imposed
        self.cache: dict[str, Any] = {}

    @property
    def kinematics(self) -> Kinematics:
        """Per-body velocities, accelerations and inertias, shared by every readout."""
        return cached_kinematics(self.model, self.data, self.cache)

    @property
    def kinetic(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic torsor {C} of the mechanism at O: (R [kg·m/s], M_O [kg·m²/s])."""
        return readouts.torsor(self.model, self.data, "kin", self.cache)

    @property
    def dynamic(self) -> tuple[np.ndarray, np.ndarray]:
        """Dynamic torsor {D} of the mechanism at O: (R [N], M_O [N·m])."""
        return readouts.torsor(self.model, self.data, "dyn", self.cache)

    @property
    def support(self) -> tuple[np.ndarray, np.ndarray]:
        """Action of the frame on the mechanism at O: (R [N], M_O [N·m])."""
        return readouts.torsor(self.model, self.data, "sup", self.cache)

    def _names(self) -> dict[tuple[str, str], int]:
        names = self.__dict__.get("_ids")
        if names is None:
            names = _NAMES.get(self.model)
            if names is None:
                names = _NAMES[self.model] = {}
            self._ids = names
        return names

    def body_id(self, name: str) -> int:
        """Id of the body called ``name`` (KeyError if absent)."""
        names = self._names()
        bid = names.get(("body", name))
        if bid is None:
            bid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
            if bid < 0:
                raise KeyError(f"no body named {name!r} in the model")
            names["body", name] = bid
        return bid

    def _joint(self, name: str, kind: str) -> int:
        """qvel (kind "dof") or qpos ("qpos") address of the joint called ``name``."""
        names = self._names()
        adr = names.get((kind, name))
        if adr is None:
            jid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)
            table = self.model.jnt_dofadr if kind == "dof" else self.model.jnt_qposadr
            adr = names[kind, name] = int(table[jid])
        return adr

    def joint_qvel(self, name: str) -> float:
        """Velocity of a 1-dof joint called ``name``."""
        return float(self.data.qvel[self._joint(name, "dof")])

    def joint_qpos(self, name: str) -> float:
        """Position of a 1-dof joint called ``name``."""
        return float(self.data.qpos[self._joint(name, "qpos")])


_NAMES: weakref.WeakKeyDictionary[Any, dict[tuple[str, str], int]] = weakref.WeakKeyDictionary()
"""Ids and addresses by name, per compiled model (names never change once compiled)."""
