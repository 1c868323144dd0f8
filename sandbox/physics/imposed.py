"""Imposed motion: a mechanism whose input the course imposes (a crank at constant speed, a
speed profile) is not integrated. Its state at any instant comes from the imposed law
through the closure equations, and every force from inverse dynamics, exactly.

- :class:`Imposed` is what a scene declares: the input joint, the motor that imposes it,
  the closure (every joint's position, speed and acceleration from the input's) and the
  law of the input in time.
- :func:`inverse_dynamics` turns a state with its acceleration into MuJoCo's derived
  quantities and forces: with M (``mj_mulM``) and the bias forces of ``mj_fwdVelocity``,
  the generalised force the motion takes, τ = M q̈ + c − passive − applied, is shared
  between the motor and the loops' constraints by one small linear solve,
  τ = B u + Jᵀ λ (the course's PFD solid by solid, written in the joints' coordinates).
  MuJoCo's soft constraints would produce no force on exact kinematics: the loop forces
  are λ, written into ``efc_force`` so that ``mj_rnePostConstraint`` (the frame's action,
  the torsors) reads them as it reads a simulated state's.
- :class:`ImposedMotion` is one simulation's imposed motion: where the law starts (its
  anchor) and the evaluation at any time.

The state's acceleration q̈ is kept in ``qacc_warmstart`` (the solver's warm start,
which nothing integrates in this mode) and the law's anchor in three ``userdata`` slots:
a recorded or copied state then carries both, so that its forces can be computed again
from the state alone and the motion continues from it exactly (a replay, ``--verify``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import mujoco
import numpy as np

from sandbox.mechanics.imposed import Anchor, Motion

Values = Mapping[str, float]

IMPOSED, FREE = "imposed", "free"
MOTIONS = (IMPOSED, FREE)
"""The names of the two ways a scene's motion is computed (``--motion``)."""

MOTION_WORDS = {
    IMPOSED: "imposé (dynamique inverse)",
    FREE: "libre (simulé)",
}
"""The two ways in the page's words, after the control's label « Mouvement » (« Mouvement
imposé (dynamique inverse) », « Mouvement libre (simulé) »: the whole phrase did not fit
the control's width on a projector)."""

_EQUALITY = int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)

ANCHOR_SLOTS = 3
"""``userdata`` numbers of the anchor: time, input position, input speed."""


@dataclass(frozen=True)
class Imposed:
    """How a scene's input motion is imposed, as the course studies it.

    Attributes:
        joint: The input joint (a crank's hinge, a carriage's slide): its position and
            speed are the law's.
        actuator: The motor that imposes it: its force is what inverse dynamics gives
            (« Couple nécessaire »).
        place: Closure equations: writes ``qpos``, ``qvel`` and ``qacc_warmstart`` (the
            acceleration) of every joint from the input's (position, speed,
            acceleration), exactly (closed form, or Newton to round-off).
        law: The input's motion at time t from an anchor: (values, anchor, t) ->
            (position, speed, acceleration) (:mod:`sandbox.mechanics.imposed`).
        default: Imposed unless the free simulation is asked for (a steady regime the
            course studies); False: free by default, imposed on request.
        slot: First of the :data:`ANCHOR_SLOTS` ``userdata`` numbers that hold the law's
            anchor (after the scene's own; the model is given enough of them).
        unavailable: Why the motion cannot be imposed at these parameter values (e.g.
            a torque command, a flexible arm that must be simulated): (English, French),
            or None when it can.
        held_at: Input angle [rad] at which the page reads its numbers while the input
            turns faster than a reader can follow (:mod:`sandbox.physics.strobe`): one
            where every headline quantity is away from zero; None: never held (an
            input that does not turn, a carriage on its slide).
        friction: Dry friction on the input joint [N·m or N, ≥ 0] at a state whose forces
            inverse dynamics just gave (a plain bearing's torque from its load): it
            opposes the input's motion, the motor gives it on top, and the joint's
            constraint force carries it (P_int = −friction × speed). None: perfect.
    """

    joint: str
    actuator: str
    place: Callable[[mujoco.MjModel, mujoco.MjData, Values, Motion], None]
    law: Callable[[Values, Anchor, float], Motion]
    default: bool = False
    unavailable: Callable[[Values], tuple[str, str] | None] | None = None
    slot: int = 0
    held_at: float | None = math.pi / 3
    friction: Callable[[mujoco.MjModel, mujoco.MjData, Values], float] | None = None

    def refusal(self, values: Values) -> tuple[str, str] | None:
        """(English, French) reason the motion cannot be imposed at ``values``, or None."""
        return None if self.unavailable is None else self.unavailable(values)


