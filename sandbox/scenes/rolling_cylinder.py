"""Rolling cylinder on an inclined plane (course 3.2 remark 1, 6.1.3, 6.2).

A cylinder of radius R (solid, or hollow down to ``inner_radius``), possibly with an
eccentric point mass, rolls or slips down a plane inclined at α = ``slope_deg``, with
Coulomb friction μ. A is the geometric contact point (under the axis C): V(A∈S) is the
velocity of the cylinder's material point at A (0 when rolling), V(A/R0) the velocity of
the geometric point, which follows the axis. Gravity and the contact only.

Contact settings (scenes/rolling_cylinder.xml), measured on this scene at 1 ms:

- One explicit pair per rolling body with the plane, every geom's contype/conaffinity 0:
  the plane-cylinder contact is the only one (the racers never touch each other).
- condim 3: sliding friction only, no spin or rolling resistance, as in the course.
- Elliptic cone, impratio 1e4, solreffriction (-0, -0.01): while slipping, MuJoCo's
  convex contact model trades a tangential residual for a separating normal one (the
  relaxation of Coulomb's law), about μ·(b_t V(A∈S) + tangential acceleration). With the
  usual pyramidal cone (which ignores solreffriction) and damping b_t = 2/solref the
  cylinder hopped off the plane on 86 % of the steps at μ = 0.05, α = 20°: N jumped
  between 0 and 2 m g cos α and mu_required between 0 and μ. An almost undamped friction
  row (b_t = 0.01 /s) removes the V(A∈S) term and impratio 1e4 makes friction stiff, so
  the creep while rolling stays below 1e-4 m/s after 2 s (impratio 100: ~4e-3 m/s).
- solimp (0.5, 0.5): half the normal load is carried by the constraint's softness, which
  absorbs the rest of that coupling (with dmin 0.99 the hops came back); solref (2 ms, 1),
  the stiffest MuJoCo allows at 1 ms, still keeps the static penetration to 6 µm.
- MuJoCo's default (solref 20 ms, solimp 0.9-0.95) sinks the cylinder 0.13 mm: the contact
  point is then R − p/2 from the axis, and a changes by −k/(1+k)·p/R (k = I/(mR²)):
  −4.5e-4 for R = 0.1 m, −1.8e-3 for R = 0.02 m. Here −1.5e-5 and −7.8e-5.
- margin 0, gap 0: a positive margin makes the contact act at a distance, so the cylinder
  would ride on a cushion of that thickness and roll on a radius R + margin/2.
- noslip_iterations 0: not needed (creep above), and it cannot cure the hops since it
  leaves the normal forces of the main solve unchanged.
- The cylinder starts at its static penetration (:func:`_settle`): dropped from contact at
  0 µm it slipped while N built up, and kept ~3 mm/s of slip near μ_min.

Remaining limit: slipping very fast with much friction (α = 60°, μ = 0.5, a thin tube),
the coupling still makes the cylinder hop (14 % of the steps over 3 s, when V(A∈S) passes
~8 m/s); x(t) and v(t) stay right.

Leaving the plane: with an eccentric mass N = m [g cos α − e (a sin β/R + v² cos β/R²)]
can reach 0 (physically right: the cylinder jumps). The ``contact`` readout turns 0 and the
references written for a cylinder on the plane (a_ref, N_ref) turn NaN ("—"), as they do
while an eccentric cylinder slips (its a_ref is written for rolling).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.snapshot import Snapshot
from sandbox.scenes.base import Accuracy, Arrow, Effects, Param, Scene, SceneReadout, Values
from sandbox.scenes.measures import energy_drift
from sandbox.scenes.presets import StudyPreset, XYPreset

G = 9.81
CYLINDER, PLANE, ECCENTRIC, START = "Cylindre", "Plan incliné", "Masse excentrée", "Lancement"
PARAMS = (
    Param("R", "m", 0.1, 0.01, 0.5, "Outer radius of the cylinder.", step=0.005, label="Rayon du cylindre R", hint="Rayon extérieur du cylindre, celui qui roule sur le plan.", group=CYLINDER),
    Param("length", "m", 0.2, 0.01, 1.0, "Length of the cylinder along its axis.", step=0.01, label="Longueur du cylindre", hint="Longueur du cylindre le long de son axe, sans effet sur la descente.", group=CYLINDER, advanced=True),
    Param("mass", "kg", 1.0, 0.01, 100.0, "Mass of the cylinder (without the eccentric mass).", step=0.01, label="Masse du cylindre m", hint="Masse du cylindre seul, sans la masse excentrée.", group=CYLINDER),
    Param("inner_radius", "m", 0.0, 0.0, 0.499, "Inner radius: 0 for a solid cylinder, close to R for a thin tube.", step=0.005, label="Rayon intérieur r", hint="Rayon intérieur : 0 pour un cylindre plein, proche de R pour un tube mince.", group=CYLINDER),
    Param("slope_deg", "deg", 20.0, 0.0, 60.0, "Slope α of the plane.", step=0.5, label="Pente du plan α", hint="Angle α du plan incliné avec l'horizontale.", group=PLANE),
    Param("mu", "", 0.3, 0.0, 2.0, "Coulomb friction coefficient between cylinder and plane.", step=0.01, label="Coefficient de frottement μ", hint="Coefficient de frottement de Coulomb entre le cylindre et le plan.", group=PLANE),
    Param("eccentric_mass", "kg", 0.0, 0.0, 10.0, "Point mass fixed in the cylinder off its axis.", step=0.01, label="Masse excentrée", hint="Masse ponctuelle fixée dans le cylindre, hors de son axe (0 : pas de masse excentrée).", group=ECCENTRIC),
    Param("eccentric_radius", "m", 0.05, 0.0, 0.5, "Distance of the eccentric mass from the axis.", step=0.005, label="Excentricité e", hint="Distance de la masse excentrée à l'axe du cylindre.", group=ECCENTRIC),
    Param("v0", "m/s", 0.0, -10.0, 10.0, "Initial speed of the centre down the slope (rolling).", step=0.05, label="Vitesse initiale v₀", hint="Vitesse initiale du centre vers le bas de la pente, le cylindre roulant sans glisser.", group=START),
    Param("plane_length", "m", 12.0, 1.0, 200.0, "Length of the drawn plane (the default holds a 3 s run); on_plane turns 0 beyond it.", step=1.0, label="Longueur du plan", hint="Longueur du plan dessiné (3 s de descente par défaut) : au-delà, l'indicateur « Sur le plan » passe à 0.", group=PLANE, advanced=True),
    Param("race", "", 0.0, 0.0, 1.0, "1: a thin tube and a solid sphere (same R and mass) race the cylinder side by side.", step=1.0, label="Course contre un tube et une sphère", hint="Oui : un tube mince et une sphère pleine, de même rayon et de même masse, descendent à côté du cylindre.", group=START, choices=("Non", "Oui")),
)  # fmt: skip


# -- closed forms ---------------------------------------------------------------------------
def axis_inertia(v: Values) -> float:
    """Inertia of the cylinder about its axis: ½ m (R² + r²)."""
    return 0.5 * v["mass"] * (v["R"] ** 2 + v["inner_radius"] ** 2)


def mass_properties(v: Values) -> tuple[float, float, float]:
    """Total mass, distance e from the axis to G, inertia about G's axis (y)."""
    m_c, m_e, r_e = v["mass"], v["eccentric_mass"], v["eccentric_radius"]
    m = m_c + m_e
    e = m_e * r_e / m
    i_g = axis_inertia(v) + m_c * e * e + m_e * (r_e - e) ** 2
    return m, e, i_g


