"""One revolution of the inline engine simulated ahead on a scratch copy of the state, and
the orders of its pilon and the largest rocking moment fitted over it."""

from __future__ import annotations

import math
from collections.abc import Mapping

import mujoco
import numpy as np

from sandbox.mechanics.engine import shaking_force, shaking_moment
from sandbox.physics import torsors as generic
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.torsors import joint_drive
from sandbox.scenes.engine.course import engine_of, motor_torque_ref
from sandbox.scenes.revolutions import SHARED, PerModel, imposed_turn
from sandbox.scenes.slider_crank import fit_orders, revolution_table

DENSE = 720
"""Angles at which a revolution's fitted moment is evaluated for its largest value."""

_REVOLUTIONS: PerModel[dict[str, np.ndarray]] = PerModel()
_IMPOSED: PerModel[dict[str, np.ndarray]] = PerModel(tolerance=0.0, shared=SHARED)
_FITS: dict[int, tuple[dict[str, np.ndarray], np.ndarray]] = {}
_COLUMNS = ("pilon", "tamis", "moment_x", "moment_y", "motor_torque", "pilon_ref", "tamis_ref",
            "moment_x_ref", "moment_y_ref", "motor_torque_ref")  # fmt: skip
SAMPLES = 64
"""Crank angles of a revolution (at most, simulated: one per step)."""


def _row(model: mujoco.MjModel, data: mujoco.MjData, v: Mapping[str, float]) -> tuple[float, ...]:
    """(engine angle, pilon, tamis, moment at C (x0, y0), C_mot, and the course's five) of a
    state with its forces."""
    r, m = generic.support_torsor(model, data)
    theta_c, w = float(data.qpos[0]), float(data.qvel[0])
    e = engine_of(v, w)
    ref_f = shaking_force(e, theta_c - math.pi / 2)
    ref_m = shaking_moment(e, theta_c - math.pi / 2)
    return (theta_c - math.pi / 2, -r[1], -r[0], -m[0], -m[1],
            float(joint_drive(model, data)[0]), ref_f[1], ref_f[0], ref_m[0], ref_m[1],
            motor_torque_ref(theta_c, w, v))  # fmt: skip


def revolution(s: Snapshot) -> dict[str, np.ndarray]:
    """One revolution simulated ahead from the current state on a scratch copy (the
    trajectory is untouched), one sample per step (at most 64 per turn): engine angle
    [deg], pilon, tamis, moment at C (x0, y0) and motor torque, with the course's values
    at the same angles. Cached while model, parameters, timestep and speed (to 0.1 %)
    stay the same: at constant speed every revolution is the same. An imposed motion's
    revolution at the current speed is placed exactly instead (64 angles)."""
    model, v = s.model, s.values
    omega = s.joint_qvel("crank")
    if s.imposed is not None:
        kept = _IMPOSED.get(model, v, omega)
        if kept is None:
            rows = imposed_turn(s, SAMPLES, lambda d: _row(model, d, v))
            kept = _IMPOSED.put(model, v, omega, revolution_table(rows, _COLUMNS))
        return kept
    kept = _REVOLUTIONS.get(model, v, omega, float(s.data.time))
    if kept is not None:
        return kept
    data = mujoco.MjData(model)
    mujoco.mj_copyData(data, model, s.data)
    period = 2 * math.pi / max(abs(omega), 1e-9)
    per = max(1, int(round(period / SAMPLES / model.opt.timestep)))
    rows = []
    start = float(s.data.time)
    while data.time < start + period - 0.5 * model.opt.timestep and abs(omega) > 1e-6:
        mujoco.mj_forward(model, data)
        mujoco.mj_rnePostConstraint(model, data)
        rows.append(_row(model, data, v))
        mujoco.mj_step(model, data, per)
    out = revolution_table(rows, _COLUMNS)
    if len(_FITS) > 64:
        _FITS.clear()
    _REVOLUTIONS.put(model, v, omega, out, float(s.data.time))
    return out


def _series(theta: np.ndarray, values: np.ndarray, orders: int = 4) -> np.ndarray:
    """Least-squares coefficients (a0, a1, b1, a2, b2...) of a series in kθ."""
    cols = [np.ones_like(theta)]
    for k in range(1, orders + 1):
        cols += [np.cos(k * theta), np.sin(k * theta)]
    coef, *_ = np.linalg.lstsq(np.stack(cols, axis=1), values, rcond=None)
    return coef


def _evaluate(coef: np.ndarray, theta: np.ndarray) -> np.ndarray:
    out = np.full_like(theta, coef[0])
    for k in range(1, (len(coef) - 1) // 2 + 1):
        out += coef[2 * k - 1] * np.cos(k * theta) + coef[2 * k] * np.sin(k * theta)
    return out


def orders(s: Snapshot) -> np.ndarray:
    """(h1, h2, largest rocking moment) of the simulated revolution."""
    if s.joint_qvel("crank") == 0.0:
        return np.zeros(3)
    rev = revolution(s)
    hit = _FITS.get(id(rev))
    if hit is not None and hit[0] is rev:
        return hit[1]
    theta = rev["theta"]
    if len(theta) < 10:
        return np.zeros(3)
    amp = fit_orders(theta, rev["pilon"])
    # The revolution's pilon differs from the course's exact one by its own accuracy (the
    # step, the servo's speed ripple): an order smaller than that gap is not resolved, 0
    # (one cylinder with its reciprocating mass balanced read 0.02 N of order 1 for 0).
    # An imposed motion's revolution is exact: its orders then resolve down to the fit's
    # own round-off, a few 1e-14 of the largest pilon (1e-10 of it is far below any order
    # the course computes).
    resolution = max(
        float(np.abs(rev["pilon"] - rev["pilon_ref"]).max()),
        1e-10 * float(np.abs(rev["pilon"]).max()),
    )
    amp = np.where(amp[:3] <= resolution, 0.0, amp[:3])
    dense = np.linspace(0, 2 * math.pi, DENSE, endpoint=False)
    mx = _evaluate(_series(theta, rev["moment_x"]), dense)
    my = _evaluate(_series(theta, rev["moment_y"]), dense)
    out = np.array([amp[1], amp[2], float(np.hypot(mx, my).max())])
    _FITS[id(rev)] = (rev, out)
    return out