def _dense_moment(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """The actuators' moment arms (nu, nv), after ``mj_fwdPosition``."""
    moment = np.zeros((model.nu, model.nv))
    if model.nu:
        mujoco.mju_sparse2dense(
            moment, data.actuator_moment, data.moment_rownnz, data.moment_rowadr,
            data.moment_colind,
        )  # fmt: skip
    return moment


def _equality_jacobian(model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
    """(rows, J): the equality constraints' rows of ``efc_J`` (dense), after
    ``mj_fwdPosition``; rows whose Jacobian is exactly zero (a planar loop's out-of-plane
    row) are left out: they carry no force."""
    nefc, nv = int(data.nefc), int(model.nv)
    if nefc == 0:
        return np.zeros(0, dtype=int), np.zeros((0, nv))
    rows = np.flatnonzero(data.efc_type[:nefc] == _EQUALITY)
    if rows.size == 0:
        return rows, np.zeros((0, nv))
    if mujoco.mj_isSparse(model):
        jac = np.zeros((nefc, nv))
        mujoco.mju_sparse2dense(
            jac, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind
        )
    else:
        jac = data.efc_J[: nefc * nv].reshape(nefc, nv)
    jac = jac[rows]
    keep = jac.any(axis=1)
    return rows[keep], jac[keep]


def _applied(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Generalised forces of ``qfrc_applied`` and ``xfrc_applied`` (nv,)."""
    out = np.array(data.qfrc_applied, dtype=float)
    if data.xfrc_applied.any():
        for b in np.flatnonzero(np.abs(data.xfrc_applied).sum(1)):
            f = np.array(data.xfrc_applied[b, :3])
            m = np.array(data.xfrc_applied[b, 3:])
            mujoco.mj_applyFT(model, data, f, m, np.array(data.xipos[b]), int(b), out)
    return out


class _Plan:
    """What one evaluation reuses of the previous one on the same model: the equality
    rows that carry a force (checked again each time: a row left out must still be zero),
    and the motors' moment arms when their transmissions are joints (constant)."""

    def __init__(self, model: mujoco.MjModel, actuators: np.ndarray) -> None:
        self.model = model
        self.key: bytes = b""
        self.rows = np.zeros(0, dtype=int)
        self.zero = np.zeros(0, dtype=int)  # equality rows left out (exactly zero)
        joints = int(mujoco.mjtTrn.mjTRN_JOINT)
        self.moment: np.ndarray | None = None
        if model.nu and all(int(t) == joints for t in model.actuator_trntype):
            moment = np.zeros((model.nu, model.nv))
            for a in range(model.nu):
                joint = int(model.actuator_trnid[a, 0])
                if int(model.jnt_type[joint]) not in (
                    int(mujoco.mjtJoint.mjJNT_HINGE),
                    int(mujoco.mjtJoint.mjJNT_SLIDE),
                ):
                    break
                moment[a, int(model.jnt_dofadr[joint])] = float(model.actuator_gear[a, 0])
            else:
                self.moment = moment
        self.columns = self.moment[actuators].T.copy() if self.moment is not None else None

    def equality(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """(rows, J) as :func:`_equality_jacobian`, reusing the rows found last time
        while the constraints' layout is the same."""
        nefc, nv = int(data.nefc), int(self.model.nv)
        if nefc == 0 or mujoco.mj_isSparse(self.model):
            return _equality_jacobian(self.model, data)
        types = data.efc_type[:nefc]
        key = types.tobytes()
        full = data.efc_J[: nefc * nv].reshape(nefc, nv)
        if key != self.key or (self.zero.size and full[self.zero].any()):
            rows = np.flatnonzero(types == _EQUALITY)
            nonzero = full[rows].any(axis=1)
            self.rows, self.zero, self.key = rows[nonzero], rows[~nonzero], key
        return self.rows, full[self.rows]


def inverse_dynamics(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    actuators: np.ndarray,
    plan: _Plan | None = None,
) -> float:
    """MuJoCo's derived quantities and every force of a state whose motion is imposed.

    ``data`` holds the positions, speeds and (in ``qacc_warmstart``) the accelerations;
    the motors ``actuators`` provide what the motion takes, the loops' equality
    constraints the rest. Afterwards ``qacc``, ``actuator_force``, ``qfrc_actuator``,
    ``efc_force`` (equality rows; the others 0), ``qfrc_constraint`` and, through
    ``mj_rnePostConstraint``, ``cacc``, ``cfrc_int`` and ``cfrc_ext`` are those of the
    motion, as after ``mj_forward`` and ``mj_rnePostConstraint`` on a simulated state.

    Args:
        model: The model.
        data: The state (positions, speeds, accelerations in ``qacc_warmstart``).
        actuators: Ids of the motors whose forces are unknown (others keep the force of
            their command).
        plan: What the previous evaluation on this model found (:class:`_Plan`: the
            same result, sooner).

    Returns:
        The residual of the solve [N or N·m]: 0 up to round-off when the motors and the
        loops can impose this motion (a large one means a joint nobody drives).
    """
    qacc = data.qacc_warmstart.copy()
    mujoco.mj_fwdPosition(model, data)
    mujoco.mj_fwdVelocity(model, data)
    moment = plan.moment if plan is not None and plan.moment is not None else None
    if moment is None:
        moment = _dense_moment(model, data)
    k = len(actuators)
    others = model.nu > k
    if others:  # other motors keep the force of their command
        mujoco.mj_fwdActuation(model, data)
        force = data.actuator_force.copy()
        force[actuators] = 0.0
    else:
        force = np.zeros(model.nu)
    need = np.empty(model.nv)
    mujoco.mj_mulM(model, data, need, qacc)
    need += data.qfrc_bias
    need -= data.qfrc_passive
    if data.qfrc_applied.any() or data.xfrc_applied.any():
        need -= _applied(model, data)
    if others:
        need -= force @ moment
    rows, jac = plan.equality(data) if plan is not None else _equality_jacobian(model, data)
    system = np.empty((model.nv, k + len(rows)))
    columns = plan.columns if plan is not None else None
    system[:, :k] = columns if columns is not None else moment[actuators].T
    system[:, k:] = jac.T
    x = None
    if system.shape[0] == system.shape[1]:
        try:
            x = np.linalg.solve(system, need)
        except np.linalg.LinAlgError:
            x = None
    if x is None:
        x = np.linalg.lstsq(system, need, rcond=None)[0]
    gap = system @ x
    gap -= need
    residual = float(np.abs(gap).max()) if gap.size else 0.0
    force[actuators] = x[:k]
    data.qacc[:] = qacc
    data.actuator_force[:] = force
    data.qfrc_actuator[:] = force @ moment
    nefc = int(data.nefc)
    if nefc:
        efc = data.efc_force
        efc[:nefc] = 0.0
        efc[rows] = x[k:]
    data.qfrc_constraint[:] = x[k:] @ jac
    mujoco.mj_rnePostConstraint(model, data)
    return residual


class ImposedMotion:
    """One simulation's imposed motion: its law, where it starts, and its evaluation.

    Args:
        spec: What the scene declares.
        model: The compiled model (its joint and actuator addresses are looked up).
    """

    def __init__(self, spec: Imposed, model: mujoco.MjModel) -> None:
        self.spec = spec
        self.residual = 0.0
        self.bind(model)

    def bind(self, model: mujoco.MjModel) -> None:
        """Look up the input joint's and the motor's addresses in ``model`` (a rebuilt
        model may place them elsewhere)."""
        joint = model.joint(self.spec.joint).id
        self._qpos = int(model.jnt_qposadr[joint])
        self._dof = int(model.jnt_dofadr[joint])
        motor = model.actuator(self.spec.actuator).id
        self.actuators = np.array([motor], dtype=int)
        self._plan = _Plan(model, self.actuators)
        self._act = int(model.actuator_actadr[motor]) if model.na else -1
        self._slot = self.spec.slot
        if model.nuserdata < self._slot + ANCHOR_SLOTS:
            raise ValueError(
                f"the model has {model.nuserdata} userdata numbers; the imposed motion's anchor "
                f"needs {self._slot + ANCHOR_SLOTS} (sandbox.physics.model.build reserves them)"
            )

    def input(self, data: mujoco.MjData) -> tuple[float, float]:
        """The input joint's (position, speed) in ``data``."""
        return float(data.qpos[self._qpos]), float(data.qvel[self._dof])

    def start(self, data: mujoco.MjData, anchor: Anchor | None = None) -> None:
        """Anchor the law at ``data``'s time, input position and speed (a reset, a switch
        from the free simulation, a new set point), or at ``anchor``: nothing jumps but
        what the law itself changes (a speed step of the course's constant ω). The anchor
        is kept in ``data``'s ``userdata``."""
        if anchor is None:
            anchor = Anchor(float(data.time), *self.input(data))
        s = self._slot
        data.userdata[s : s + ANCHOR_SLOTS] = (anchor.time, anchor.position, anchor.speed)

    def anchor(self, data: mujoco.MjData) -> Anchor:
        """The law's anchor kept in ``data``."""
        s = self._slot
        return Anchor(*(float(x) for x in data.userdata[s : s + ANCHOR_SLOTS]))

    def motion(self, values: Values, data: mujoco.MjData, t: float) -> Motion:
        """The input's (position, speed, acceleration) at time ``t``, by the law anchored
        in ``data``."""
        return self.spec.law(values, self.anchor(data), t)

    def put(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        values: Values,
        t: float,
        *,
        forces: bool = True,
    ) -> None:
        """The exact state at time ``t`` in ``data``, with every force (see
        :func:`inverse_dynamics`; ``forces`` False: the bodies' poses only)."""
        motion = self.motion(values, data, t)
        data.time = t
        if forces:
            self.place(model, data, values, motion)
            return
        self.spec.place(model, data, values, motion)
        if self._act >= 0:
            data.act[self._act] = motion[1]
        mujoco.mj_kinematics(model, data)

    def place(
        self, model: mujoco.MjModel, data: mujoco.MjData, values: Values, motion: Motion
    ) -> None:
        """The mechanism at the input's ``motion`` (position, speed, acceleration), with
        every force: the closure, then inverse dynamics (a filtered set point's state
        follows the speed, so that the free simulation takes over without a jump)."""
        self.spec.place(model, data, values, motion)
        if self._act >= 0:
            data.act[self._act] = motion[1]
        self.forces(model, data, values)

    def forces(
        self, model: mujoco.MjModel, data: mujoco.MjData, values: Values | None = None
    ) -> None:
        """Derived quantities and forces of the state in ``data`` (its acceleration in
        ``qacc_warmstart``); with ``values``, the input joint's dry friction
        (:attr:`Imposed.friction`) on top."""
        plan = self._plan if self._plan.model is model else None
        self.residual = inverse_dynamics(model, data, self.actuators, plan)
        if self.spec.friction is not None and values is not None:
            self._friction(model, data, self.spec.friction(model, data, values))

    def _friction(self, model: mujoco.MjModel, data: mujoco.MjData, friction: float) -> None:
        """Add a dry friction ``friction`` opposing the input's speed: a pure torque (or
        force) on the input joint, which the motor, acting on that joint alone, gives on
        top of what inverse dynamics found; the loops' forces and every other reaction
        stay as they were (the solve is linear and the motor's column is that joint's)."""
        speed = float(data.qvel[self._dof])
        if friction <= 0.0 or speed == 0.0:
            return
        torque = math.copysign(friction, speed)
        motor = int(self.actuators[0])
        gear = float(model.actuator_gear[motor, 0]) or 1.0
        data.actuator_force[motor] += torque / gear
        data.qfrc_actuator[self._dof] += torque
        data.qfrc_constraint[self._dof] -= torque