def mu_min(v: Values) -> float:
    """Least friction for rolling without slipping: tan α / (1 + m R² / I) (homogeneous)."""
    alpha = math.radians(v["slope_deg"])
    return math.tan(alpha) / (1 + v["mass"] * v["R"] ** 2 / axis_inertia(v))


def acceleration(v: Values) -> float:
    """Acceleration of the centre down the slope (homogeneous): rolling if μ ≥ μ_min,
    a = g sin α / (1 + I/(mR²)); else slipping, a = g (sin α − μ cos α)."""
    alpha = math.radians(v["slope_deg"])
    if v["mu"] >= mu_min(v):
        return G * math.sin(alpha) / (1 + axis_inertia(v) / (v["mass"] * v["R"] ** 2))
    return G * (math.sin(alpha) - v["mu"] * math.cos(alpha))


def eccentric_acceleration(beta: float, v_c: float, v: Values) -> float:
    """Rolling with G off the axis, from the energy theorem (Lagrange on φ = x_C / R).

    β is the angle of CG from the plane's normal towards the slope; T = ½ J_A(β) φ'²
    with J_A = I_G + m (e² + R² + 2 R e cos β), V = −m g·OG.
    """
    m, e, i_g = mass_properties(v)
    R, alpha = v["R"], math.radians(v["slope_deg"])
    j_a = i_g + m * (e * e + R * R + 2 * R * e * math.cos(beta))
    dj = -2 * m * R * e * math.sin(beta)
    dv = (
        -m * G * (math.sin(alpha) * (R + e * math.cos(beta)) + math.cos(alpha) * e * math.sin(beta))
    )
    dphi = v_c / R
    return R * -(0.5 * dj * dphi**2 + dv) / j_a


