"""Generic readouts for any MJCF model: energy, powers and torsors of the mechanism.

Pure functions of (model, data). Everything is at the world origin O, on the world axes,
relative to the world frame R0 (Galilean). The *mechanism* is every body not welded to
the world (``model.body_weldid != 0``).

Call :func:`prepare` once at the current state (after ``mj_step`` MuJoCo's derived
quantities belong to the state *before* the step), then :func:`compute`.
"""

from __future__ import annotations

import weakref
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import mujoco
import numpy as np

from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.units import display_unit

Pair = tuple[np.ndarray, np.ndarray]


@dataclass(frozen=True)
class ReadoutInfo:
    """Name, unit and one-line doc of a readout; ``label`` and ``hint``: the French words
    (with the course's symbol) and tooltip of the web page ("": the name and the doc)."""

    name: str
    unit: str
    doc: str
    label: str = ""
    hint: str = ""

    @property
    def display_unit(self) -> str:
        """The unit as the web page shows it ("tr/min" for "rpm", "°" for "deg")."""
        return display_unit(self.unit)


AXES = {"x": "x₀", "y": "y₀", "z": "z₀"}
"""The world axes as the course writes them (basis B0 of R0)."""


def _torsor_infos(
    prefix: str, what: str, ru: str, mu: str, words: tuple[str, str, str, str]
) -> list[ReadoutInfo]:
    """Six components of a torsor at O; ``words``: French (resultant label, resultant
    hint, moment label, moment hint), each with ``{axis}`` for the axis."""
    rl, rh, ml, mh = words
    out = [
        ReadoutInfo(
            f"{prefix}_R_{c}",
            ru,
            f"{what}: resultant, {c} component",
            rl.format(axis=AXES[c]),
            rh.format(axis=AXES[c]),
        )
        for c in "xyz"
    ]
    out += [
        ReadoutInfo(
            f"{prefix}_M_{c}",
            mu,
            f"{what}: moment at O, {c} component",
            ml.format(axis=AXES[c]),
            mh.format(axis=AXES[c]),
        )
        for c in "xyz"
    ]
    return out


GENERIC_READOUTS: tuple[ReadoutInfo, ...] = (
    ReadoutInfo("time", "s", "Simulated time.", "Temps t", "Temps simulé écoulé depuis le départ."),
    ReadoutInfo(
        "T",
        "J",
        "Kinetic energy of the mechanism in R0.",
        "Énergie cinétique T",
        "Énergie cinétique de l'ensemble des pièces mobiles dans leur mouvement par rapport "
        "au bâti (repère R₀, supposé galiléen).",
    ),
    ReadoutInfo(
        "V",
        "J",
        "Potential energy of weight and joint springs.",
        "Énergie potentielle V",
        "Énergie potentielle de la pesanteur et des ressorts des liaisons (nulle quand le "
        "poids est négligé).",
    ),
    ReadoutInfo(
        "P_ext",
        "W",
        "Power of weight, motors and applied loads.",
        "Puissance des efforts extérieurs Pₑₓₜ",
        "Puissance du poids, des moteurs et des charges appliquées aux pièces mobiles, dans "
        "leur mouvement par rapport à R₀.",
    ),
    ReadoutInfo(
        "P_int",
        "W",
        "Power of inter-efforts, non-perfect joints and contacts.",
        "Puissance des efforts intérieurs Pᵢₙₜ",
        "Puissance des inter-efforts : frottements et amortissements des liaisons non "
        "parfaites et des contacts, toujours négative ou nulle.",
    ),
    ReadoutInfo(
        "P_acc",
        "W",
        "Power of the accelerations, equal to dT/dt.",
        "Puissance des quantités d'accélération dT/dt",
        "Somme sur les solides du comoment {D} ⊗ {V}, égale à la dérivée de l'énergie cinétique T.",
    ),
    *_torsor_infos(
        "kin",
        "Kinetic torsor {C}",
        "kg·m/s",
        "kg·m²/s",
        (
            "Résultante cinétique m·V(G) selon {axis}",
            "Composante sur {axis} de la résultante du torseur cinétique {{C}} des pièces "
            "mobiles, leur quantité de mouvement.",
            "Moment cinétique σ en O selon {axis}",
            "Composante sur {axis} du moment en O du torseur cinétique {{C}} des pièces mobiles.",
        ),
    ),
    *_torsor_infos(
        "dyn",
        "Dynamic torsor {D}",
        "N",
        "N·m",
        (
            "Résultante dynamique m·Γ(G) selon {axis}",
            "Composante sur {axis} de la résultante du torseur dynamique {{D}} des pièces mobiles.",
            "Moment dynamique δ en O selon {axis}",
            "Composante sur {axis} du moment en O du torseur dynamique {{D}} des pièces mobiles.",
        ),
    ),
    *_torsor_infos(
        "sup",
        "Action of the frame on the mechanism",
        "N",
        "N·m",
        (
            "Action du bâti : résultante selon {axis}",
            "Composante sur {axis} de la résultante des actions du bâti 0 sur les pièces "
            "mobiles, par les liaisons et les contacts (moteurs exclus).",
            "Action du bâti : moment en O selon {axis}",
            "Composante sur {axis} du moment en O des actions du bâti 0 sur les pièces "
            "mobiles, par les liaisons et les contacts (moteurs exclus).",
        ),
    ),
)
GENERIC_NAMES: tuple[str, ...] = tuple(r.name for r in GENERIC_READOUTS)
GENERIC_SET: frozenset[str] = frozenset(GENERIC_NAMES)
_NEEDS_RNE = ("dyn_", "sup_", "P_acc")


