"""Readouts and arrows of the rolling cylinder: the slope's frame, the contact point A and
the velocities V(A∈S) and V(A/R0), the plane's action (N, Tt) and its power, the dynamic
moment at A by the formula and by transport, the course's a and N while they apply, and
the racers' distances."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.kinematics import Kinematics
from sandbox.physics.page import Arrow
from sandbox.physics.scratch import scratch_data
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout, Values
from sandbox.scenes.rolling_cylinder.course import (
    acceleration,
    eccentric_acceleration,
    eccentric_normal_force,
)


def _frame(s: Snapshot) -> np.ndarray:
    """Slope basis (columns x down the slope, y axis, z normal) in world coordinates."""
    return s.data.xmat[s.body_id("slope")].reshape(3, 3)


def _centre(s: Snapshot) -> np.ndarray:
    return s.data.xpos[s.body_id("cylinder")].copy()


def _contact_point(s: Snapshot) -> np.ndarray:
    """A: the geometric contact point, under the axis on the plane."""
    b = _frame(s)
    return _centre(s) - s.values["R"] * b[:, 2]


def _omega(s: Snapshot) -> np.ndarray:
    return s.data.cvel[s.body_id("cylinder"), :3].copy()


def _velocity_of_material_point(s: Snapshot, p: np.ndarray) -> np.ndarray:
    """Velocity in R0 of the cylinder's material point at p."""
    res = np.zeros(6)
    mujoco.mj_objectVelocity(
        s.model, s.data, mujoco.mjtObj.mjOBJ_BODY, s.body_id("cylinder"), res, 0
    )
    v_origin, omega = res[3:], res[:3]
    return v_origin + _cross(omega, p - _centre(s))


def _plane_contacts(s: Snapshot) -> list[tuple[np.ndarray, np.ndarray]]:
    """(position, force of the plane on the cylinder) of each contact, world axes."""
    if "rc_contacts" in s.cache:
        return s.cache["rc_contacts"]
    m, d = s.model, s.data
    plane = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "plane")
    body = s.body_id("cylinder")
    out = []
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        if plane not in (c.geom1, c.geom2):
            continue
        other = c.geom2 if c.geom1 == plane else c.geom1
        if m.geom_bodyid[other] != body:
            continue  # a racer's contact
        mujoco.mj_contactForce(m, d, i, f6)
        f = c.frame.reshape(3, 3).T @ f6[:3]  # on geom2, from geom1
        out.append((np.asarray(c.pos).copy(), f if c.geom1 == plane else -f))
    s.cache["rc_contacts"] = out
    return out


def _penetration(s: Snapshot) -> float:
    """Depth of the cylinder in the plane [m] (0 when it is off the plane)."""
    m, d = s.model, s.data
    body = s.body_id("cylinder")
    depths = [
        -d.contact[i].dist
        for i in range(d.ncon)
        if body in (m.geom_bodyid[d.contact[i].geom1], m.geom_bodyid[d.contact[i].geom2])
    ]
    return float(max(depths, default=0.0))


def _contact_force(s: Snapshot) -> np.ndarray:
    """Force of the plane on the cylinder, world axes, summed over contact points."""
    return sum((f for _, f in _plane_contacts(s)), np.zeros(3))


def _contact_power(s: Snapshot) -> float:
    """Power of the contact forces on the cylinder: Σ f_i · V(P_i ∈ S) (≤ 0)."""
    return float(sum(f @ _velocity_of_material_point(s, p) for p, f in _plane_contacts(s)))


def _along(s: Snapshot, vec: np.ndarray, axis: int) -> float:
    return float(_frame(s)[:, axis] @ vec)