def eccentric_normal_force(beta: float, v_c: float, v: Values) -> float:
    """Normal force of the plane while rolling with G off the axis [N].

    The centre C stays at R from the plane, so G's acceleration along the normal z is that
    of e (sin β, cos β) turning at β' = v/R: z''(G) = −e (β'' sin β + β'² cos β) with
    β'' = a/R (a from :func:`eccentric_acceleration`). The PFD along z gives
    N = m g cos α + m z''(G) = m [g cos α − e (a sin β / R + v² cos β / R²)]. The cylinder
    leaves the plane where this reaches 0; started with the mass straight up (β = 0) on a
    horizontal plane, as soon as v0 > R √(g / e).
    """
    m, e, _ = mass_properties(v)
    R, alpha = v["R"], math.radians(v["slope_deg"])
    a = eccentric_acceleration(beta, v_c, v) if e > 0 else 0.0
    return m * (G * math.cos(alpha) - e * (a * math.sin(beta) / R + v_c**2 * math.cos(beta) / R**2))


def reference(v: Values) -> dict[str, float]:
    """Course values of a homogeneous cylinder (constant along the motion): μ_min (or μ
    while it slips), a, and N = m g cos α. With an eccentric mass they vary along the motion:
    the readouts a_ref and N_ref give them."""
    if v["eccentric_mass"] > 0:
        return {}
    return {
        "mu_required": mu_min(v) if v["mu"] >= mu_min(v) else v["mu"],
        "a": acceleration(v),
        "N": v["mass"] * G * math.cos(math.radians(v["slope_deg"])),
    }