class _Structure:
    """Model-constant index arrays of the mechanism (body tree and joints): computed once
    per compiled model, since every readout row would otherwise rebuild them."""

    def __init__(self, model: mujoco.MjModel) -> None:
        weld, parent = model.body_weldid, model.body_parentid
        self.bodies = _frozen(np.flatnonzero(weld != 0))
        b = self.bodies
        self.children = _frozen(b[weld[parent[b]] == 0])
        jointed = self.children[model.body_jntnum[self.children] > 0]
        self.support_bodies = _frozen(np.concatenate([jointed, b]))
        self.support_roots = _frozen(model.body_rootid[self.support_bodies])
        self.n_jointed = len(jointed)
        self.children_joints = _JointGroups(model, self.children)
        kind = model.jnt_type
        scalar = (kind == mujoco.mjtJoint.mjJNT_HINGE) | (kind == mujoco.mjtJoint.mjJNT_SLIDE)
        self.scalar_joints = _frozen(np.flatnonzero(scalar))  # those a spring may act in
        self.scalar_qpos = _frozen(model.jnt_qposadr[self.scalar_joints])


class _JointGroups:
    """The joints of some bodies, grouped by type, as index arrays."""

    def __init__(self, model: mujoco.MjModel, bodies: np.ndarray) -> None:
        kinds: dict[int, list[tuple[int, int, int]]] = {}
        for body in bodies:
            start = int(model.body_jntadr[body])
            for j in range(start, start + int(model.body_jntnum[body])):
                kind = int(model.jnt_type[j])
                kinds.setdefault(kind, []).append((j, int(model.jnt_dofadr[j]), int(body)))

        def cols(kind: mujoco.mjtJoint) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
            rows = kinds.get(int(kind))
            if not rows:
                return None
            a = np.array(rows, dtype=int)
            return _frozen(a[:, 0]), _frozen(a[:, 1]), _frozen(a[:, 2])

        self.hinge = cols(mujoco.mjtJoint.mjJNT_HINGE)
        self.slide = cols(mujoco.mjtJoint.mjJNT_SLIDE)
        self.ball = cols(mujoco.mjtJoint.mjJNT_BALL)
        self.free = cols(mujoco.mjtJoint.mjJNT_FREE)
        if self.ball is not None:
            self.ball_dofs = _frozen(self.ball[1][:, None] + np.arange(3))
        if self.free is not None:
            self.free_dofs = _frozen(self.free[1][:, None] + np.arange(6))


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


_STRUCTURES: weakref.WeakKeyDictionary[Any, _Structure] = weakref.WeakKeyDictionary()
_GROUPS: weakref.WeakKeyDictionary[Any, dict[bytes, _JointGroups]] = weakref.WeakKeyDictionary()


def _structure(model: mujoco.MjModel) -> _Structure:
    found = _STRUCTURES.get(model)
    if found is None:
        found = _STRUCTURES[model] = _Structure(model)
    return found


def _joint_groups(model: mujoco.MjModel, bodies: np.ndarray) -> _JointGroups:
    cache = _GROUPS.get(model)
    if cache is None:
        cache = _GROUPS[model] = {}
    key = np.asarray(bodies, dtype=int).tobytes()
    found = cache.get(key)
    if found is None:
        found = cache[key] = _JointGroups(model, np.asarray(bodies, dtype=int))
    return found


