"""Per-body kinematics of one state: velocities, accelerations and inertias of the bodies'
centres of mass in R0 (world axes), computed once and shared by every readout.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import cached_property
from typing import Any

import mujoco
import numpy as np

from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.mechanism import gravity_vector, mechanism_bodies

Pair = tuple[np.ndarray, np.ndarray]


class Kinematics:
    """Per-body quantities of one state, computed once and shared by every readout.

    Velocities need ``mj_forward``; accelerations also ``mj_rnePostConstraint``.
    Arrays cover every body (index = body id); ``bodies`` are the mechanism's.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self.model, self.data = model, data
        self.bodies = mechanism_bodies(model)

    @cached_property
    def arm(self) -> np.ndarray:
        """G − c for every body, c the subtree com where cvel/cacc are expressed."""
        return self.data.xipos - self.data.subtree_com[self.model.body_rootid]

    @cached_property
    def omega(self) -> np.ndarray:
        return self.data.cvel[:, :3]

    @cached_property
    def v_g(self) -> np.ndarray:
        return self.data.cvel[:, 3:] + _cross(self.omega, self.arm)

    @cached_property
    def alpha(self) -> np.ndarray:
        return self.data.cacc[:, :3]

    @cached_property
    def a_g(self) -> np.ndarray:
        """True acceleration of G: cacc includes −g like an accelerometer (module doc)."""
        d = self.data
        a = d.cacc[:, 3:] + _cross(self.alpha, self.arm) + _cross(self.omega, self.v_g)
        return a + gravity_vector(self.model)

    @cached_property
    def inertia(self) -> np.ndarray:
        """I_G of every body in world axes, (nbody, 3, 3)."""
        rot = self.data.ximat.reshape(-1, 3, 3)
        return np.einsum("bij,bj,bkj->bik", rot, self.model.body_inertia, rot)

    @cached_property
    def i_omega(self) -> np.ndarray:
        """I_G ω of every body."""
        return np.einsum("bij,bj->bi", self.inertia, self.omega)

    @cached_property
    def delta_g(self) -> np.ndarray:
        """I_G α + ω ∧ I_G ω of every body (dynamic moment at G)."""
        return np.einsum("bij,bj->bi", self.inertia, self.alpha) + _cross(self.omega, self.i_omega)

    # -- the mechanism's bodies only (index = position in ``bodies``), shared by the torsors,
    # energies and powers of one row instead of each indexing the per-body arrays again.
    @cached_property
    def gravity(self) -> np.ndarray:
        return gravity_vector(self.model)

    @cached_property
    def mass_b(self) -> np.ndarray:
        return self.model.body_mass[self.bodies]

    @cached_property
    def xipos_b(self) -> np.ndarray:
        return self.data.xipos[self.bodies]

    @cached_property
    def v_g_b(self) -> np.ndarray:
        return self.v_g[self.bodies]

    @cached_property
    def omega_b(self) -> np.ndarray:
        return self.omega[self.bodies]

    @cached_property
    def i_omega_b(self) -> np.ndarray:
        return self.i_omega[self.bodies]

    @cached_property
    def momentum_b(self) -> np.ndarray:
        """m v_G of the mechanism's bodies."""
        return self.mass_b[:, None] * self.v_g_b

    @cached_property
    def a_g_b(self) -> np.ndarray:
        return self.a_g[self.bodies]

    @cached_property
    def delta_g_b(self) -> np.ndarray:
        return self.delta_g[self.bodies]


def ensure_kinematics(
    model: mujoco.MjModel, data: mujoco.MjData, kin: Kinematics | None
) -> Kinematics:
    """``kin`` if given, else the :class:`Kinematics` of (model, data)."""
    return kin if kin is not None else Kinematics(model, data)


def body_velocities(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """(v_G, ω) of every body's centre of mass in R0, each (nbody, 3), world axes."""
    k = Kinematics(model, data)
    return k.v_g, k.omega


def body_accelerations(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """(a_G, α): true accelerations of every centre of mass, after mj_rnePostConstraint.

    MuJoCo's ``cacc`` is a spatial acceleration that includes −g (like an accelerometer);
    the classical acceleration of G is cacc_lin + α ∧ (G − c) + ω ∧ v_G, plus g.
    """
    k = Kinematics(model, data)
    return k.a_g, k.alpha


def select_bodies(k: Kinematics, bodies: Iterable[int] | None) -> np.ndarray:
    """Ids of ``bodies`` as an array (None: the mechanism's bodies)."""
    return k.bodies if bodies is None else np.asarray(list(bodies), dtype=int)


def cached_kinematics(
    model: mujoco.MjModel, data: mujoco.MjData, cache: dict[str, Any] | None
) -> Kinematics:
    """The :class:`Kinematics` of (model, data), kept in ``cache`` so that every consumer
    of one state shares it (None: a new one)."""
    if cache is None:
        return Kinematics(model, data)
    kin = cache.get("_kin")
    if kin is None:
        kin = cache["_kin"] = Kinematics(model, data)
    return kin