# -- model ----------------------------------------------------------------------------------
def edit(spec: mujoco.MjSpec, v: Values) -> None:
    """Slope, radius, length, inertia (solid or hollow), eccentric mass, friction."""
    if v["inner_radius"] >= v["R"]:
        from sandbox.errors import BadParameter

        raise BadParameter(
            f"inner_radius = {v['inner_radius']:g} m must be smaller than R = {v['R']:g} m; "
            "lower inner_radius"
        )
    alpha = math.radians(v["slope_deg"])
    slope = spec.body("slope")
    slope.quat = [math.cos(alpha / 2), 0, math.sin(alpha / 2), 0]  # x down the slope
    plane = spec.geom("plane")  # infinite for collisions; drawn by "deck" below
    plane.rgba = [0, 0, 0, 0]
    spec.pair("contact").friction[:2] = [v["mu"], v["mu"]]
    deck = spec.geom("deck")
    deck.size = [v["plane_length"] / 2, max(v["length"], 0.5), 0.005]
    deck.pos = [v["plane_length"] / 2 - 0.5, 0, -0.005]
    R, h, m = v["R"], v["length"], v["mass"]
    cyl = spec.geom("cylinder")
    cyl.size = [R, h / 2, 0]
    body = spec.body("cylinder")
    body.pos = [0, 0, R]
    i_axis = axis_inertia(v)
    i_across = m * (3 * (R * R + v["inner_radius"] ** 2) + h * h) / 12
    body.explicitinertial = True
    body.mass, body.ipos = m, [0, 0, 0]
    body.fullinertia = [i_across, i_axis, i_across, 0, 0, 0]
    stripe = spec.geom("stripe")
    stripe.pos = [0, 0, 0.6 * R]
    stripe.size = [0.02 * R + 0.002, h / 2 + 0.001, 0.4 * R]
    ecc = spec.body("eccentric")
    ecc.pos = [0, 0, v["eccentric_radius"]]
    m_e = v["eccentric_mass"]
    ecc.explicitinertial = True
    ecc.mass = max(m_e, 1e-9)
    tiny = max(m_e * 1e-6, 1e-10)
    ecc.fullinertia = [tiny, tiny, tiny, 0, 0, 0]
    spec.geom("eccentric").rgba = [0.8, 0.1, 0.1, 1.0 if m_e > 0 else 0.0]
    spec.geom("eccentric").size = [max(0.012, 0.1 * R), 0, 0]
    if v["race"] >= 0.5:
        deck.size = [v["plane_length"] / 2, 3 * (h + 2 * R), 0.005]
        _add_racers(spec, v)


RACERS = (("hollow", 0.35), ("sphere", -0.35))
"""Race companions and their offset along the axis, in multiples of (length + 2R)."""