def mechanism_bodies(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the bodies not welded to the world (read-only, shared)."""
    return _structure(model).bodies


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

    # -- the mechanism's bodies only (index = position in ``bodies``), shared by the torsors,
    # energies and powers of one row instead of each indexing the per-body arrays again.
    @cached_property
    def gravity(self) -> np.ndarray:
        return _gravity(self.model)

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
    model: mujoco.MjModel,
    data: mujoco.MjData,
    bodies: Iterable[int] | None = None,
    *,
    kin: Kinematics | None = None,
) -> Pair:
    """{C} at O: (Σ m v_G, Σ I_G ω + OG ∧ m v_G)."""
    k = _kin(model, data, kin)
    if bodies is None:
        p = k.momentum_b
        return p.sum(0), (k.i_omega_b + _cross(k.xipos_b, p)).sum(0)
    b = _select(k, bodies)
    p = model.body_mass[b][:, None] * k.v_g[b]
    return p.sum(0), (k.i_omega[b] + _cross(data.xipos[b], p)).sum(0)


def dynamic_torsor(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    bodies: Iterable[int] | None = None,
    *,
    kin: Kinematics | None = None,
) -> Pair:
    """{D} at O: (Σ m a_G, Σ I_G α + ω ∧ I_G ω + OG ∧ m a_G)."""
    k = _kin(model, data, kin)
    if bodies is None:
        ma = k.mass_b[:, None] * k.a_g_b
        return ma.sum(0), (k.delta_g_b + _cross(k.xipos_b, ma)).sum(0)
    b = _select(k, bodies)
    ma = model.body_mass[b][:, None] * k.a_g[b]
    return ma.sum(0), (k.delta_g[b] + _cross(data.xipos[b], ma)).sum(0)


def gravity_torsor(
    model: mujoco.MjModel, data: mujoco.MjData, bodies: Iterable[int] | None = None
) -> Pair:
    """Weight of the mechanism at O (zero when weight is neglected)."""
    b = mechanism_bodies(model) if bodies is None else np.asarray(list(bodies), dtype=int)
    w = model.body_mass[b][:, None] * _gravity(model)
    return w.sum(0), _cross(data.xipos[b], w).sum(0)


def _frame_children(model: mujoco.MjModel) -> np.ndarray:
    """Mechanism bodies whose parent is welded to the world (they touch the frame)."""
    return _structure(model).children


def _dof_wrenches(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    force: np.ndarray,
    bodies: np.ndarray,
    *,
    groups: _JointGroups | None = None,
) -> Pair:
    """Wrench at O of generalised forces ``force`` (nv,) in the joints of ``bodies``.

    Hinge: a torque along its axis; slide: a force along its axis through its anchor; ball:
    a torque in body axes; free: a world-axis force at the body origin and a body-axis
    torque. Vectorised over the joints of each type (``groups``: their cached indices).
    """
    g = groups if groups is not None else _joint_groups(model, bodies)
    r, m = np.zeros(3), np.zeros(3)
    if g.hinge is not None:
        j, dof, _ = g.hinge
        m += force[dof] @ data.xaxis[j]
    if g.slide is not None:
        j, dof, _ = g.slide
        f = force[dof][:, None] * data.xaxis[j]
        r += f.sum(0)
        m += _cross(data.xanchor[j], f).sum(0)
    if g.ball is not None:
        _, _, body = g.ball
        rot = data.xmat[body].reshape(-1, 3, 3)
        m += np.einsum("bij,bj->i", rot, force[g.ball_dofs])
    if g.free is not None:
        _, _, body = g.free
        rot = data.xmat[body].reshape(-1, 3, 3)
        dofs = g.free_dofs
        f = force[dofs[:, :3]]
        r += f.sum(0)
        m += _cross(data.xpos[body], f).sum(0) + np.einsum("bij,bj->i", rot, force[dofs[:, 3:]])
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
    if not data.xfrc_applied.any():  # the usual case: no applied load
        return np.zeros(3), np.zeros(3)
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
    st = _structure(model)
    bodies, n = st.support_bodies, st.n_jointed
    wrench = np.concatenate([data.cfrc_int[bodies[:n]], data.cfrc_ext[bodies[n:]]])
    c = data.subtree_com[st.support_roots]
    r = wrench[:, 3:].sum(0)
    m = (wrench[:, :3] + _cross(c, wrench[:, 3:])).sum(0)
    drive = joint_drive(model, data)
    ar, am = _dof_wrenches(model, data, drive, st.children, groups=st.children_joints)
    xr, xm = applied_torsor(model, data)
    return r - ar - xr, m - am - xm


def kinetic_energy(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    bodies: Iterable[int] | None = None,
    *,
    kin: Kinematics | None = None,
) -> float:
    """T = Σ ½ m v_G² + ½ ω·I_G ω, plus ½ Σ armature q̇² (motor rotors, whole mechanism)."""
    k = _kin(model, data, kin)
    if bodies is None:
        v, m, i_omega, omega = k.v_g_b, k.mass_b, k.i_omega_b, k.omega_b
    else:
        b = _select(k, bodies)
        v, m, i_omega, omega = k.v_g[b], model.body_mass[b], k.i_omega[b], k.omega[b]
    t = 0.5 * (m * (v * v).sum(1)).sum() + 0.5 * (i_omega * omega).sum()
    if bodies is None:
        t += 0.5 * float(model.dof_armature @ (data.qvel * data.qvel))
    return float(t)


def potential_energy(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Weight (−Σ m g·OG) plus hinge and slide joint springs ½ k (q − q_ref)²."""
    st = _structure(model)
    b = st.bodies
    v = -float((model.body_mass[b] * (data.xipos[b] @ _gravity(model))).sum())
    if not model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_SPRING:
        k = model.jnt_stiffness[st.scalar_joints]
        if k.any():
            a = st.scalar_qpos
            stretch = data.qpos[a] - model.qpos_spring[a]
            v += 0.5 * float(k @ (stretch * stretch))
    return v


def powers(
    model: mujoco.MjModel, data: mujoco.MjData, *, kin: Kinematics | None = None
) -> dict[str, float]:
    """P_ext and P_int [W] (see the module and docs/reference.md for the split)."""
    k = _kin(model, data, kin)
    qv = data.qvel
    p_grav = float((k.mass_b * (k.v_g_b @ k.gravity)).sum())
    p_xfrc = 0.0
    if data.xfrc_applied.any():
        xf = data.xfrc_applied[k.bodies]
        p_xfrc = float((xf[:, :3] * k.v_g_b).sum() + (xf[:, 3:] * k.omega_b).sum())
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
    return float(
        (k.mass_b * (k.a_g_b * k.v_g_b).sum(1)).sum()
        + (k.delta_g_b * k.omega_b).sum()
        + model.dof_armature @ (data.qvel * data.qacc)
    )


_TORSORS = ("kin", "dyn", "sup")


def torsor(
    model: mujoco.MjModel, data: mujoco.MjData, prefix: str, cache: dict[str, Any] | None = None
) -> Pair:
    """The mechanism's torsor ``prefix`` ("kin", "dyn" or "sup") at O, memoised in cache."""
    if cache is not None and prefix in cache:
        return cache[prefix]
    if prefix == "sup":
        value = support_torsor(model, data)
    elif prefix in ("kin", "dyn"):
        fn = kinetic_torsor if prefix == "kin" else dynamic_torsor
        value = fn(model, data, kin=_cached_kin(model, data, cache))
    else:
        raise KeyError(f"unknown torsor {prefix!r}; valid: {', '.join(_TORSORS)}")
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
    asked = set(names)
    unknown = [n for n in names if n not in GENERIC_SET]
    if unknown:
        raise KeyError(f"unknown readout {unknown[0]!r}; valid: {', '.join(GENERIC_NAMES)}")
    out: dict[str, float] = {}
    heads = {n[:4] for n in asked}
    for prefix in _TORSORS:
        if prefix + "_" in heads:
            r, m = torsor(model, data, prefix, cache)
            for c, ri, mi in zip("xyz", r.tolist(), m.tolist(), strict=True):
                out[f"{prefix}_R_{c}"], out[f"{prefix}_M_{c}"] = ri, mi
    if "time" in asked:
        out["time"] = float(data.time)
    kin = _cached_kin(model, data, cache)
    if "T" in asked:
        out["T"] = kinetic_energy(model, data, kin=kin)
    if "V" in asked:
        out["V"] = potential_energy(model, data)
    if "P_ext" in asked or "P_int" in asked:
        out.update(powers(model, data, kin=kin))
    if "P_acc" in asked:
        out["P_acc"] = acceleration_power(model, data, kin=kin)
    return {n: out[n] for n in names}
