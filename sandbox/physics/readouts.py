"""Generic readouts for any MJCF model: energy, powers and torsors of the mechanism.

Pure functions of (model, data). Everything is at the world origin O, on the world axes,
relative to the world frame R0 (Galilean). The *mechanism* is every body not welded to
the world (``model.body_weldid != 0``).

Call :func:`prepare` once at the current state (after ``mj_step`` MuJoCo's derived
quantities belong to the state *before* the step), then :func:`compute`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import mujoco
import numpy as np

Pair = tuple[np.ndarray, np.ndarray]


@dataclass(frozen=True)
class ReadoutInfo:
    """Name, unit and one-line doc of a generic readout."""

    name: str
    unit: str
    doc: str


def _torsor_infos(prefix: str, what: str, ru: str, mu: str) -> list[ReadoutInfo]:
    out = [ReadoutInfo(f"{prefix}_R_{c}", ru, f"{what}: resultant, {c} component") for c in "xyz"]
    out += [
        ReadoutInfo(f"{prefix}_M_{c}", mu, f"{what}: moment at O, {c} component") for c in "xyz"
    ]
    return out


GENERIC_READOUTS: tuple[ReadoutInfo, ...] = (
    ReadoutInfo("time", "s", "Simulated time."),
    ReadoutInfo("T", "J", "Kinetic energy of the mechanism in R0."),
    ReadoutInfo("V", "J", "Potential energy of weight and joint springs."),
    ReadoutInfo("P_ext", "W", "Power of weight, motors and applied loads."),
    ReadoutInfo("P_int", "W", "Power of inter-efforts, non-perfect joints and contacts."),
    ReadoutInfo("P_acc", "W", "Power of the accelerations, equal to dT/dt."),
    *_torsor_infos("kin", "Kinetic torsor {C}", "kg·m/s", "kg·m²/s"),
    *_torsor_infos("dyn", "Dynamic torsor {D}", "N", "N·m"),
    *_torsor_infos("sup", "Action of the frame on the mechanism", "N", "N·m"),
)
GENERIC_NAMES: tuple[str, ...] = tuple(r.name for r in GENERIC_READOUTS)
_NEEDS_RNE = ("dyn_", "sup_", "P_acc")


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a ∧ b on the last axis, for (3,) or (n, 3) arrays (cheaper than np.cross)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        a, b = np.broadcast_arrays(a, b)
    out = np.empty(a.shape)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def mechanism_bodies(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the bodies not welded to the world."""
    return np.flatnonzero(model.body_weldid != 0)


def _gravity(model: mujoco.MjModel) -> np.ndarray:
    if model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY:
        return np.zeros(3)
    return np.array(model.opt.gravity)


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
        return a + _gravity(self.model)

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


def _kin(model: mujoco.MjModel, data: mujoco.MjData, kin: Kinematics | None) -> Kinematics:
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


def _select(k: Kinematics, bodies: Iterable[int] | None) -> np.ndarray:
    return k.bodies if bodies is None else np.asarray(list(bodies), dtype=int)


def kinetic_torsor(
    model: mujoco.MjModel, data: mujoco.MjData, bodies=None, *, kin: Kinematics | None = None
) -> Pair:
    """{C} at O: (Σ m v_G, Σ I_G ω + OG ∧ m v_G)."""
    k = _kin(model, data, kin)
    b = _select(k, bodies)
    p = model.body_mass[b][:, None] * k.v_g[b]
    return p.sum(0), (k.i_omega[b] + _cross(data.xipos[b], p)).sum(0)


def dynamic_torsor(
    model: mujoco.MjModel, data: mujoco.MjData, bodies=None, *, kin: Kinematics | None = None
) -> Pair:
    """{D} at O: (Σ m a_G, Σ I_G α + ω ∧ I_G ω + OG ∧ m a_G)."""
    k = _kin(model, data, kin)
    b = _select(k, bodies)
    ma = model.body_mass[b][:, None] * k.a_g[b]
    return ma.sum(0), (k.delta_g[b] + _cross(data.xipos[b], ma)).sum(0)


def gravity_torsor(model: mujoco.MjModel, data: mujoco.MjData, bodies=None) -> Pair:
    """Weight of the mechanism at O (zero when weight is neglected)."""
    b = mechanism_bodies(model) if bodies is None else np.asarray(list(bodies), dtype=int)
    w = model.body_mass[b][:, None] * _gravity(model)
    return w.sum(0), _cross(data.xipos[b], w).sum(0)


def _frame_children(model: mujoco.MjModel) -> np.ndarray:
    """Mechanism bodies whose parent is welded to the world (they touch the frame)."""
    b = mechanism_bodies(model)
    return b[model.body_weldid[model.body_parentid[b]] == 0]