def _delta_terms(s: Snapshot) -> tuple[float, float, float]:
    """(dσA/dt, V(A) ∧ m V(G), δA direct) about the cylinder's axis y [N·m].

    dσA/dt is a numerical time derivative of σA = σG + AG ∧ m V(G) (A moving with the
    axis) from states at t ± h along the current motion; the direct value is
    δG + AG ∧ m Γ(G) from MuJoCo's accelerations.
    """
    m, d = s.model, s.data
    ids = [s.body_id("cylinder"), s.body_id("eccentric")]
    y = _frame(s)[:, 1]
    k = s.kinematics

    def sigma_a(data: mujoco.MjData, kin: Kinematics) -> np.ndarray:
        c = data.xpos[ids[0]]
        a = c - s.values["R"] * data.xmat[m.body_parentid[ids[0]]].reshape(3, 3)[:, 2]
        total = np.zeros(3)
        for b in ids:
            mv = m.body_mass[b] * kin.v_g[b]
            total += kin.i_omega[b] + _cross(data.xipos[b] - a, mv)
        return total

    h = 1e-4
    values = []
    scratch = scratch_data(m)
    for sign in (1.0, -1.0):
        scratch.qpos[:] = d.qpos + sign * h * d.qvel + 0.5 * h * h * d.qacc
        scratch.qvel[:] = d.qvel + sign * h * d.qacc
        mujoco.mj_kinematics(m, scratch)
        mujoco.mj_comPos(m, scratch)
        mujoco.mj_comVel(m, scratch)
        values.append(sigma_a(scratch, Kinematics(m, scratch)))
    dsigma = (values[0] - values[1]) / (2 * h)
    v_a = _axis_velocity(s)
    transport = np.zeros(3)
    direct = np.zeros(3)
    a = _contact_point(s)
    for b in ids:
        mv = m.body_mass[b] * k.v_g[b]
        transport += _cross(v_a, mv)
        direct += k.delta_g[b] + _cross(d.xipos[b] - a, m.body_mass[b] * k.a_g[b])
    return float(dsigma @ y), float(transport @ y), float(direct @ y)


def _axis_velocity(s: Snapshot) -> np.ndarray:
    """V(C/R0) = V(A/R0): the geometric contact point moves with the axis."""
    return _velocity_of_material_point(s, _centre(s))


def _cached_delta(s: Snapshot) -> tuple[float, float, float]:
    if "rc_delta" not in s.cache:
        s.cache["rc_delta"] = _delta_terms(s)
    return s.cache["rc_delta"]


def _beta(s: Snapshot) -> float:
    """Angle of CG from the plane's normal towards the slope (x)."""
    d = s.data
    g = sum(
        s.model.body_mass[b] * d.xipos[b] for b in (s.body_id("cylinder"), s.body_id("eccentric"))
    )
    g = g / sum(s.model.body_mass[b] for b in (s.body_id("cylinder"), s.body_id("eccentric")))
    cg = g - _centre(s)
    return math.atan2(_along(s, cg, 0), _along(s, cg, 2))


def _racer_x(s: Snapshot, name: str) -> float:
    j = mujoco.mj_name2id(s.model, mujoco.mjtObj.mjOBJ_JOINT, f"x_{name}")
    return float(s.data.qpos[s.model.jnt_qposadr[j]]) if j >= 0 else 0.0


SLIP_TOL = 1e-3
"""|V(A∈S)| [m/s] under which the cylinder counts as rolling (the creep while rolling stays
below 1e-4 m/s; a slip starts at 1e-2 m/s and grows)."""


def _contact(s: Snapshot) -> bool:
    """The plane pushes on the cylinder (N > 0); False once it has left the plane."""
    if "rc_contact" not in s.cache:
        s.cache["rc_contact"] = _along(s, _contact_force(s), 2) > 0.0
    return bool(s.cache["rc_contact"])


def _eccentric(v: Values) -> bool:
    """An eccentric mass (even on the axis: the homogeneous formulas count only ``mass``)."""
    return v["eccentric_mass"] > 0


def _slip(s: Snapshot) -> float:
    return _along(s, _velocity_of_material_point(s, _contact_point(s)), 0)


def _applies(s: Snapshot) -> bool:
    """The course's formulas hold: in contact and, with G off the axis (formulas written for
    rolling), rolling. A homogeneous cylinder's formulas cover slipping too. Cached: a_ref
    and N_ref share it."""
    if "rc_applies" in s.cache:
        return bool(s.cache["rc_applies"])
    ok = _contact(s) and (not _eccentric(s.values) or abs(_slip(s)) <= SLIP_TOL)
    s.cache["rc_applies"] = ok
    return ok


