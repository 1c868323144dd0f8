"""Inline engine with 1, 2 or 4 cylinders (course sections 1, 7.3 and figure 1).

Each cylinder is the compressor's slider-crank (:mod:`sandbox.scenes.compressor`): crank
radius R, rod 2 (mass m2, AG2 = d2, I_A,z = C2), piston 3 (mass m3); the cylinders stand
along y0 in the planes z = z_i of the crankshaft (axis z0), a apart, around the block's
centre C (the origin). Throws at 0° (one cylinder), 0-180° (twin) and 0-180-180-0° (the
flat-crank four of figure 1). Each throw carries its share of crank mass m1 at d1 and a
counterweight at R opposite its pin that balances the fraction k_r of the rotating mass
and k_a of the reciprocating one (the course's "balourd", section 1). The Lanchester
option adds two shafts below the crank, geared to it at +2ω and −2ω (joint equalities),
whose unbalance cancels the two-term second-order pilon. A velocity servo holds the
crankshaft at ``speed_rpm``; the block is the frame. Weight neglected, perfect joints,
links never touch.

Readouts and how they are measured:

- ``pilon`` / ``tamis``: force of the moving parts on the block along y0 / x0, minus the
  frame's action on the mechanism (``s.support``: joint and closure reactions).
- ``pilon_1`` .. ``pilon_4``: each cylinder's share (piston, rod, throw, counterweight),
  −Σ m Γ(G)·y0 from the simulated body accelerations; 0 for an absent cylinder (a column
  that always exists keeps CSV files of 1, 2 and 4 cylinders alike). With the shafts'
  own share they add up to ``pilon``, a second route to the same force.
- ``shaking_force_h1`` / ``_h2``: amplitudes of orders 1 and 2 of the simulated pilon over
  one revolution: the revolution is simulated ahead on a scratch copy of the state (the
  trajectory is untouched, cached while model, parameters and speed stay), and the
  samples are projected on cos kθ, sin kθ by least squares (the compressor's
  :func:`~sandbox.scenes.compressor.fit_orders`). Their course values are the exact
  slider-crank's orders (:func:`sandbox.mechanics.engine.pilon_orders`); the two-term
  formula m R ω² λ of the second order is 1.9 % lower at the default λ = 0.27.
- ``shaking_moment``: norm of the rocking moment on the block about C, its components
  along x0 (pitch, from the pilons) and y0 (yaw, from the tamis); the moment along the
  crankshaft z0 (the motor's reaction) is left out, as in the course's balancing.
  ``shaking_moment_max`` is its largest value over a revolution, from the same simulated
  revolution (orders 0..4 of each component evaluated densely).

C2 stops at 5e-3 kg·m² (77 times the default rod): the rods' swing then makes the
crank's inertia vary so much that the servo lets the speed ripple by 0.6 %, which the
constant-speed references see as a 0.3 % gap on the pilon.

The references take the engine at constant ω (:class:`sandbox.mechanics.engine.Engine`)
at the measured speed; the servo holds it within 3e-4 of its set point (four cylinders,
3000 rpm), so the gap is the simulation's own error. Measured with RK4 at the default
step (7e-4 s at 3000 rpm, 1e-4 s at 17,000 rpm): pilon within 5e-4 of its peak, orders 1
and 2 and the largest rocking moment within 1.5e-4 of the course's, loops closed to 1.1e-6
m (7.8e-7 m at 17,000 rpm), |P_int| below 1e-4 of the shaft's power; the four cylinders
run 31 times faster than real time on one core (25 times with the web page's readouts).
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import BadParameter
from sandbox.mechanics.engine import (
    THROWS_DEG,
    Engine,
    lanchester_unbalance,
    pilon_orders,
    shaking_force,
    shaking_moment,
)
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.torsors import joint_drive
from sandbox.scenes import compressor
from sandbox.scenes.base import (
    Accuracy,
    Arrow,
    Effects,
    Param,
    Scene,
    SceneReadout,
    Values,
    per_revolution_timestep,
)
from sandbox.scenes.compressor import RPM, fit_orders, kinematics
from sandbox.scenes.measures import largest, residual_over_peak
from sandbox.scenes.presets import StudyPreset, XYPreset
from sandbox.scenes.revolutions import PerModel

MAX_CYLINDERS = 4
SHAFT_ECCENTRICITY = 0.01
"""Distance [m] of each Lanchester shaft's unbalance from its axis."""
DENSE = 720
"""Angles at which a revolution's fitted moment is evaluated for its largest value."""


def _p(name: str, unit: str, default: float, lo: float, hi: float, doc: str, **kw: Any) -> Param:
    return Param(name, unit, default, lo, hi, doc, **kw)