def _dof_wrenches(
    model: mujoco.MjModel, data: mujoco.MjData, force: np.ndarray, bodies: np.ndarray
) -> Pair:
    """Wrench at O of generalised forces ``force`` (nv,) in the joints of ``bodies``."""
    r, m = np.zeros(3), np.zeros(3)
    for body in bodies:
        for j in range(model.body_jntadr[body], model.body_jntadr[body] + model.body_jntnum[body]):
            kind, dof = model.jnt_type[j], model.jnt_dofadr[j]
            rot = data.xmat[body].reshape(3, 3)
            if kind == mujoco.mjtJoint.mjJNT_HINGE:
                m += force[dof] * data.xaxis[j]
            elif kind == mujoco.mjtJoint.mjJNT_SLIDE:
                f = force[dof] * data.xaxis[j]
                r += f
                m += _cross(data.xanchor[j], f)
            elif kind == mujoco.mjtJoint.mjJNT_BALL:
                m += rot @ force[dof : dof + 3]
            else:  # free: world-axis force at the body origin, body-axis torque
                f = force[dof : dof + 3]
                r += f
                m += _cross(data.xpos[body], f) + rot @ force[dof + 3 : dof + 6]
    return r, m


def joint_drive(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Generalised forces that motors and qfrc_applied pass on to the bodies (nv,).

    A joint's armature models a motor rotor spinning with it: its inertial torque
    armature·q̈ stays inside the motor, so the bodies receive the rest.
    """
    return data.qfrc_actuator + data.qfrc_applied - model.dof_armature * data.qacc


def actuator_torsor(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """Motors (and qfrc_applied) acting in joints between the frame and the mechanism."""
    return _dof_wrenches(model, data, joint_drive(model, data), _frame_children(model))


def applied_torsor(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """xfrc_applied (force at G, torque) on mechanism bodies, at O."""
    b = mechanism_bodies(model)
    f = data.xfrc_applied[b, :3]
    return f.sum(0), (data.xfrc_applied[b, 3:] + _cross(data.xipos[b], f)).sum(0)


def _spatial_at_origin(
    model: mujoco.MjModel, data: mujoco.MjData, body: int, wrench: np.ndarray
) -> Pair:
    """Com-based spatial force [torque at c; force] of ``body`` reduced at O."""
    c = data.subtree_com[model.body_rootid[body]]
    return wrench[3:].copy(), wrench[:3] + _cross(c, wrench[3:])


def support_torsor(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """Action of the frame on the mechanism at O: joints, contacts, equality constraints.

    Joints: ``cfrc_int`` of each body hanging from the frame is the wrench its parent
    transmits, motors and qfrc_applied included, so those are removed. Contacts and
    connect/weld constraints: MuJoCo gathers their forces with ``xfrc_applied`` in
    ``cfrc_ext``; summed over the mechanism, the pairs between two moving bodies cancel
    (mutual actions), leaving the frame's share. Requires mj_rnePostConstraint.
    """
    children = _frame_children(model)
    jointed = children[model.body_jntnum[children] > 0]
    mech = mechanism_bodies(model)
    bodies = np.concatenate([jointed, mech])
    wrench = np.concatenate([data.cfrc_int[jointed], data.cfrc_ext[mech]])
    c = data.subtree_com[model.body_rootid[bodies]]
    r = wrench[:, 3:].sum(0)
    m = (wrench[:, :3] + _cross(c, wrench[:, 3:])).sum(0)
    ar, am = _dof_wrenches(model, data, joint_drive(model, data), children)
    xr, xm = applied_torsor(model, data)
    return r - ar - xr, m - am - xm


def kinetic_energy(
    model: mujoco.MjModel, data: mujoco.MjData, bodies=None, *, kin: Kinematics | None = None
) -> float:
    """T = Σ ½ m v_G² + ½ ω·I_G ω, plus ½ Σ armature q̇² (motor rotors, whole mechanism)."""
    k = _kin(model, data, kin)
    b = _select(k, bodies)
    v = k.v_g[b]
    t = 0.5 * (model.body_mass[b] * (v * v).sum(1)).sum() + 0.5 * (k.i_omega[b] * k.omega[b]).sum()
    if bodies is None:
        t += 0.5 * float(model.dof_armature @ (data.qvel * data.qvel))
    return float(t)


def potential_energy(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Weight (−Σ m g·OG) plus hinge and slide joint springs ½ k (q − q_ref)²."""
    b = mechanism_bodies(model)
    v = -float((model.body_mass[b] * (data.xipos[b] @ _gravity(model))).sum())
    if not model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_SPRING:
        for j in np.flatnonzero(model.jnt_stiffness > 0):
            if int(model.jnt_type[j]) in (
                int(mujoco.mjtJoint.mjJNT_HINGE),
                int(mujoco.mjtJoint.mjJNT_SLIDE),
            ):
                a = model.jnt_qposadr[j]
                v += (
                    0.5
                    * float(model.jnt_stiffness[j])
                    * float(data.qpos[a] - model.qpos_spring[a]) ** 2
                )
    return v


def powers(
    model: mujoco.MjModel, data: mujoco.MjData, *, kin: Kinematics | None = None
) -> dict[str, float]:
    """P_ext and P_int [W] (see the module and README for the split)."""
    k = _kin(model, data, kin)
    b = k.bodies
    qv = data.qvel
    p_grav = float((model.body_mass[b] * (k.v_g[b] @ _gravity(model))).sum())
    xf = data.xfrc_applied[b]
    p_xfrc = float((xf[:, :3] * k.v_g[b]).sum() + (xf[:, 3:] * k.omega[b]).sum())
    p_ext = (
        p_grav + p_xfrc + float(qv @ (data.qfrc_actuator + data.qfrc_applied + data.qfrc_gravcomp))
    )
    p_int = float(qv @ (data.qfrc_passive - data.qfrc_gravcomp + data.qfrc_constraint))
    return {"P_ext": p_ext, "P_int": p_int}


def acceleration_power(
    model: mujoco.MjModel, data: mujoco.MjData, *, kin: Kinematics | None = None
) -> float:
    """P_acc = Σ {D_i}⊗{V_i} = Σ m a_G·v_G + (I_G α + ω ∧ I_G ω)·ω, plus the motor
    rotors' Σ armature q̇ q̈ (so that P_acc = dT/dt with T as above)."""
    k = _kin(model, data, kin)
    b = k.bodies
    return float(
        (model.body_mass[b] * (k.a_g[b] * k.v_g[b]).sum(1)).sum()
        + (k.delta_g[b] * k.omega[b]).sum()
        + model.dof_armature @ (data.qvel * data.qacc)
    )


_TORSORS = {"kin": kinetic_torsor, "dyn": dynamic_torsor, "sup": support_torsor}


def torsor(
    model: mujoco.MjModel, data: mujoco.MjData, prefix: str, cache: dict[str, Any] | None = None
) -> Pair:
    """The mechanism's torsor ``prefix`` ("kin", "dyn" or "sup") at O, memoised in cache."""
    if cache is not None and prefix in cache:
        return cache[prefix]
    fn = _TORSORS[prefix]
    value = (
        fn(model, data) if prefix == "sup" else fn(model, data, kin=_cached_kin(model, data, cache))
    )
    if cache is not None:
        cache[prefix] = value
    return value


def _cached_kin(
    model: mujoco.MjModel, data: mujoco.MjData, cache: dict[str, Any] | None
) -> Kinematics:
    if cache is None:
        return Kinematics(model, data)
    kin = cache.get("_kin")
    if kin is None:
        kin = cache["_kin"] = Kinematics(model, data)
    return kin


def prepare(model: mujoco.MjModel, data: mujoco.MjData, names: Iterable[str]) -> None:
    """Bring ``data`` up to date at its current state for the readouts ``names``."""
    mujoco.mj_forward(model, data)
    if any(n.startswith(_NEEDS_RNE) for n in names):
        mujoco.mj_rnePostConstraint(model, data)


def compute(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    names: Iterable[str],
    cache: dict[str, Any] | None = None,
) -> dict[str, float]:
    """Values of the generic readouts ``names`` (after :func:`prepare`); only those asked.

    ``cache`` (prefix -> torsor) lets several consumers share one torsor computation.
    """
    names = list(names)
    unknown = [n for n in names if n not in GENERIC_NAMES]
    if unknown:
        raise KeyError(f"unknown readout {unknown[0]!r}; valid: {', '.join(GENERIC_NAMES)}")
    out: dict[str, float] = {}
    for prefix in _TORSORS:
        if any(n.startswith(prefix + "_") for n in names):
            r, m = torsor(model, data, prefix, cache)
            for i, c in enumerate("xyz"):
                out[f"{prefix}_R_{c}"], out[f"{prefix}_M_{c}"] = float(r[i]), float(m[i])
    if "time" in names:
        out["time"] = float(data.time)
    kin = _cached_kin(model, data, cache)
    if "T" in names:
        out["T"] = kinetic_energy(model, data, kin=kin)
    if "V" in names:
        out["V"] = potential_energy(model, data)
    if "P_ext" in names or "P_int" in names:
        out.update(powers(model, data, kin=kin))
    if "P_acc" in names:
        out["P_acc"] = acceleration_power(model, data, kin=kin)
    return {n: out[n] for n in names}
