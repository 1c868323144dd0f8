"""One revolution of the micro-compressor: simulated ahead on a scratch copy of the state,
or put on the loop at the current speed, and the orders of its pilon and tamis."""

from __future__ import annotations

import math
from collections.abc import Mapping

import mujoco
import numpy as np

from sandbox.physics import torsors as generic
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.torsors import joint_drive
from sandbox.scenes.compressor.course import HARMONIC_SAMPLES, frame_force, motor_torque
from sandbox.scenes.compressor.model import set_loop_state
from sandbox.scenes.revolutions import SHARED, PerModel, imposed_turn
from sandbox.scenes.slider_crank import fit_orders, revolution_table

LOOP_SAMPLES = 32
"""Crank angles of :func:`loop_forces` (orders 0..4 need 9; 32 keeps aliasing out)."""

_REVOLUTIONS: PerModel[dict[str, np.ndarray]] = PerModel()
_IMPOSED: PerModel[dict[str, np.ndarray]] = PerModel(tolerance=0.0, shared=SHARED)
_COLUMNS = ("pilon", "tamis", "motor_torque", "pilon_ref", "tamis_ref", "motor_torque_ref")


def _row(model: mujoco.MjModel, data: mujoco.MjData, v: Mapping[str, float]) -> tuple[float, ...]:
    """(θ, pilon, tamis, C_mot, and the course's three) of a state with its forces."""
    theta, w, alpha = float(data.qpos[0]), float(data.qvel[0]), float(data.qacc[0])
    force = -generic.support_torsor(model, data)[0]
    ref = frame_force(theta, w, v, alpha=alpha)
    return (theta, force[1], force[0], float(joint_drive(model, data)[0]), ref[1], ref[0],
            motor_torque(theta, w, v, alpha=alpha))  # fmt: skip


def _imposed_revolution(s: Snapshot) -> dict[str, np.ndarray]:
    """The imposed crank's revolution at its current speed, placed exactly at
    :data:`HARMONIC_SAMPLES` angles (:func:`~sandbox.scenes.revolutions.imposed_turn`)."""
    model, v = s.model, s.values
    omega = float(s.data.qvel[0])
    kept = _IMPOSED.get(model, v, omega)
    if kept is not None:
        return kept
    rows = imposed_turn(s, HARMONIC_SAMPLES, lambda d: _row(model, d, v))
    return _IMPOSED.put(model, v, omega, revolution_table(rows, _COLUMNS))


def revolution(s: Snapshot) -> dict[str, np.ndarray]:
    """One revolution simulated from the current state on a scratch copy (the trajectory
    itself is untouched): crank angle [deg], pilon, tamis and motor torque, and the
    course's values at the same angles. Cached while the model, the parameters and the
    speed (to 0.1 %) stay the same: in steady state the revolution does not change. An
    imposed motion's revolution at the current speed is placed exactly instead."""
    if s.imposed is not None:
        return _imposed_revolution(s)
    model, v = s.model, s.values
    omega = float(s.data.qvel[0])
    kept = _REVOLUTIONS.get(model, v, omega, float(s.data.time))
    if kept is not None:
        return kept
    data = mujoco.MjData(model)
    mujoco.mj_copyData(data, model, s.data)
    period = 2 * math.pi / max(abs(omega), 1e-9)
    per = max(1, int(round(period / HARMONIC_SAMPLES / model.opt.timestep)))
    rows = []
    while data.time < s.data.time + period and abs(omega) > 1e-6:
        mujoco.mj_forward(model, data)
        mujoco.mj_rnePostConstraint(model, data)
        rows.append(_row(model, data, v))
        mujoco.mj_step(model, data, per)
    out = revolution_table(rows, _COLUMNS)
    _REVOLUTIONS.put(model, v, omega, out, float(s.data.time))
    return out


def steady(s: Snapshot, tol: float = 1e-3) -> bool:
    """True when the crank turns at its set point (and a ramp has reached it), to ``tol``."""
    target = float(s.data.ctrl[0])
    if target == 0.0:
        return False
    near = abs(float(s.data.qvel[0]) - target) <= tol * abs(target)
    if s.model.na:
        near = near and abs(float(s.data.act[0]) - target) <= tol * abs(target)
    return near


def loop_forces(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """Pilon and tamis [N] that MuJoCo computes for the mechanism put on the loop at
    ``LOOP_SAMPLES`` crank angles, at the current speed and motor state, without
    stepping (a scratch copy: the trajectory is untouched). Returns (θ, forces (n, 2))."""
    model, v = s.model, s.values
    data = mujoco.MjData(model)
    mujoco.mj_copyData(data, model, s.data)
    omega = float(s.data.qvel[0])
    thetas = np.linspace(0, 2 * math.pi, LOOP_SAMPLES, endpoint=False)
    forces = np.empty((LOOP_SAMPLES, 2))
    for i, theta in enumerate(thetas):
        set_loop_state(model, data, float(theta), omega, v)
        mujoco.mj_forward(model, data)
        mujoco.mj_rnePostConstraint(model, data)
        forces[i] = -generic.support_torsor(model, data)[0][[1, 0]]
    return thetas, forces


def pilon_harmonics(s: Snapshot) -> np.ndarray:
    """Orders 0..4 of the pilon (row 0) and the tamis (row 1) over one revolution.

    In steady state the revolution is simulated ahead from the current state on a scratch
    copy (:func:`revolution`, cached while nothing changes): at constant speed it is the
    last revolution again. During a speed change (ramp, new set point) that would cost a
    whole revolution of steps at every reading and mix several speeds, so the orders come
    from :func:`loop_forces` at the current speed instead (same values in steady state,
    within 1e-4 of the peak). Shared by the three order readouts through the snapshot.
    """
    cached = s.cache.get("compressor_orders")
    if cached is not None:
        return cached[0]
    rev = None
    if steady(s) or s.imposed is not None:  # imposed: the turn at the current speed, exact
        rev = revolution(s)
        hit = _ORDERS.get(id(rev))
        if hit is not None and hit[0] is rev:  # the same cached revolution: same orders
            s.cache["compressor_orders"] = (hit[1], hit[1])
            return hit[1]
        theta, pilon, tamis = rev["theta"], rev["pilon"], rev["tamis"]
    else:
        theta, forces = loop_forces(s)
        pilon, tamis = forces[:, 0], forces[:, 1]
    if len(theta) < 10 or float(s.data.qvel[0]) == 0.0:
        orders = np.zeros((2, 5))
    else:
        orders = np.stack([fit_orders(theta, pilon), fit_orders(theta, tamis)])
    if rev is not None:
        if len(_ORDERS) > 64:
            _ORDERS.clear()
        _ORDERS[id(rev)] = (rev, orders)
    s.cache["compressor_orders"] = (orders, orders)
    return orders


_ORDERS: dict[int, tuple[dict[str, np.ndarray], np.ndarray]] = {}
"""Orders of each cached revolution (a least-squares fit per reading cost 80 µs)."""