def _a_ref(s: Snapshot) -> float:
    v = s.values
    if not _applies(s):
        return math.nan
    if _eccentric(v):
        return eccentric_acceleration(_beta(s), s.joint_qvel("x"), v)
    return acceleration(v)


def _n_ref(s: Snapshot) -> float:
    if not _applies(s):
        return math.nan
    return eccentric_normal_force(_beta(s), s.joint_qvel("x"), s.values)


READOUTS = (
    SceneReadout("x", "m", "Distance travelled by the centre down the slope.", lambda s: s.joint_qpos("x"), label="Distance parcourue x", hint="Distance parcourue par le centre du cylindre le long de la pente."),
    SceneReadout("v", "m/s", "Speed of the centre down the slope.", lambda s: s.joint_qvel("x"), label="Vitesse du centre v", hint="Vitesse du centre du cylindre vers le bas de la pente."),
    SceneReadout("a", "m/s²", "Acceleration of the centre down the slope.", lambda s: float(s.data.qacc[0]), label="Accélération du centre a", hint="Accélération du centre du cylindre vers le bas de la pente."),
    SceneReadout("a_ref", "m/s²", "Course value of the acceleration (rolling or slipping; energy theorem with the eccentric mass, while it rolls); NaN (—) once the cylinder has left the plane.", _a_ref, label="Accélération selon le cours", hint="Accélération donnée par le cours, en roulement ou en glissement (théorème de l'énergie cinétique avec la masse excentrée), et « — » une fois le plan quitté."),
    SceneReadout("slip_velocity", "m/s", "V(A∈S/R0) down the slope: the material point at A (0 when rolling).", _slip, label="Vitesse de glissement V(A∈S/R₀)", hint="Vitesse du point du cylindre qui se trouve en A, le long de la pente : nulle quand il roule sans glisser."),
    SceneReadout("contact_point_velocity", "m/s", "V(A/R0) down the slope: the geometric contact point, which follows the axis.", lambda s: _along(s, _axis_velocity(s), 0), label="Vitesse du point de contact V(A/R₀)", hint="Vitesse du point géométrique de contact A, qui avance avec l'axe du cylindre."),
    SceneReadout("N", "N", "Normal force of the plane on the cylinder.", lambda s: _along(s, _contact_force(s), 2), label="Effort normal N", hint="Composante normale de l'action du plan sur le cylindre."),
    SceneReadout("N_ref", "N", "Course value of N: m g cos α, and with the eccentric mass m [g cos α − e (a sin β/R + v² cos β/R²)] while it rolls; NaN (—) off the plane.", _n_ref, label="Effort normal selon le cours", hint="Valeur de N donnée par le cours, m·g·cos α sans masse excentrée, et « — » hors du plan."),
    SceneReadout("contact", "", "Contact avec le plan: 1 while the plane pushes on the cylinder (N > 0), 0 once it has left it (a_ref and N_ref then show —).", lambda s: float(_contact(s)), label="Contact avec le plan", hint="1 tant que le plan appuie sur le cylindre (N positif), 0 quand le cylindre l'a quitté."),
    SceneReadout("Tt", "N", "Tangential force of the plane on the cylinder, down the slope.", lambda s: _along(s, _contact_force(s), 0), label="Effort tangentiel Tₜ", hint="Composante tangentielle de l'action du plan sur le cylindre, comptée vers le bas de la pente."),
    SceneReadout("mu_required", "", "|Tt| / N: the friction the motion uses.", lambda s: abs(_along(s, _contact_force(s), 0)) / max(_along(s, _contact_force(s), 2), 1e-12), label="Frottement utilisé Tₜ/N", hint="Rapport entre la valeur absolue de Tₜ et N, ce que le mouvement demande au frottement : le cylindre glisse quand il atteint μ."),
    SceneReadout("P_contact", "W", "Power of the contact forces on the cylinder (≤ 0; 0 when rolling).", _contact_power, label="Puissance du contact", hint="Puissance de l'action du plan sur le cylindre : nulle en roulement sans glissement, négative en glissement."),
    SceneReadout("delta_A_formula", "N·m", "δA about the axis from dσA/dt + V(A) ∧ m V(G).", lambda s: _cached_delta(s)[0] + _cached_delta(s)[1], label="Moment dynamique en A, par la formule", hint="Moment dynamique δ en A sur l'axe du cylindre, calculé par dσ(A)/dt + V(A) ∧ m·V(G)."),
    SceneReadout("delta_A_direct", "N·m", "δA about the axis from δG + AG ∧ m Γ(G).", lambda s: _cached_delta(s)[2], label="Moment dynamique en A, par transport", hint="Moment dynamique δ en A sur l'axe du cylindre, transporté depuis G : δ(G) + AG ∧ m·Γ(G)."),
    SceneReadout("delta_A_dsigma", "N·m", "First term of the formula: dσA/dt (time derivative).", lambda s: _cached_delta(s)[0], label="Terme dσ(A)/dt", hint="Premier terme de la formule : dérivée par rapport au temps du moment cinétique en A."),
    SceneReadout("delta_A_transport", "N·m", "Second term: V(A) ∧ m V(G) (0 if G is on the axis).", lambda s: _cached_delta(s)[1], label="Terme V(A) ∧ m·V(G)", hint="Second terme de la formule, nul quand G est sur l'axe du cylindre."),
    SceneReadout("x_hollow", "m", "Race: distance travelled by the thin tube (0 without race).", lambda s: _racer_x(s, "hollow"), label="Distance du tube mince", hint="Course : distance parcourue par le tube mince (0 sans course)."),
    SceneReadout("x_sphere", "m", "Race: distance travelled by the sphere (0 without race).", lambda s: _racer_x(s, "sphere"), label="Distance de la sphère", hint="Course : distance parcourue par la sphère pleine (0 sans course)."),
    SceneReadout("penetration", "m", "Depth of the cylinder in the plane: a few µm at 1 ms, about 25 µm at 2 ms (the step without an eccentric mass); centimetres mean the timestep is far too large.", _penetration, label="Enfoncement dans le plan", hint="Enfoncement du cylindre dans le plan : quelques µm au pas de 1 ms, environ 25 µm à 2 ms (le pas sans masse excentrée) ; des centimètres signalent un pas de temps bien trop grand."),
    SceneReadout("on_plane", "", "1 while the centre is over the drawn plane, 0 beyond its end.", lambda s: float(-0.5 <= s.joint_qpos("x") <= s.values["plane_length"] - 0.5), label="Sur le plan", hint="1 tant que le centre est au-dessus du plan dessiné, 0 au-delà de son extrémité."),
)  # fmt: skip


