"""The plain bearings of a scene (course, appendix B.2, « du global au local »): the
parameters every scene with bearings shares (the bore's radius R and length L, the
pressure hypothesis, the friction coefficient f) and, for each bearing the scene declares
(:class:`~sandbox.physics.page.Bearing`), two readouts: the largest contact pressure
``bearing_<name>_pmax`` and the friction torque ``bearing_<name>_Cf`` of the chosen
hypothesis, both from the live radial load.

The radial load is the frame's force on the shaft without its component along the bore's
axis: a plain bearing carries the radial part, a shoulder or a thrust washer the axial
part (none of these scenes has one).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import mujoco
import numpy as np

from sandbox.mechanics.two_planes import split_across_axis
from sandbox.physics import isolate
from sandbox.physics.bearings import (
    FRICTION_WORDS,
    HYPOTHESIS_WORDS,
    MM,
    friction_on,
    friction_torque,
    max_pressure,
    radial_load,
)
from sandbox.physics.page import Bearing
from sandbox.physics.scratch import scratch_data
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import Effects, Param, SceneReadout, Values

GROUP = "Paliers"


def friction_param(group: str = GROUP) -> Param:
    """« Paliers avec frottement »: the friction torque applied in the simulation itself
    (a rebuild switches MuJoCo's dry friction on; off by default, the course's perfect
    joints)."""
    return Param(
        "bearing_friction", "", 0.0, 0.0, 1.0,
        "1: the bearings' friction torque (hypothesis 3, or 2's with the cosine) opposes "
        "the rotation in the simulation, from the live load; 0: perfect joints.",
        step=1.0, label="Paliers avec frottement",
        hint="Applique dans la simulation le couple de frottement des paliers, calculé à "
        "chaque pas depuis leur charge : Pᵢₙₜ devient négative et le moteur fournit Cf de "
        "plus.",
        group=group, choices=FRICTION_WORDS, advanced=True,
    )  # fmt: skip


def with_friction(base: Effects) -> tuple[Effects, Callable[[Values], Effects]]:
    """A scene's effects with the bearings' dry friction: (every effect it may call for,
    the effects at given values: MuJoCo's joint friction only while it is on)."""
    union = dataclasses.replace(base, joint_friction=True)
    return union, lambda v: dataclasses.replace(base, joint_friction=friction_on(v))


def params(radius: float, length: float, group: str = GROUP) -> tuple[Param, ...]:
    """The bearing parameters of a scene whose bores are ``radius`` and ``length`` [m]
    by default, typed in mm (advanced: they change no motion, only the pressure and
    torque read), in ``group`` (a scene with many groups already puts them in one of its
    own)."""
    return (
        Param(
            "bearing_R", "mm", radius / MM, 2.0, 200.0,
            "Radius R of the plain bearings' bore (the shaft's radius), in millimetres.",
            live=True, step=0.5, label="Rayon du palier R",
            hint="Rayon de l'alésage des paliers lisses, celui de l'arbre qui y tourne.",
            group=group, advanced=True,
        ),
        Param(
            "bearing_L", "mm", length / MM, 2.0, 500.0,
            "Length L of the plain bearings' bore, in millimetres.",
            live=True, step=0.5, label="Longueur du palier L",
            hint="Longueur de l'alésage des paliers, le long de l'arbre : plus il est long, "
            "plus la charge s'étale et plus la pression baisse.",
            group=group, advanced=True,
        ),
        Param(
            "bearing_model", "", 0.0, 0.0, 2.0,
            "Pressure distribution in the bearings: 0 uniform (hypothesis 1), 1 cosine "
            "(hypothesis 2), 2 uniform with Coulomb friction f (hypothesis 3).",
            live=True, step=1.0, label="Hypothèse de pression dans les paliers",
            hint="Comment la pression de contact se répartit sur la moitié chargée de "
            "l'alésage : uniforme, en cosinus, ou uniforme avec du frottement.",
            group=group, advanced=True, choices=HYPOTHESIS_WORDS,
        ),
        Param(
            "bearing_f", "", 0.1, 0.0, 1.0,
            "Coulomb friction coefficient f between shaft and bore (hypothesis 3).",
            live=True, step=0.01, label="Coefficient de frottement du palier f",
            hint="Coefficient de frottement entre l'arbre et l'alésage, utilisé par "
            "l'hypothèse 3 (bronze graissé sur acier : environ 0,1).",
            group=group, advanced=True,
        ),
    )  # fmt: skip


def _pmax(b: Bearing) -> Callable[[Snapshot], float]:
    def fn(s: Snapshot) -> float:
        return max_pressure(float(np.linalg.norm(radial_load(b, s))), s.values)

    return fn


def _cf(b: Bearing) -> Callable[[Snapshot], float]:
    def fn(s: Snapshot) -> float:
        return friction_torque(float(np.linalg.norm(radial_load(b, s))), s.values)

    return fn


def readouts(bearings: tuple[Bearing, ...]) -> tuple[SceneReadout, ...]:
    """``bearing_<name>_pmax`` [Pa] and ``bearing_<name>_Cf`` [N·m] of each bearing."""
    out: list[SceneReadout] = []
    for b in bearings:
        out += [
            SceneReadout(
                f"bearing_{b.name}_pmax", "Pa",
                f"Largest contact pressure in bearing {b.name} under its radial load, for "
                "the chosen hypothesis (bearing_model): F/(2RL) uniform, 2F/(πRL) cosine.",
                _pmax(b),
                label=f"Pression maximale au palier {b.name}",
                hint=f"Plus grande pression de contact entre l'arbre et l'alésage du palier "
                f"{b.name}, selon l'hypothèse choisie : elle doit rester sous 200 bar.",
            ),
            SceneReadout(
                f"bearing_{b.name}_Cf", "N·m",
                f"Friction torque in bearing {b.name} (hypothesis 3: (π/2) f R F; 0 under "
                "hypotheses 1 and 2, without friction).",
                _cf(b),
                label=f"Couple de frottement au palier {b.name}",
                hint=f"Couple résistant du frottement dans le palier {b.name} avec "
                "l'hypothèse 3, Cf = (π/2)·f·R·F ; nul sans frottement (hypothèses 1 et 2).",
            ),
        ]  # fmt: skip
    return tuple(out)


def pivot_action(s: Snapshot, body: str) -> tuple[np.ndarray, np.ndarray]:
    """The frame's action on ``body`` through its pivot: resultant [N] and moment at the
    origin O [N·m], world axes (the motor's torque apart, as « Isoler un solide » shows
    it); cached a snapshot."""
    key = f"pivot_{body}"
    if key not in s.cache:
        joint = isolate.joint_action(s.model, s.data, s.body_id(body))
        s.cache[key] = (joint.resultant, joint.moment)
    r, m = s.cache[key]
    return np.asarray(r), np.asarray(m)


def two_bearings(
    s: Snapshot, body: str, a: np.ndarray, b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The frame's forces on ``body`` at two bearings at ``a`` and ``b`` [m] on its axis,
    from its pivot's action (isostatic: a ball joint at A, an annular joint at B)."""
    key = f"pivot_{body}_split"
    if key not in s.cache:
        s.cache[key] = split_across_axis(*pivot_action(s, body), a, b)
    f_a, f_b = s.cache[key]
    return np.asarray(f_a), np.asarray(f_b)


def friction_control(
    declared: tuple[Bearing, ...],
    joint: str,
    motor: str,
    set_point: Callable[[Values], float],
) -> Callable[[mujoco.MjModel, mujoco.MjData, Values], None]:
    """A per-step control that sets the dry friction of ``joint`` (MuJoCo's
    ``frictionloss``, a constraint whose force is −C_f sign(ω) while it turns: P_int
    = −C_f |ω|) to the bearings' friction torque under their load at the current state
    (a pure function of it: positions, speeds, command); 0 while the friction is off.

    The velocity servo ``motor`` (force kv (u − ω)) then gets the command
    ``set_point(values) + C_f / kv``: it gives the friction torque on top of what it gave,
    as the course's motor does, instead of losing C_f / kv of speed to it."""

    def control(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
        dof = int(model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)])
        if not friction_on(values):
            model.dof_frictionloss[dof] = 0.0
            return
        here = scratch_data(model)
        here.time = data.time
        here.qpos[:] = data.qpos
        here.qvel[:] = data.qvel
        here.act[:] = data.act
        here.ctrl[:] = data.ctrl
        mujoco.mj_forward(model, here)
        mujoco.mj_rnePostConstraint(model, here)
        torque = _friction_at(declared, Snapshot(model, here, values), values)
        model.dof_frictionloss[dof] = torque
        act = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, motor)
        kv = float(model.actuator_gainprm[act, 0])
        data.ctrl[act] = set_point(values) + (torque / kv if kv > 0 else 0.0)

    return control


def _friction_at(declared: tuple[Bearing, ...], snap: Snapshot, values: Values) -> float:
    """The bearings' total friction torque [N·m] under their loads at ``snap``."""
    return float(
        sum(friction_torque(float(np.linalg.norm(radial_load(b, snap))), values) for b in declared)
    )


def imposed_friction(
    declared: tuple[Bearing, ...],
) -> Callable[[mujoco.MjModel, mujoco.MjData, Values], float]:
    """The bearings' friction torque for an imposed motion (:attr:`Imposed.friction`): at
    the state inverse dynamics just solved, from the bearings' loads (which the friction,
    a torque about the shaft, does not change); 0 while the friction is off."""

    def friction(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> float:
        if not friction_on(values):
            return 0.0
        return _friction_at(declared, Snapshot(model, data, values), values)

    return friction