DRIVE, GEOMETRY, MASSES, BALANCE = "Entraînement", "Géométrie", "Masses", "Équilibrage"

PARAMS = (
    _p("speed_rpm", "rpm", 3000.0, 0.0, 17000.0, "Crankshaft speed held by the motor.", live=True, step=50.0, label="Vitesse du vilebrequin ω", hint="Vitesse de rotation que le moteur impose au vilebrequin.", group=DRIVE),
    _p("cylinders", "", 4.0, 1.0, 4.0, "Number of cylinders in line: 1, 2 (throws 0-180) or 4 (flat crank 0-180-180-0).", step=1.0, label="Nombre de cylindres n", hint="Un, deux ou quatre cylindres en ligne, manetons à 0-180 ou 0-180-180-0 degrés.", group=GEOMETRY),
    _p("R", "m", 0.015, 0.005, 0.05, "Crank radius OA of every throw.", step=0.0005, label="Rayon de manivelle R", hint="Distance OA entre l'axe du vilebrequin et chaque maneton.", group=GEOMETRY),
    _p("L", "m", 0.055, 0.0055, 0.25, "Rod length AB (must exceed R).", step=0.0005, label="Longueur de bielle L", hint="Longueur AB de chaque bielle, qui doit dépasser R.", group=GEOMETRY),
    _p("spacing", "m", 0.06, 0.02, 0.3, "Distance a between neighbouring cylinders along the crankshaft.", step=0.005, label="Entraxe des cylindres a", hint="Distance entre deux cylindres voisins le long de l'axe du vilebrequin.", group=GEOMETRY),
    _p("m1", "kg", 0.2, 0.0, 2.0, "Crank mass of one throw (its web and pin).", step=0.005, label="Masse d'un bras de manivelle m₁", hint="Masse du bras et du maneton d'un cylindre, sans le contrepoids.", group=MASSES, advanced=True),
    _p("d1", "m", 0.005, 0.0, 0.05, "Distance from the crankshaft's axis to the centre of mass of one throw.", step=0.0005, label="Position de G₁ d₁", hint="Distance du centre de gravité d'un bras de manivelle à l'axe du vilebrequin.", group=MASSES, advanced=True),
    _p("m2", "kg", 0.06, 0.001, 2.0, "Mass of one rod.", step=0.005, label="Masse d'une bielle m₂", hint="Masse de chaque bielle.", group=MASSES),
    _p("d2", "m", 0.02, 0.0, 0.25, "AG2: rod centre of mass from the crank pin A.", step=0.0005, label="Position de G₂ d₂", hint="Distance AG₂ du centre de gravité de la bielle depuis le maneton A.", group=MASSES, advanced=True),
    _p("C2", "kg·m²", 6.5e-5, 1e-7, 5e-3, "Rod inertia about (A, z0).", step=1e-7, label="Moment d'inertie C₂", hint="Moment d'inertie d'une bielle autour de l'axe (A, z₀), parallèle au vilebrequin.", group=MASSES, advanced=True, log=True),
    _p("m3", "kg", 0.08, 0.001, 2.0, "Mass of one piston.", step=0.005, label="Masse d'un piston m₃", hint="Masse de chaque piston, en translation le long de y₀.", group=MASSES),
    _p("counterweight_rot", "", 1.0, 0.0, 1.0, "Counterweight per throw, fraction of the rotating mass balanced.", step=0.05, label="Part équilibrée des masses tournantes kᵣ", hint="Fraction de la masse tournante de chaque manivelle que son contrepoids compense.", group=BALANCE),
    _p("counterweight_rec", "", 0.0, 0.0, 1.0, "Counterweight per throw, fraction of the reciprocating mass balanced.", step=0.05, label="Part équilibrée des masses alternatives kₐ", hint="Fraction de la masse alternative de chaque cylindre que son contrepoids compense, au prix d'un tamis.", group=BALANCE),
    _p("lanchester", "", 0.0, 0.0, 1.0, "0: none; 1: two balance shafts at twice the crank speed (Lanchester).", step=1.0, label="Arbres d'équilibrage de Lanchester", hint="Deux arbres à balourd tournant en sens contraires à deux fois la vitesse du vilebrequin.", group=BALANCE, choices=("Sans", "Avec")),
    _p("motor_inertia", "kg·m²", 0.02, 0.0, 0.2, "Inertia of the motor's rotor, turning with the crankshaft (a joint armature).", step=0.001, label="Inertie du rotor du moteur J", hint="Moment d'inertie du rotor du moteur, qui tourne avec le vilebrequin.", group=DRIVE, advanced=True),
)  # fmt: skip

DEFAULTS = {p.name: p.default for p in PARAMS}