def _g_and_velocity(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """G of cylinder + eccentric mass and V(G/R0)."""

    k = s.kinematics
    ids = [s.body_id("cylinder"), s.body_id("eccentric")]
    mass = s.model.body_mass[ids]
    g = (mass[:, None] * s.data.xipos[ids]).sum(0) / mass.sum()
    return g, (mass[:, None] * k.v_g[ids]).sum(0) / mass.sum()


ARROW_SCALE = 0.02
"""Metres of arrow per newton (forces) or per m/s (velocities, × 5)."""


def _at_a(s: Snapshot, vec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return _contact_point(s), vec


ARROWS = (
    Arrow("N", "Effort normal N", (60, 160, 60), lambda s: _at_a(s, _along(s, _contact_force(s), 2) * _frame(s)[:, 2]), ARROW_SCALE, unit="N", point="A", hint="Effort normal du plan sur le cylindre, au point de contact A (vert)."),
    Arrow("Tt", "Effort tangentiel Tₜ", (220, 120, 40), lambda s: _at_a(s, _along(s, _contact_force(s), 0) * _frame(s)[:, 0]), ARROW_SCALE, unit="N", point="A", hint="Effort tangentiel du plan sur le cylindre, au point de contact A (orange)."),
    Arrow("v_G", "Vitesse V(G)", (60, 100, 220), lambda s: _g_and_velocity(s), 0.1, unit="m/s", point="G", hint="Vitesse du centre de gravité G par rapport au bâti (bleu)."),
    Arrow("slip", "Vitesse V(A∈S)", (200, 40, 40), lambda s: _at_a(s, _velocity_of_material_point(s, _contact_point(s))), 0.1, unit="m/s", point="A", hint="Vitesse du point du cylindre situé en A : nulle en roulement sans glissement (rouge)."),
)  # fmt: skip
