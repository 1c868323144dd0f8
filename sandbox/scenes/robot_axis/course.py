"""The course's robot axis for the parameter values (course 6.3, 6.4): the data record
(:class:`sandbox.mechanics.robot_axis.RobotAxis`), the arm's model and the command read
from the values, the servo's gains, the default timestep and the course's J_eq."""

from __future__ import annotations

import functools

import mujoco
import numpy as np

from sandbox.mechanics.robot_axis import RobotAxis, equivalent_inertia, state_matrices
from sandbox.physics.spec import Effects, Values, per_revolution_timestep
from sandbox.scenes.robot_axis.params import (
    BACK_AND_FORTH,
    DEFAULTS,
    LARGEST_TIMESTEP,
    POSITION_TIME,
    SERVO_TIME,
    SINE,
    STEP_ANGLE,
    TORQUE,
)


def axis_of(v: Values) -> RobotAxis:
    """The course's data record for the parameter values (J_r = J_p = 0 allowed here)."""
    tiny = 1e-300  # RobotAxis wants > 0; an inertia of 0 is a valid choice of the sliders
    return RobotAxis(
        J_m=v["J_m"], J_r=max(v["J_r"], tiny), J_p=max(v["J_p"], tiny), R_p=v["R_p"],
        k=v["k"], M1=v["M1"], M2=v["M2"], K_t=v["K_t"], mu_t=v["mu_t"], f_v=v["f_v"],
    )  # fmt: skip


def effects(v: Values) -> Effects:
    """Friction f_v and the end stops always; the arm's spring and damper only when it is
    flexible."""
    return Effects(joint_damping=True, springs=flexible(v), actuation=True, limits=True)


def flexible(v: Values) -> bool:
    """True for the flexible arm (parameter ``flexible`` = 1)."""
    return v["flexible"] >= 0.5


def profile(v: Values) -> int:
    """The command: TORQUE, SPEED, BACK_AND_FORTH or SINE."""
    return int(round(v["profile"]))


def servo_gain(v: Values) -> float:
    """K_v [N·m·s/rad] of the speed servo (0 for the torque commands)."""
    if profile(v) in (TORQUE, SINE):
        return 0.0
    return equivalent_inertia(axis_of(v), flexible=False) / SERVO_TIME


def position_gain(v: Values) -> float:
    """K_p [1/s] of the back-and-forth move's position loop (0 for the other commands)."""
    return 1.0 / POSITION_TIME if profile(v) == BACK_AND_FORTH else 0.0


def default_timestep(v: Values, data: mujoco.MjData | None = None) -> float:
    """RK4 step [s] turning the model's fastest eigenvalue by at most STEP_ANGLE (1 ms at
    the course's numbers: the arm against the free chain is 58.5 rad/s). It depends on
    the parameters only: computed once for each set of values (a session asks after every
    frame's steps, and an eigenvalue problem costs a tenth of a millisecond)."""
    return _default_timestep(tuple(sorted({**DEFAULTS, **v}.items())))


@functools.lru_cache(maxsize=64)
def _default_timestep(items: tuple[tuple[str, float], ...]) -> float:
    v = dict(items)
    a, _ = state_matrices(
        axis_of(v), flexible=flexible(v), rho=v["eta"], servo_gain=servo_gain(v),
        position_gain=position_gain(v),
    )  # fmt: skip
    fastest = float(np.max(np.abs(np.linalg.eigvals(a))))
    return per_revolution_timestep(STEP_ANGLE, fastest, largest=LARGEST_TIMESTEP)


def reference(v: Values) -> dict[str, float]:
    """The course's J_eq (6.3, no efficiency): 2.7208e-3 kg·m², 3.4568e-3 for a rigid arm."""
    return {"J_eq": equivalent_inertia(axis_of(v), flexible=flexible(v))}