# -- closed form --------------------------------------------------------------------------
def cylinder_count(v: Values) -> int:
    """The number of cylinders, 1, 2 or 4.

    Raises:
        BadParameter: for 3 or a fraction (one line naming the fix).
    """
    n = v["cylinders"]
    if n not in (1.0, 2.0, 4.0):
        raise BadParameter(
            f"cylinders = {n:g} is not offered: lower it to 2 or raise it to 4 "
            "(inline engines of 1, 2 or 4 cylinders)"
        )
    return int(n)


def masses(v: Values) -> tuple[float, float]:
    """(m, m_rot) [kg]: reciprocating mass m3 + m2 d2/L at the piston pin and rotating
    mass m1 d1/R + m2 (1 − d2/L) at the crank pin, per cylinder (the rod split in two
    point masses keeps its centre of mass, hence every force)."""
    w = v["d2"] / v["L"]
    return v["m3"] + v["m2"] * w, v["m1"] * v["d1"] / v["R"] + v["m2"] * (1 - w)


def engine_of(v: Values, omega: float | None = None) -> Engine:
    """The course's engine for the parameters ``v`` at ``omega`` [rad/s] (default: the
    set point)."""
    m, m_rot = masses(v)
    w = v["speed_rpm"] * RPM if omega is None else abs(omega)
    return Engine(
        cylinder_count(v), v["R"], v["L"], m, w, spacing=v["spacing"], m_rot=m_rot,
        k_rot=v["counterweight_rot"], k_rec=v["counterweight_rec"],
        balance_shaft=1.0 if v["lanchester"] >= 0.5 else 0.0,
    )  # fmt: skip


def counterweight_mass(v: Values) -> float:
    """Counterweight at R opposite each pin [kg]: k_r m_rot + k_a m."""
    m, m_rot = masses(v)
    return v["counterweight_rot"] * m_rot + v["counterweight_rec"] * m


def reference(v: Values) -> dict[str, float]:
    """Course values at the set point: ω, the exact pilon's orders 1 and 2 and the rocking
    moment's largest value over a revolution."""
    from sandbox.mechanics.engine import shaking_moment_amplitude

    e = engine_of(v)
    orders = pilon_orders(e)
    return {
        "omega": e.omega,
        "shaking_force_h1": float(orders[1]),
        "shaking_force_h2": float(orders[2]),
        "shaking_moment_max": shaking_moment_amplitude(e),
    }


def motor_torque_ref(theta_c: float, omega: float, v: Values) -> float:
    """C_mot at constant ω [N·m]: the compressor's (dT/dt)/ω summed over the cylinders at
    θ_c − φ_i (the shafts at constant speed need none)."""
    one = {"R": v["R"], "L": v["L"], "d2": v["d2"], "m2": v["m2"], "m3": v["m3"],
           "C2": v["C2"], "C1": 0.0, "counterweight_mass": 0.0, "counterweight_radius": 0.0}  # fmt: skip
    phis = np.radians(THROWS_DEG[cylinder_count(v)])
    return float(sum(compressor.motor_torque(theta_c - p, omega, one) for p in phis))


# -- model ---------------------------------------------------------------------------------
def _check(v: Values) -> None:
    cylinder_count(v)
    if v["L"] <= v["R"] * 1.0001:
        raise BadParameter(
            f"the rod (L = {v['L']:g} m) must be longer than the crank (R = {v['R']:g} m); "
            "raise L or lower R"
        )
    if v["d2"] > v["L"]:
        raise BadParameter(
            f"the rod's centre of mass (d2 = {v['d2']:g} m) must lie between A and B "
            f"(L = {v['L']:g} m); lower d2 or raise L"
        )
    if v["C2"] <= v["m2"] * v["d2"] ** 2 * 1.0001:
        raise BadParameter(
            f"C2 = {v['C2']:g} kg·m² is below m2·d2² = {v['m2'] * v['d2'] ** 2:g} kg·m², an "
            "impossible rod; raise C2 or lower m2 or d2"
        )


def positions(n: int, spacing: float) -> np.ndarray:
    """z_i [m] of the cylinders about C."""
    return (np.arange(n) - (n - 1) / 2) * spacing


def _inertial(body: mujoco.MjsBody, mass: float, pos: list[float], diag: list[float]) -> None:
    body.explicitinertial = True
    body.mass = mass
    body.ipos = pos
    body.fullinertia = [*diag, 0.0, 0.0, 0.0]


def _delete_body(spec: mujoco.MjSpec, name: str) -> None:
    body = spec.body(name)
    if body is not None:
        spec.delete(body)