def _add_racers(spec: mujoco.MjSpec, v: Values) -> None:
    """A thin tube (I = m R²) and a solid sphere (I = 2/5 m R²) beside the cylinder."""
    R, h, m = v["R"], v["length"], v["mass"]
    for name, side in RACERS:
        y = side * (h + 2 * R) * 2.5
        body = spec.body("slope").add_body(name=name, pos=[0, y, R])
        for axis, kind, jname in (([1, 0, 0], "slide", "x"), ([0, 0, 1], "slide", "z"),
                                  ([0, 1, 0], "hinge", "spin")):  # fmt: skip
            joint = body.add_joint(name=f"{jname}_{name}", axis=axis)
            joint.type = (
                mujoco.mjtJoint.mjJNT_SLIDE if kind == "slide" else mujoco.mjtJoint.mjJNT_HINGE
            )
        body.explicitinertial = True
        body.mass = m
        if name == "hollow":
            i_axis, i_across = m * R * R, m * (6 * R * R + h * h) / 12
            geom = body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[R, h / 2, 0])
            geom.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT
            geom.quat = [math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0]
            geom.rgba = [0.3, 0.5, 0.85, 1]
        else:
            i_axis = i_across = 0.4 * m * R * R
            geom = body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[R, 0, 0])
            geom.rgba = [0.3, 0.75, 0.4, 1]
        body.ipos, body.iquat = [0, 0, 0], [1, 0, 0, 0]
        body.inertia = [i_across, i_axis, i_across]
        pair = spec.add_pair(name=f"contact_{name}", geomname1="plane", geomname2=name)
        pair.friction = [v["mu"], v["mu"], 0, 0, 0]  # solref, solimp... from the pair default
        stripe = body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, pos=[0, 0, 0.6 * R],
                               size=[0.02 * R + 0.002, 0.3 * R, 0.4 * R])  # fmt: skip
        stripe.rgba = [0.2, 0.2, 0.2, 1]
        stripe.mass = 0


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """On the plane, rolling at v0 (ω = v0 / R), eccentric mass straight up; racers alike."""
    data.qpos[:] = 0.0
    for k in range(model.nv // 3):
        data.qvel[3 * k : 3 * k + 3] = [v["v0"], 0.0, v["v0"] / v["R"]]
    _settle(model, data)


def _settle(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Sink every body to its static penetration (a few µm), where the contact carries it.

    Started just touching, the cylinder would fall onto the plane while N builds up from
    0, slip meanwhile (μ N is small), and keep that slip (~3 mm/s near μ_min): friction
    barely corrects a slip velocity (solreffriction, below). Bisection on each z so that
    its acceleration across the plane is 0.
    """
    z = np.arange(1, model.nv, 3)  # the z slide of each body (x, z, spin)
    lo, hi = np.full(len(z), -0.01), np.zeros(len(z))  # pushed out at lo, falling at hi
    for _ in range(40):
        data.qpos[z] = 0.5 * (lo + hi)
        mujoco.mj_forward(model, data)
        out = data.qacc[z] > 0
        lo = np.where(out, data.qpos[z], lo)
        hi = np.where(out, hi, data.qpos[z])
    data.qpos[z] = 0.5 * (lo + hi)
    mujoco.mj_forward(model, data)
    data.qacc_warmstart[:] = data.qacc


# -- readouts ---------------------------------------------------------------------------------
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
    from sandbox.physics.kinematics import Kinematics

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
    scratch = _scratch(m)
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


_SCRATCH: dict[int, tuple[mujoco.MjModel, mujoco.MjData]] = {}


def _scratch(model: mujoco.MjModel) -> mujoco.MjData:
    """A reusable MjData for ``model`` (allocating one per readout costs more than using it)."""
    entry = _SCRATCH.get(id(model))
    if entry is None or entry[0] is not model:
        if len(_SCRATCH) > 16:
            _SCRATCH.clear()
        entry = _SCRATCH[id(model)] = (model, mujoco.MjData(model))
    return entry[1]


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


def past_the_plane(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> bool:
    """Whether the run is over: every rolling body's centre past the plane's far end (in a
    race, the last one too). The web page then starts the descent again."""
    end = v["plane_length"] - 0.5
    for name in ("x", *(f"x_{racer}" for racer, _ in RACERS)):
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j >= 0 and float(data.qpos[model.jnt_qposadr[j]]) <= end:
            return False
    return True


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
    SceneReadout("penetration", "m", "Depth of the cylinder in the plane: a few µm at 1 ms; centimetres mean the timestep is far too large.", _penetration, label="Enfoncement dans le plan", hint="Enfoncement du cylindre dans le plan : quelques µm à 1 ms, des centimètres signalent un pas de temps bien trop grand."),
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


def _accel_error(series, values) -> float:
    """max |a − a_ref| / max |a_ref| over the run (NaN references, off the plane, skipped)."""
    ref = np.asarray(series["a_ref"], dtype=float)
    ok = np.isfinite(ref)
    if not ok.any():
        return math.nan
    gap = np.abs(np.asarray(series["a"], dtype=float)[ok] - ref[ok])
    return float(np.max(gap) / max(float(np.max(np.abs(ref[ok]))), 1e-300))


ACCURACY_VALUES = {"eccentric_mass": 0.5, "eccentric_radius": 0.07, "slope_deg": 10.0, "mu": 1.0}
"""The benchmark's cylinder: 0.5 kg at 70 mm from the axis, rolling down 10° (μ = 1) until
it leaves the plane at 1.86 s. A homogeneous cylinder keeps T + V to 1e-3 with any
integrator at 1 ms; this one separates them."""


SCENE = Scene(
    name="rolling_cylinder",
    overlay={"v": "v", "a": "a", "contact": "Contact"},
    title="Cylindre qui roule : V(A∈S) et V(A), frottement, énergie",
    summary=(
        "A cylinder rolls (or slips) down an inclined plane. The material point at the "
        "contact is at rest while the geometric contact point runs with the axis."
    ),
    mjcf="rolling_cylinder.xml",
    params=PARAMS,
    effects=Effects(gravity=True, contacts=True, actuation=False),
    readouts=READOUTS,
    edit=edit,
    initial_state=initial_state,
    reference=reference,
    # RK4 at 1 ms (sandbox bench, measured on the eccentric cylinder of ACCURACY_VALUES):
    # the contact solve sets velocities and forces, so every integrator gives the same
    # acceleration at 1 ms, but a first-order position update puts x half a step ahead of
    # v, and with an eccentric mass V swings fast with the rotation: T + V drifts by 1.1 %
    # of T with implicitfast at 1 ms (0.5 % needs 0.4 ms, 2.5 times the cost), 8e-5 with
    # RK4 at 1 ms, 3.5 times implicitfast's stepping cost (but half of a web session's CPU
    # is readouts: 111x -> 59x real time). RK4 keeps T + V within 1.1e-3 of T at every
    # corner of the sliders (tests/scenes/test_rolling_cylinder.py); implicitfast misses
    # 0.5 % at 8 of those 384 corners. 1 ms, because MuJoCo stiffens a contact only down to
    # solref = 2 h: at 3 ms the rolling error grows to 1.8e-4, and at 2 ms a heavy mass
    # balanced on top of a thin cylinder already drifts 4.6e-3.
    integrator="rk4",
    timestep=1e-3,
    # Beyond 20 ms the contact softens (penetration 2.5 mm, acceleration -0.8 %; -22 % at
    # 0.1 s): nothing explodes, so such timesteps are refused rather than detected.
    max_timestep=0.02,
    plots=("v", "slip_velocity", "mu_required"),
    study_presets=(
        StudyPreset(
            "Accélération selon la pente, de part et d'autre du glissement",
            ("slope_deg", 2.0, 60.0, 30),
            "a",
            duration=0.3,
            hint="Tant que μ suffit, le cylindre roule : a = g·sin α / (1 + I/(m·R²)). "
            "Au-delà de tan α = 3μ (cylindre plein), il glisse : a = g·(sin α − μ·cos α).",
        ),
    ),
    xy_presets=(
        XYPreset(
            "Vitesse selon la distance parcourue",
            "x",
            ("v",),
            hint="Sous accélération constante, v² croît comme x : la courbe est une "
            "demi-parabole couchée.",
        ),
        XYPreset(
            "Accélération au cours du temps",
            "time",
            ("a",),
            hint="L'accélération du centre ; en tirets, celle du cours (roulement sans "
            "glissement ou glissement selon μ).",
        ),
    ),
    arrows=ARROWS,
    body_frame="cylinder",
    sections="3.2, 6.1.3, 6.2",
    camera=((0.1, -1.0, 0.25), (0.0, 0.0, 1.0)),
    look_at=((0.5, 0.0, -0.15), 1.3),
    leaves_view=True,
    run_ended=past_the_plane,
    extra={"solid_names": {"cylinder": "cylindre", "eccentric": "masse excentrée"}},
    # Round-off: an absent eccentric mass is a 1e-9 kg point, which leaves 1e-9 N·m in
    # V(A) ∧ m V(G) where the course has 0 (δ in A is a few N·m).
    zero={"N": 1e-9, "N·m": 1e-8, "W": 1e-9, "J": 1e-12, "kg·m/s": 1e-12, "kg·m²/s": 1e-12},
    accuracy=Accuracy(
        key="a",
        readouts=("a", "a_ref", "T", "V"),
        duration=1.8,  # it leaves the plane at 1.86 s
        values=ACCURACY_VALUES,
        error=_accel_error,
        invariant="T + V (rolling, eccentric mass)",
        drift=energy_drift(),
        settle=0.01,
        drift_tol=5e-3,  # the course's energy theorem while rolling, to 0.5 %
    ),
)
