"""What the 3D view draws: the state at the display time, not at the last physics step.

The physics steps by whole timesteps (the rotor's 10 ms turn it 90° at 1500 rpm and
360° at 6000 rpm); the display asks for the state at any instant in between. The last
step's positions are carried forward with its velocities for the fraction of timestep
(``mj_integratePos``: exact for a rotation at constant speed, quaternions handled; a
closed loop is brought back onto its constraints, :func:`close_loops`), then
``mj_kinematics`` (or ``mj_forward`` when arrows need forces) runs on a second
``MjData`` that only the display reads: the physics itself is never touched. An imposed
motion needs none of this: its state at the display time is placed exactly
(:meth:`~sandbox.physics.simulation.Simulation.put_at`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import mujoco
import numpy as np

from sandbox.physics import readouts as generic
from sandbox.physics.simulation import Simulation
from sandbox.physics.snapshot import Snapshot

MAX_AHEAD_STEPS = 2.0
"""The display runs ahead of the physics by less than one timestep; a larger gap (a
reset, a state changed behind the controller's back) draws the physics state."""


class DisplayState:
    """A second ``MjData`` holding the state drawn at ``time``.

    Args:
        sim: The simulation it follows (its model may be swapped at any time).
    """

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self._model: mujoco.MjModel | None = None
        self._data: mujoco.MjData | None = None
        self._key: tuple[object, ...] | None = None
        self._state = np.zeros(0)

    def ahead(self, time: float) -> float:
        """Seconds of motion to add to the physics state to draw ``time`` (0 when
        ``time`` is not within :data:`MAX_AHEAD_STEPS` timesteps after it)."""
        sim = self.sim
        gap = time - float(sim.data.time)
        dt = sim.timestep
        if not (math.isfinite(gap) and gap > 0 and gap <= MAX_AHEAD_STEPS * max(dt, 1e-12)):
            return 0.0
        return gap

    def data(
        self, time: float, names: Iterable[str] = (), *, forces: bool = False
    ) -> mujoco.MjData:
        """The state at ``time``: a copy of the physics state carried forward by
        :meth:`ahead` (positions and bodies' poses up to date).

        Args:
            time: Display time [s].
            names: Readouts the caller evaluates on it (they need ``mj_forward``);
                empty: positions only (``mj_kinematics``).
            forces: The caller reads forces on it (arrows, scene readouts): the
                frame's actions and the dynamic torsor brought up to date.
        """
        sim = self.sim
        model, physics = sim.model, sim.data
        gap = self.ahead(time)
        if self._model is not model or self._data is None:
            self._model, self._data = model, mujoco.MjData(model)
        names = tuple(names)
        key = (
            id(model),
            float(physics.time),
            gap,
            names,
            forces,
            physics.qpos.tobytes(),
            physics.qvel.tobytes(),
            physics.ctrl.tobytes(),
        )
        shown = self._data
        if key == self._key:
            return shown
        if gap == 0.0 and sim.imposed is not None:
            # the exact state just placed: its forces computed there once when they are
            # read (the recorder may read them too), then copied
            if names or forces:
                sim.snapshot(names, forces=forces)
            mujoco.mj_copyData(shown, model, physics)
            self._key = key
            return shown
        spec = mujoco.mjtState.mjSTATE_INTEGRATION  # state, inputs and warm start only
        size = mujoco.mj_stateSize(model, spec)
        if self._state.size != size:
            self._state = np.zeros(size)
        mujoco.mj_getState(model, physics, self._state, spec)
        mujoco.mj_setState(model, shown, self._state, spec)
        at = float(physics.time) + gap
        if sim.put_at(shown, at, forces=bool(names) or forces):
            pass  # an imposed motion: the exact state at that time, nothing carried forward
        else:
            if gap > 0:
                mujoco.mj_integratePos(model, shown.qpos, shown.qvel, gap)
                close_loops(model, shown)
            shown.time = at
            if names or forces:
                generic.prepare(model, shown, names, forces=forces)
            else:
                mujoco.mj_kinematics(model, shown)
        self._key = key
        return shown

    def snapshot(self, time: float, names: Iterable[str] = (), *, forces: bool = False) -> Snapshot:
        """A snapshot of the state at ``time`` for the readouts ``names`` and, when
        ``forces`` is set, the forces (arrows)."""
        names = tuple(names)
        sim = self.sim
        data = self.data(time, names or ("time",), forces=forces)
        return Snapshot(sim.model, data, sim.values, imposed=sim.imposed)


LOOP_TOLERANCE = 1e-12
"""Violation [m or rad] below which a carried-forward closed loop counts as closed."""


def _equality_rows(model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
    """(J, r): the equality constraints' Jacobian (dense) and violation at ``data``'s
    positions (``mj_fwdPosition`` is run)."""
    mujoco.mj_fwdPosition(model, data)
    nefc, nv = int(data.nefc), int(model.nv)
    rows = np.flatnonzero(
        np.asarray(data.efc_type[:nefc]) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    )
    if rows.size == 0:
        return np.zeros((0, nv)), np.zeros(0)
    if mujoco.mj_isSparse(model):
        jac = np.zeros((nefc, nv))
        mujoco.mju_sparse2dense(
            jac, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind
        )
    else:
        jac = np.asarray(data.efc_J[: nefc * nv]).reshape(nefc, nv)
    return jac[rows], np.asarray(data.efc_pos[rows], dtype=float)


def close_loops(model: mujoco.MjModel, data: mujoco.MjData, iterations: int = 4) -> None:
    """Bring carried-forward positions and velocities back onto the equality constraints.

    A closed loop (the compressor's slider-crank, the engine's four) carried forward along
    its velocities opens by up to 0.2 mm in a timestep: forces evaluated on it would then
    hold the constraint's correction (a few newtons) and a revolution simulated ahead from
    it would start with a transient (the engine's first order read 14 N instead of 0).
    Gauss-Newton steps (:func:`_impulse`: least change in the kinetic-energy metric) close
    it, then the velocities are projected on the constraints' tangent space (``J q̇ = 0``).
    Nothing is done for a model without active equality constraints.
    """
    if model.neq == 0 or model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_EQUALITY:
        return
    for _ in range(iterations):
        jac, violation = _equality_rows(model, data)
        if violation.size == 0 or float(np.max(np.abs(violation))) <= LOOP_TOLERANCE:
            break
        mujoco.mj_integratePos(model, data.qpos, -_impulse(model, data, jac, violation), 1.0)
    jac, _ = _equality_rows(model, data)
    if jac.size:
        data.qvel[:] -= _impulse(model, data, jac, jac @ data.qvel)


def _impulse(
    model: mujoco.MjModel, data: mujoco.MjData, jac: np.ndarray, residual: np.ndarray
) -> np.ndarray:
    """The smallest change ``dq`` in the kinetic-energy metric with ``J dq = residual``:
    ``M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁻¹ residual`` (what an impulse along the constraints does, so the
    heavy parts, a motor's rotor, keep their speed)."""
    minv_jt = np.zeros((jac.shape[0], model.nv))
    mujoco.mj_solveM(model, data, minv_jt, np.ascontiguousarray(jac))
    gram = jac @ minv_jt.T
    return minv_jt.T @ np.linalg.lstsq(gram, residual, rcond=None)[0]


def joint_speed(model: mujoco.MjModel, data: mujoco.MjData, joint: int) -> float:
    """Angular speed [rad/s] of a joint relative to its parent: |ω| of a hinge, ‖ω‖ of a
    ball or of a free joint's rotation; 0 for a slide."""
    adr = int(model.jnt_dofadr[joint])
    kind = int(model.jnt_type[joint])
    if kind == int(mujoco.mjtJoint.mjJNT_HINGE):
        return abs(float(data.qvel[adr]))
    if kind == int(mujoco.mjtJoint.mjJNT_BALL):
        return float(np.linalg.norm(data.qvel[adr : adr + 3]))
    if kind == int(mujoco.mjtJoint.mjJNT_FREE):
        return float(np.linalg.norm(data.qvel[adr + 3 : adr + 6]))
    return 0.0


def main_joint(model: mujoco.MjModel, data: mujoco.MjData) -> int | None:
    """The mechanism's main rotating joint: the one turning fastest (a crank, a rotor's
    spin, a top's ball joint), None when nothing turns."""
    best, speed = None, 0.0
    for j in range(model.njnt):
        w = joint_speed(model, data, j)
        if w > speed:
            best, speed = j, w
    return best


def rotation_speed(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Angular speed [rad/s] of :func:`main_joint` (0 when nothing turns): a "Pas" of an
    angle lasts that angle divided by it."""
    j = main_joint(model, data)
    return 0.0 if j is None else joint_speed(model, data, j)


def angle_between(a: np.ndarray, b: np.ndarray) -> float:
    """Angle [rad] between two orientations (w, x, y, z)."""
    dot = abs(float(np.dot(a, b)) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return 2.0 * math.acos(min(1.0, dot))