def edit(spec: mujoco.MjSpec, v: Values) -> None:
    """Keep the cylinders asked for (and the shafts when ``lanchester`` is on), then set
    their positions, lengths, masses and inertias."""
    _check(v)
    n = cylinder_count(v)
    for i in range(n + 1, MAX_CYLINDERS + 1):
        for name in (f"piston_{i}", f"throw_{i}", f"cw_{i}"):
            _delete_body(spec, name)
        spec.delete(spec.geom(f"bore_{i}"))
    shafts = v["lanchester"] >= 0.5
    if not shafts:
        for i in (1, 2):
            _delete_body(spec, f"shaft_{i}")
    # Equalities tied to deleted sites or joints go with them; drop any left over.
    kept = {f"closure_{i}" for i in range(1, n + 1)} | ({"gear_1", "gear_2"} if shafts else set())
    for eq in [e for e in spec.equalities if e.name not in kept]:
        spec.delete(eq)
    R, L, d2, m2, m3 = v["R"], v["L"], v["d2"], v["m2"], v["m3"]
    m_cw = counterweight_mass(v)
    zs = positions(n, v["spacing"])
    half = max(abs(zs[0]), 0.0) + 0.05
    spec.geom("block").size = [0.045, 0.012, half]
    spec.geom("shaft").fromto = [0, 0, -half, 0, 0, half]
    for i, (z, phi) in enumerate(zip(zs, THROWS_DEG[n], strict=True), start=1):
        sign = 1.0 if phi == 0.0 else -1.0  # the pin's side along x of the crank's frame
        throw = spec.body(f"throw_{i}")
        throw.pos = [0, 0, z]
        _inertial(throw, max(v["m1"], 1e-9), [sign * v["d1"], 0, 0], [1e-12] * 3)
        spec.site(f"A_crank_{i}").pos = [sign * R, 0, 0]
        spec.geom(f"pin_{i}").pos = [sign * R, 0, 0]
        web = spec.geom(f"web_{i}")
        web.pos = [sign * R / 2, 0, -0.008]
        web.size = [R / 2 + 0.006, 0.008, 0.003]
        cw = spec.body(f"cw_{i}")
        cw.pos = [-sign * R, 0, z]
        _inertial(cw, max(m_cw, 1e-9), [0, 0, 0], [m_cw * 1e-6 + 1e-12] * 3)
        spec.geom(f"cw_{i}").rgba = [0.3, 0.3, 0.8, 1.0 if m_cw > 0 else 0.15]
        piston = spec.body(f"piston_{i}")
        piston.pos = [0, 0, z]
        _inertial(piston, m3, [0, 0, 0], [m3 * 1e-4] * 3)
        rod = spec.body(f"rod_{i}")
        i_g = v["C2"] - m2 * d2 * d2
        _inertial(rod, m2, [0, -L + d2, 0], [i_g, m2 * 1e-5 + 1e-12, i_g])
        spec.site(f"A_rod_{i}").pos = [0, -L, 0]
        spec.geom(f"rod_{i}").fromto = [0, 0, 0, 0, -L, 0]
        bore = spec.geom(f"bore_{i}")
        bore.pos = [0, L + R + 0.01, z]
        bore.size = [0.022, R + 0.02, 0]
    if shafts:
        me = lanchester_unbalance(engine_of(v))
        for i in (1, 2):
            body = spec.body(f"shaft_{i}")
            body.pos = [0.05 * (1 if i == 1 else -1), -R - 0.03, 0]
            mass = max(me / SHAFT_ECCENTRICITY, 1e-9)
            _inertial(body, mass, [0, SHAFT_ECCENTRICITY, 0], [mass * 1e-6 + 1e-12] * 3)
    spec.joint("crank").armature = v["motor_inertia"]


def _crank_inertia(v: Values) -> float:
    """Inertia the servo sees on the crank axis [kg·m²] (rotor, throws, counterweights,
    rods' big ends and the shafts through their 2:1 gears), for its gain."""
    n = cylinder_count(v)
    m, m_rot = masses(v)
    per = v["m1"] * v["d1"] ** 2 + (counterweight_mass(v) + m_rot + m) * v["R"] ** 2
    per += v["C2"] * (v["R"] / v["L"]) ** 2  # the rod's swing, φ' up to ω R / L
    shafts = 0.0
    if v["lanchester"] >= 0.5:
        shafts = 2 * 4 * lanchester_unbalance(engine_of(v)) * SHAFT_ECCENTRICITY
    return v["motor_inertia"] + 1e-4 + n * per + shafts


