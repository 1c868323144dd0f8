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
    """a ∧ b on the last axis (much cheaper than np.cross for small arrays)."""
    a, b = np.broadcast_arrays(a, b)
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        axis=-1,
    )


def mechanism_bodies(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the bodies not welded to the world."""
    return np.flatnonzero(model.body_weldid != 0)


def _inertia_world(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """I_G of every body in world axes, shape (nbody, 3, 3)."""
    rot = data.ximat.reshape(-1, 3, 3)
    return np.einsum("bij,bj,bkj->bik", rot, model.body_inertia, rot)


def body_velocities(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """(v_G, ω) of every body's centre of mass in R0, each (nbody, 3), world axes."""
    omega = data.cvel[:, :3]
    c = data.subtree_com[model.body_rootid]
    v_g = data.cvel[:, 3:] + _cross(omega, data.xipos - c)
    return v_g, omega


def _gravity(model: mujoco.MjModel) -> np.ndarray:
    if model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY:
        return np.zeros(3)
    return np.array(model.opt.gravity)


def body_accelerations(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """(a_G, α): true accelerations of every centre of mass, after mj_rnePostConstraint.

    MuJoCo's ``cacc`` is a spatial acceleration that includes −g (like an accelerometer);
    the classical acceleration of G is cacc_lin + α ∧ (G − c) + ω ∧ v_G, plus g.
    """
    v_g, omega = body_velocities(model, data)
    alpha = data.cacc[:, :3]
    c = data.subtree_com[model.body_rootid]
    a_g = data.cacc[:, 3:] + _cross(alpha, data.xipos - c) + _cross(omega, v_g)
    return a_g + _gravity(model), alpha


def _select(model: mujoco.MjModel, bodies: Iterable[int] | None) -> np.ndarray:
    return mechanism_bodies(model) if bodies is None else np.asarray(list(bodies), dtype=int)


def kinetic_torsor(model: mujoco.MjModel, data: mujoco.MjData, bodies=None) -> Pair:
    """{C} at O: (Σ m v_G, Σ I_G ω + OG ∧ m v_G)."""
    b = _select(model, bodies)
    v_g, omega = body_velocities(model, data)
    m = model.body_mass[b][:, None]
    p = m * v_g[b]
    sigma = np.einsum("bij,bj->bi", _inertia_world(model, data)[b], omega[b])
    return p.sum(0), (sigma + _cross(data.xipos[b], p)).sum(0)


def dynamic_torsor(model: mujoco.MjModel, data: mujoco.MjData, bodies=None) -> Pair:
    """{D} at O: (Σ m a_G, Σ I_G α + ω ∧ I_G ω + OG ∧ m a_G)."""
    b = _select(model, bodies)
    a_g, alpha = body_accelerations(model, data)
    _, omega = body_velocities(model, data)
    inertia = _inertia_world(model, data)[b]
    m = model.body_mass[b][:, None]
    ma = m * a_g[b]
    iw = np.einsum("bij,bj->bi", inertia, omega[b])
    delta = np.einsum("bij,bj->bi", inertia, alpha[b]) + _cross(omega[b], iw)
    return ma.sum(0), (delta + _cross(data.xipos[b], ma)).sum(0)


def gravity_torsor(model: mujoco.MjModel, data: mujoco.MjData, bodies=None) -> Pair:
    """Weight of the mechanism at O (zero when weight is neglected)."""
    b = _select(model, bodies)
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


def actuator_torsor(model: mujoco.MjModel, data: mujoco.MjData) -> Pair:
    """Motors (and qfrc_applied) acting in joints between the frame and the mechanism."""
    return _dof_wrenches(
        model, data, data.qfrc_actuator + data.qfrc_applied, _frame_children(model)
    )


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
    r, m = np.zeros(3), np.zeros(3)
    children = _frame_children(model)
    for body in children:
        if model.body_jntnum[body]:
            dr, dm = _spatial_at_origin(model, data, body, data.cfrc_int[body])
            r, m = r + dr, m + dm
    for body in mechanism_bodies(model):
        dr, dm = _spatial_at_origin(model, data, body, data.cfrc_ext[body])
        r, m = r + dr, m + dm
    ar, am = _dof_wrenches(model, data, data.qfrc_actuator + data.qfrc_applied, children)
    xr, xm = applied_torsor(model, data)
    return r - ar - xr, m - am - xm


def kinetic_energy(model: mujoco.MjModel, data: mujoco.MjData, bodies=None) -> float:
    """T = Σ ½ m v_G² + ½ ω·I_G ω (armature, a joint property, is not counted)."""
    b = _select(model, bodies)
    v_g, omega = body_velocities(model, data)
    iw = np.einsum("bij,bj->bi", _inertia_world(model, data)[b], omega[b])
    return float(
        0.5 * (model.body_mass[b] * (v_g[b] ** 2).sum(1)).sum() + 0.5 * (iw * omega[b]).sum()
    )


def potential_energy(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Weight (−Σ m g·OG) plus hinge and slide joint springs ½ k (q − q_ref)²."""
    b = mechanism_bodies(model)
    v = -float((model.body_mass[b] * (data.xipos[b] @ _gravity(model))).sum())
    if not model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_SPRING:
        for j in np.flatnonzero(model.jnt_stiffness > 0):
            if model.jnt_type[j] in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                a = model.jnt_qposadr[j]
                v += 0.5 * model.jnt_stiffness[j] * (data.qpos[a] - model.qpos_spring[a]) ** 2
    return v


def powers(model: mujoco.MjModel, data: mujoco.MjData) -> dict[str, float]:
    """P_ext and P_int [W] (see the module and README for the split)."""
    b = mechanism_bodies(model)
    v_g, omega = body_velocities(model, data)
    qv = data.qvel
    p_grav = float((model.body_mass[b] * (v_g[b] @ _gravity(model))).sum())
    xf = data.xfrc_applied[b]
    p_xfrc = float((xf[:, :3] * v_g[b]).sum() + (xf[:, 3:] * omega[b]).sum())
    p_ext = (
        p_grav + p_xfrc + float(qv @ (data.qfrc_actuator + data.qfrc_applied + data.qfrc_gravcomp))
    )
    p_int = float(qv @ (data.qfrc_passive - data.qfrc_gravcomp + data.qfrc_constraint))
    return {"P_ext": p_ext, "P_int": p_int}


def acceleration_power(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """P_acc = Σ {D_i}⊗{V_i} = Σ m a_G·v_G + (I_G α + ω ∧ I_G ω)·ω."""
    b = mechanism_bodies(model)
    a_g, alpha = body_accelerations(model, data)
    v_g, omega = body_velocities(model, data)
    inertia = _inertia_world(model, data)[b]
    delta = np.einsum("bij,bj->bi", inertia, alpha[b]) + _cross(
        omega[b], np.einsum("bij,bj->bi", inertia, omega[b])
    )
    return float((model.body_mass[b] * (a_g[b] * v_g[b]).sum(1)).sum() + (delta * omega[b]).sum())


_TORSORS = {"kin": kinetic_torsor, "dyn": dynamic_torsor, "sup": support_torsor}


def torsor(
    model: mujoco.MjModel, data: mujoco.MjData, prefix: str, cache: dict[str, Pair] | None = None
) -> Pair:
    """The mechanism's torsor ``prefix`` ("kin", "dyn" or "sup") at O, memoised in cache."""
    if cache is not None and prefix in cache:
        return cache[prefix]
    value = _TORSORS[prefix](model, data)
    if cache is not None:
        cache[prefix] = value
    return value


def prepare(model: mujoco.MjModel, data: mujoco.MjData, names: Iterable[str]) -> None:
    """Bring ``data`` up to date at its current state for the readouts ``names``."""
    mujoco.mj_forward(model, data)
    if any(n.startswith(_NEEDS_RNE) for n in names):
        mujoco.mj_rnePostConstraint(model, data)


def compute(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    names: Iterable[str],
    cache: dict[str, Pair] | None = None,
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
    if "T" in names:
        out["T"] = kinetic_energy(model, data)
    if "V" in names:
        out["V"] = potential_energy(model, data)
    if "P_ext" in names or "P_int" in names:
        out.update(powers(model, data))
    if "P_acc" in names:
        out["P_acc"] = acceleration_power(model, data)
    return {n: out[n] for n in names}
