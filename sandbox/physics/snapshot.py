"""A consistent view of the simulation at one instant, with lazily cached torsors.

Scene readouts and arrows receive a :class:`Snapshot`; several readouts that need the
same torsor (e.g. both bearing forces) share one computation.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import mujoco
import numpy as np

from sandbox.physics import readouts


class Snapshot:
    """Model, data and parameter values at one instant (after :func:`readouts.prepare`)."""

    def __init__(
        self, model: mujoco.MjModel, data: mujoco.MjData, values: Mapping[str, float]
    ) -> None:
        self.model = model
        self.data = data
        self.values = values
        self.cache: dict[str, Any] = {}

    @property
    def kinematics(self) -> readouts.Kinematics:
        """Per-body velocities, accelerations and inertias, shared by every readout."""
        return readouts._cached_kin(self.model, self.data, self.cache)

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

    def body_id(self, name: str) -> int:
        """Id of the body called ``name`` (KeyError if absent)."""
        bid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        if bid < 0:
            raise KeyError(f"no body named {name!r} in the model")
        return bid

    def joint_qvel(self, name: str) -> float:
        """Velocity of a 1-dof joint called ``name``."""
        jid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)
        return float(self.data.qvel[self.model.jnt_dofadr[jid]])

    def joint_qpos(self, name: str) -> float:
        """Position of a 1-dof joint called ``name``."""
        jid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)
        return float(self.data.qpos[self.model.jnt_qposadr[jid]])