def drive(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """Motor set point; servo gain and constraint stiffness follow the timestep (the
    compressor's choices: servo time constant 0.7 dt, closures and gears 5 dt)."""
    dt = float(model.opt.timestep)
    kv = compressor.SERVO_STIFFNESS * _crank_inertia(v) / dt
    model.actuator_gainprm[0, 0] = kv
    model.actuator_biasprm[0, :3] = [0.0, 0.0, -kv]
    model.eq_solref[:] = [compressor.CLOSURE_TIMECONST * dt, 1.0]
    model.eq_solimp[:, :3] = [0.9999, 0.9999, 0.001]
    data.ctrl[0] = v["speed_rpm"] * RPM


def set_state(model: mujoco.MjModel, data: mujoco.MjData, theta: float, omega: float,
              v: Values) -> None:  # fmt: skip
    """Every loop closed at engine angle θ (cylinder 1 from its top dead centre) and speed
    ω, shafts in phase."""
    n = cylinder_count(v)
    theta_c = theta + math.pi / 2  # the compressor's angle, from x0
    qpos, qvel = data.qpos, data.qvel

    def put(joint: str, q: float, dq: float) -> None:
        j = model.joint(joint)
        qpos[model.jnt_qposadr[j.id]] = q
        qvel[model.jnt_dofadr[j.id]] = dq

    put("crank", theta_c, omega)
    for i, phi in enumerate(np.radians(THROWS_DEG[n]), start=1):
        k = kinematics(theta_c - phi, omega, v["R"], v["L"])
        put(f"piston_{i}", k.lam, k.dlam)
        put(f"rod_{i}", k.phi, k.dphi)
    if v["lanchester"] >= 0.5:
        put("shaft_1", 2 * theta_c, 2 * omega)
        put("shaft_2", -2 * theta_c, -2 * omega)


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """At speed, cylinder 1 at its top dead centre."""
    set_state(model, data, 0.0, v["speed_rpm"] * RPM, v)


STEP_ANGLE = 0.22
"""Crank angle per RK4 step [rad]: 7e-4 s at 3000 rpm (ω dt = 0.22), whose four
cylinders then run 30 times faster than real time; measured there: pilon within 5.3e-4
of its peak, |P_int| within 6.3e-5 of the shaft's power, loops closed to 1.1e-6 m. At
17,000 rpm the rounding (:func:`~sandbox.scenes.base.per_revolution_timestep`) gives
1e-4 s (ω dt = 0.18, the compressor's): pilon 3.9e-4, loops 7.8e-7 m."""


def default_timestep(v: Values, data: mujoco.MjData | None = None) -> float:
    """RK4 timestep [s] turning the crank by at most :data:`STEP_ANGLE` per step at
    ``speed_rpm`` (the compressor's rule, :func:`sandbox.scenes.compressor.default_timestep`,
    with a larger angle): 7e-4 s at 3000 rpm, 1e-4 s at 17,000 rpm; shorter for a rod
    much shorter than the default one, and kept short while a crank faster than its set
    point slows down."""
    cos_max = math.sqrt(max(1.0 - (v["R"] / v["L"]) ** 2, 1e-4))
    cos_default = math.sqrt(1.0 - (DEFAULTS["R"] / DEFAULTS["L"]) ** 2)
    angle = STEP_ANGLE * min(1.0, cos_max / cos_default)
    omega = v["speed_rpm"] * RPM
    if data is not None:
        omega = max(omega, abs(float(data.qvel[0])) / compressor.FASTER)
    return per_revolution_timestep(angle, omega, largest=compressor.LARGEST_TIMESTEP)


# -- readouts ------------------------------------------------------------------------------
def _theta_c(s: Snapshot) -> float:
    return s.joint_qpos("crank")


def _theta(s: Snapshot) -> float:
    return _theta_c(s) - math.pi / 2


def _engine(s: Snapshot) -> Engine:
    return engine_of(s.values, s.joint_qvel("crank"))


def _block(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """(force, moment at C) of the moving parts on the block: minus the frame's action."""
    r, m = s.support
    return -np.asarray(r), -np.asarray(m)


def _cylinder_pilons(s: Snapshot) -> np.ndarray:
    """Each cylinder's −Σ m Γ(G)·y0 [N], 0 for the absent ones, shape (4,): computed once a
    snapshot for the four readouts that read it."""
    cached = s.cache.get("engine_pilons")
    if cached is not None:
        return cached
    out = s.cache["engine_pilons"] = np.zeros(MAX_CYLINDERS)
    acc = s.kinematics.a_g
    mass = s.model.body_mass
    for i in range(1, cylinder_count(s.values) + 1):
        ids = [s.body_id(f"{b}_{i}") for b in ("piston", "rod", "throw", "cw")]
        out[i - 1] = -float(mass[ids] @ acc[ids, 1])
    return out


def _closure(s: Snapshot) -> float:
    d, worst = s.data, 0.0
    for i in range(1, cylinder_count(s.values) + 1):
        a = d.site(f"A_crank_{i}").xpos
        b = d.site(f"A_rod_{i}").xpos
        worst = max(worst, float(np.linalg.norm(a - b)))
    return worst


_REVOLUTIONS: PerModel[dict[str, np.ndarray]] = PerModel()
_FITS: dict[int, tuple[dict[str, np.ndarray], np.ndarray]] = {}


def revolution(s: Snapshot) -> dict[str, np.ndarray]:
    """One revolution simulated ahead from the current state on a scratch copy (the
    trajectory is untouched), one sample per step (at most 64 per turn): engine angle
    [deg], pilon, tamis, moment at C (x0, y0) and motor torque, with the course's values
    at the same angles. Cached while model, parameters, timestep and speed (to 0.1 %)
    stay the same: at constant speed every revolution is the same."""
    from sandbox.physics import torsors as generic

    model, v = s.model, s.values
    omega = s.joint_qvel("crank")
    kept = _REVOLUTIONS.get(model, v, omega, float(s.data.time))
    if kept is not None:
        return kept
    data = mujoco.MjData(model)
    mujoco.mj_copyData(data, model, s.data)
    period = 2 * math.pi / max(abs(omega), 1e-9)
    per = max(1, int(round(period / 64 / model.opt.timestep)))
    rows = []
    start = float(s.data.time)
    while data.time < start + period - 0.5 * model.opt.timestep and abs(omega) > 1e-6:
        mujoco.mj_forward(model, data)
        mujoco.mj_rnePostConstraint(model, data)
        r, m = generic.support_torsor(model, data)
        theta_c, w = float(data.qpos[0]), float(data.qvel[0])
        e = engine_of(v, w)
        ref_f = shaking_force(e, theta_c - math.pi / 2)
        ref_m = shaking_moment(e, theta_c - math.pi / 2)
        rows.append((theta_c - math.pi / 2, -r[1], -r[0], -m[0], -m[1],
                     float(joint_drive(model, data)[0]), ref_f[1], ref_f[0], ref_m[0], ref_m[1],
                     motor_torque_ref(theta_c, w, v)))  # fmt: skip
        mujoco.mj_step(model, data, per)
    a = np.array(rows, dtype=float).reshape(-1, 11)
    a = a[np.argsort(np.mod(a[:, 0], 2 * math.pi))]
    out = {
        "angle_deg": np.degrees(np.mod(a[:, 0], 2 * math.pi)),
        "theta": a[:, 0],
        "pilon": a[:, 1],
        "tamis": a[:, 2],
        "moment_x": a[:, 3],
        "moment_y": a[:, 4],
        "motor_torque": a[:, 5],
        "pilon_ref": a[:, 6],
        "tamis_ref": a[:, 7],
        "moment_x_ref": a[:, 8],
        "moment_y_ref": a[:, 9],
        "motor_torque_ref": a[:, 10],
    }
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


def _orders(s: Snapshot) -> np.ndarray:
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
    resolution = float(np.abs(rev["pilon"] - rev["pilon_ref"]).max())
    amp = np.where(amp[:3] <= resolution, 0.0, amp[:3])
    dense = np.linspace(0, 2 * math.pi, DENSE, endpoint=False)
    mx = _evaluate(_series(theta, rev["moment_x"]), dense)
    my = _evaluate(_series(theta, rev["moment_y"]), dense)
    out = np.array([amp[1], amp[2], float(np.hypot(mx, my).max())])
    _FITS[id(rev)] = (rev, out)
    return out


def _force_ref(s: Snapshot) -> np.ndarray:
    """The course's force on the block at the snapshot's angle and speed (tamis, pilon)."""
    out = s.cache.get("engine_force_ref")
    if out is None:
        out = s.cache["engine_force_ref"] = shaking_force(_engine(s), _theta(s))
    return out


def _pilon_ref(s: Snapshot) -> float:
    return float(_force_ref(s)[1])


def _tamis_ref(s: Snapshot) -> float:
    return float(_force_ref(s)[0])


def _moment_ref(s: Snapshot) -> float:
    return float(np.linalg.norm(shaking_moment(_engine(s), _theta(s))))


def _pilon_i(i: int) -> SceneReadout:
    return SceneReadout(
        f"pilon_{i}", "N",
        f"Share of cylinder {i} in the pilon: -sum m Gamma(G).y0 of its piston, rod, throw and counterweight (0 when absent).",
        lambda s: float(_cylinder_pilons(s)[i - 1]),
        label=f"Pilon du cylindre {i}",
        hint=f"Part du cylindre {i} dans l'effet de pilon, nulle quand ce cylindre n'existe pas.",
    )  # fmt: skip


READOUTS = (
    SceneReadout("theta", "rad", "Engine angle θ: cylinder 1's crank from its top dead centre (unwrapped).", _theta, label="Angle du vilebrequin θ", hint="Angle de la manivelle du premier cylindre depuis son point mort haut, qui croît tour après tour."),
    SceneReadout("omega", "rad/s", "Crankshaft speed θ'.", lambda s: s.joint_qvel("crank"), label="Vitesse mesurée du vilebrequin ω", hint="Vitesse de rotation θ' du vilebrequin par rapport au bloc moteur."),
    SceneReadout("pilon", "N", "Force of the moving parts on the block along y0 (the cylinders' axis).", lambda s: float(_block(s)[0][1]), label="Effet de pilon", hint="Effort des pièces mobiles sur le bloc moteur le long de l'axe des cylindres y₀."),
    SceneReadout("tamis", "N", "Force of the moving parts on the block along x0 (across the cylinders).", lambda s: float(_block(s)[0][0]), label="Effet de tamis", hint="Effort des pièces mobiles sur le bloc moteur perpendiculairement aux cylindres, le long de x₀."),
    SceneReadout("pilon_ref", "N", "Course value of the pilon at the current angle and speed (exact slider-cranks, constant speed).", _pilon_ref, label="Pilon selon le cours", hint="Pilon calculé par le cours pour les systèmes bielle-manivelle exacts, à l'angle et à la vitesse actuels."),
    SceneReadout("tamis_ref", "N", "Course value of the tamis at the current angle and speed (as pilon_ref): zero when the counterweights balance the rotating masses exactly, and for two or four cylinders whatever they balance (their throws cancel the first order).", _tamis_ref, label="Tamis selon le cours", hint="Tamis calculé par le cours, nul quand les contrepoids compensent juste les masses tournantes ou quand les manivelles sont opposées deux à deux."),
    *(_pilon_i(i) for i in range(1, MAX_CYLINDERS + 1)),
    SceneReadout("shaking_force_h1", "N", "Order-1 amplitude of the pilon over a revolution simulated ahead (least-squares projection).", lambda s: float(_orders(s)[0]), label="Pilon, ordre 1", hint="Amplitude de la composante du pilon à la fréquence de rotation, sur un tour simulé."),
    SceneReadout("shaking_force_h2", "N", "Order-2 amplitude of the pilon over a revolution simulated ahead (as shaking_force_h1).", lambda s: float(_orders(s)[1]), label="Pilon, ordre 2", hint="Amplitude de la composante du pilon à deux fois la fréquence de rotation, sur un tour simulé."),
    SceneReadout("shaking_moment", "N·m", "Rocking moment of the moving parts on the block about its centre C (norm of its x0 and y0 components).", lambda s: float(np.hypot(*_block(s)[1][:2])), label="Moment de basculement en C", hint="Moment des pièces mobiles sur le bloc moteur en son centre C, autour des axes x₀ et y₀."),
    SceneReadout("shaking_moment_ref", "N·m", "Course value of the rocking moment at the current angle and speed.", _moment_ref, label="Moment de basculement selon le cours", hint="Moment de basculement en C calculé par le cours à l'angle et à la vitesse actuels."),
    SceneReadout("shaking_moment_max", "N·m", "Largest rocking moment over a revolution simulated ahead.", lambda s: float(_orders(s)[2]), label="Moment de basculement maximal", hint="Plus grande valeur du moment de basculement en C sur un tour simulé."),
    SceneReadout("motor_torque", "N·m", "Torque of the motor on the crankshaft (its rotor's own inertia excluded).", lambda s: float(joint_drive(s.model, s.data)[0]), label="Couple moteur Cₘₒₜ", hint="Couple que le moteur transmet au vilebrequin, sans celui qui accélère son propre rotor."),
    SceneReadout("closure_error", "m", "Largest distance between a rod's end and its crank pin.", _closure, label="Écart de fermeture des boucles", hint="Plus grande distance entre l'extrémité d'une bielle et son maneton, quasi nulle quand les chaînes restent fermées."),
)  # fmt: skip

FORCE_SCALE = 3e-4
"""Metres of arrow per newton."""
MOMENT_SCALE = 1e-2
"""Metres of arrow per newton-metre."""


def _at_c(vec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(3), np.array([vec[0], vec[1], 0.0])


ARROWS = (
    Arrow("frame_force", "Effort sur le bloc", (220, 60, 60), lambda s: _at_c(_block(s)[0]), FORCE_SCALE, unit="N", point="C", hint="Effort des pièces mobiles sur le bloc moteur, pilon et tamis ensemble (rouge)."),
    Arrow("shaking_moment", "Moment de basculement", (120, 60, 160), lambda s: _at_c(_block(s)[1]), MOMENT_SCALE, unit="N·m", point="C", hint="Moment de basculement des pièces mobiles sur le bloc en C, autour de x₀ et y₀ (violet)."),
)  # fmt: skip


SOLID_NAMES = {
    "crank": "1 (vilebrequin)",
    **{f"throw_{i}": f"bras de manivelle {i}" for i in range(1, MAX_CYLINDERS + 1)},
    **{f"cw_{i}": f"contrepoids {i}" for i in range(1, MAX_CYLINDERS + 1)},
    **{f"rod_{i}": f"bielle {i}" for i in range(1, MAX_CYLINDERS + 1)},
    **{f"piston_{i}": f"piston {i}" for i in range(1, MAX_CYLINDERS + 1)},
    "shaft_1": "arbre d'équilibrage 1 (+2ω)",
    "shaft_2": "arbre d'équilibrage 2 (−2ω)",
}
"""French names of the bodies (the web page's solid picker)."""


def _peak_error(series: Any, values: Values) -> float:
    """max |pilon − course| / max |course pilon| over the run."""
    ref = np.asarray(series["pilon_ref"])
    return float(np.max(np.abs(np.asarray(series["pilon"]) - ref)) / np.max(np.abs(ref)))


SCENE = Scene(
    name="engine",
    overlay={
        "omega": "ω",
        "shaking_force_h1": "Pilon, ordre 1",
        "shaking_force_h2": "Pilon, ordre 2",
        "shaking_moment_max": "Basculement maximal",
    },
    title="Moteur en ligne : équilibrage des machines alternatives",
    summary=(
        "One, two or four slider-cranks on one crankshaft, held at constant speed. The "
        "block feels the pilons and their rocking moment: the flat-crank four cancels the "
        "first order and the moment but keeps four times one cylinder's second order, "
        "which counterweights cannot touch and Lanchester shafts at 2ω cancel."
    ),
    mjcf="engine.xml",
    params=PARAMS,
    effects=Effects(gravity=False, contacts=False, equality=True, actuation=True),
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    initial_state=initial_state,
    reference=reference,
    # The compressor's choices: RK4 keeps the closures from draining energy; the same
    # crank angle per step at every speed (7e-4 s at 3000 rpm, 1e-4 s at 17,000 rpm).
    integrator="rk4",
    timestep=7e-4,
    timestep_for=default_timestep,
    # The orders, steady at a steady speed: the pilon itself turns at 50 to 280 Hz, which
    # ten samples a second alias into noise (its curve over a turn is « Sur un tour »).
    plots=("shaking_force_h1", "shaking_force_h2", "shaking_moment_max"),
    study_presets=(
        StudyPreset(
            "Force de secouement d'ordre 2 selon la vitesse",
            ("speed_rpm", 1000.0, 6000.0, 11),
            "shaking_force_h2",
            duration=0.05,
            hint="Dans un moteur à quatre cylindres en ligne, les forces d'ordre 2 des "
            "pistons s'ajoutent : elles croissent comme ω².",
        ),
    ),
    xy_presets=(
        XYPreset(
            "Pilon sur un tour du vilebrequin",
            "theta",
            ("pilon",),
            hint="La somme des effets de pilon des cylindres selon l'angle θ ; en tirets, "
            "celle du cours.",
        ),
        XYPreset(
            "Moment de basculement sur un tour du vilebrequin",
            "theta",
            ("shaking_moment",),
            hint="Le moment que les équipages mobiles exercent sur le bâti selon θ ; en "
            "tirets, celui du cours.",
        ),
    ),
    arrows=ARROWS,
    body_frame="crank",
    sections="1, 7.3, figure 1",
    camera=((1.0, 0.45, 0.8), (0.0, 1.0, 0.0)),
    # framed with room for the arrows: the force on the block reaches ~0.22 m from C
    look_at=((0.0, 0.03, 0.0), 0.42),
    cycle=revolution,
    extra={"solid_names": SOLID_NAMES, "engine": engine_of},
    zero={
        "N": 1e-9,
        "N·m": 1e-10,
        "W": 1e-9,
        "J": 1e-12,
        "kg·m/s": 1e-12,
        "kg·m²/s": 1e-12,
        "m": 1e-15,
    },
    accuracy=Accuracy(
        key="pilon",
        readouts=("pilon", "pilon_ref", "P_int", "P_ext", "closure_error"),
        duration=0.04,
        values={"speed_rpm": 17000.0},
        timesteps=(1e-5, 3e-5, 1e-4, 3e-4, 1e-3),
        error=_peak_error,
        invariant="energy theorem (|P_int| / peak P_ext)",
        drift=residual_over_peak("P_int", "P_ext"),
        constraint=largest("closure_error"),
        settle=0.003,
        drift_tol=1e-3,
        constraint_tol=1e-6,
    ),
)
