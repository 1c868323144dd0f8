"""Model of the inline engine: the cylinders and balance shafts kept in the MJCF with their
positions, lengths, masses and inertias, the velocity servo, the constraints' stiffness,
the state with every loop closed and the default timestep (the compressor's choices)."""

from __future__ import annotations

import math
import weakref

import mujoco
import numpy as np

from sandbox.errors import BadParameter
from sandbox.french import number
from sandbox.mechanics.engine import THROWS_DEG, lanchester_unbalance
from sandbox.mechanics.imposed import Motion
from sandbox.physics.imposed import Imposed
from sandbox.physics.spec import Values, per_revolution_timestep
from sandbox.scenes.compressor import model as compressor
from sandbox.scenes.compressor.course import kinematics, loop
from sandbox.scenes.compressor.params import RPM
from sandbox.scenes.engine.course import counterweight_mass, cylinder_count, engine_of, masses
from sandbox.scenes.engine.params import DEFAULTS, MAX_CYLINDERS
from sandbox.scenes.imposed import held_speed

SHAFT_ECCENTRICITY = 0.01
"""Distance [m] of each Lanchester shaft's unbalance from its axis."""


def _check(v: Values) -> None:
    cylinder_count(v)
    if v["L"] <= v["R"] * 1.0001:
        raise BadParameter(
            f"the rod (L = {v['L']:g} m) must be longer than the crank (R = {v['R']:g} m); "
            "raise L or lower R",
            french=f"La bielle (L = {number(v['L'])} m) doit être plus longue que la manivelle "
            f"(R = {number(v['R'])} m) : augmentez L ou diminuez R.",
        )
    if v["d2"] > v["L"]:
        raise BadParameter(
            f"the rod's centre of mass (d2 = {v['d2']:g} m) must lie between A and B "
            f"(L = {v['L']:g} m); lower d2 or raise L",
            french=f"Le centre d'inertie de la bielle (d₂ = {number(v['d2'])} m) doit être entre "
            f"A et B (L = {number(v['L'])} m) : diminuez d₂ ou augmentez L.",
        )
    if v["C2"] <= v["m2"] * v["d2"] ** 2 * 1.0001:
        raise BadParameter(
            f"C2 = {v['C2']:g} kg·m² is below m2·d2² = {v['m2'] * v['d2'] ** 2:g} kg·m², an "
            "impossible rod; raise C2 or lower m2 or d2",
            french=f"C₂ = {number(v['C2'])} kg·m² est inférieur à m₂·d₂² = "
            f"{number(v['m2'] * v['d2'] ** 2)} kg·m², une bielle impossible : augmentez C₂ ou "
            "diminuez m₂ ou d₂.",
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
        cw.explicitinertial = True  # a welded point mass: none at all when m_cw = 0
        cw.mass = m_cw
        cw.ipos = [0, 0, 0]
        cw.inertia = [m_cw * 1e-6] * 3
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


STEP_ANGLE = compressor.STEP_ANGLE
"""Crank angle per RK4 step [rad], the compressor's (ω dt = 0.178): 5e-4 s at 3000 rpm,
where the four cylinders run 33 times faster than real time; measured there over 11
revolutions: pilon within 3.3e-4 of its peak, |P_int| within 2.8e-5 of the shaft's
power, loops closed to 6.6e-7 m. At 17,000 rpm 1e-4 s: pilon 3.6e-4, loops 7.8e-7 m.
(0.22 rad, 7e-4 s at 3000 rpm, left the loops open by 1.03e-6 m, past the 1e-6 m the
reference test admits: the errors depend on ω dt alone, and the limit is crossed at
0.215 rad.)"""


def default_timestep(v: Values, data: mujoco.MjData | None = None) -> float:
    """RK4 timestep [s] turning the crank by at most :data:`STEP_ANGLE` per step at
    ``speed_rpm`` (the compressor's rule, :func:`sandbox.scenes.compressor.default_timestep`,
    and its angle): 5e-4 s at 3000 rpm, 1e-4 s at 17,000 rpm; shorter for a rod
    much shorter than the default one, and kept short while a crank faster than its set
    point slows down."""
    cos_max = math.sqrt(max(1.0 - (v["R"] / v["L"]) ** 2, 1e-4))
    cos_default = math.sqrt(1.0 - (DEFAULTS["R"] / DEFAULTS["L"]) ** 2)
    angle = STEP_ANGLE * min(1.0, cos_max / cos_default)
    omega = v["speed_rpm"] * RPM
    if data is not None:
        omega = max(omega, abs(float(data.qvel[0])) / compressor.FASTER)
    return per_revolution_timestep(angle, omega, largest=compressor.LARGEST_TIMESTEP)


def place(model: mujoco.MjModel, data: mujoco.MjData, v: Values, motion: Motion) -> None:
    """The closure equations of the imposed motion: every piston and rod from the
    crankshaft's angle, speed and acceleration (the compressor's exact slider-crank per
    cylinder, its throw's phase subtracted), the balance shafts at ±2θ; accelerations
    into ``qacc_warmstart`` (:mod:`sandbox.physics.imposed`)."""
    theta, omega, alpha = motion
    n = cylinder_count(v)
    qpos, qvel, qacc = data.qpos.copy(), data.qvel.copy(), data.qacc_warmstart.copy()
    layout = _layout(model, n, v["lanchester"] >= 0.5)
    crank, cylinders, shafts = layout
    qpos[crank[0]], qvel[crank[1]], qacc[crank[1]] = theta, omega, alpha
    s, c = math.sin(theta), math.cos(theta)
    R, L = v["R"], v["L"]
    for (sp, cp), (pq, pd), (rq, rd) in cylinders:
        # θ − φ_i by rotating the crank's own sine and cosine: after an hour at 6000 rpm θ
        # is 2×10⁶ rad, whose subtraction would lose 5×10⁻¹⁰ rad (3×10⁻¹² m on the pin)
        lam, dlam, ddlam, phi, dphi, ddphi, _, _ = loop(
            s * cp - c * sp, c * cp + s * sp, omega, alpha, R, L
        )
        qpos[pq], qvel[pd], qacc[pd] = lam, dlam, ddlam
        qpos[rq], qvel[rd], qacc[rd] = phi, dphi, ddphi
    for sign, (q, d) in shafts:
        qpos[q], qvel[d], qacc[d] = sign * 2 * theta, sign * 2 * omega, sign * 2 * alpha
    data.qpos[:], data.qvel[:], data.qacc_warmstart[:] = qpos, qvel, qacc


Address = tuple[int, int]
Layout = tuple[
    Address,
    tuple[tuple[tuple[float, float], Address, Address], ...],
    tuple[tuple[float, Address], ...],
]
_LAYOUTS: weakref.WeakKeyDictionary[mujoco.MjModel, Layout] = weakref.WeakKeyDictionary()


def _layout(model: mujoco.MjModel, n: int, shafts: bool) -> Layout:
    """Per compiled model: the crank's (qpos, dof) address; each cylinder's throw phase
    (sin φ, cos φ, exact for the throws' 0 and 180°), piston's and rod's addresses; each
    balance shaft's sign and address."""
    found = _LAYOUTS.get(model)
    if found is None:

        def at(name: str) -> Address:
            j = model.joint(name).id
            return int(model.jnt_qposadr[j]), int(model.jnt_dofadr[j])

        cylinders = tuple(
            (
                (round(math.sin(phi), 15), round(math.cos(phi), 15)),
                at(f"piston_{i}"),
                at(f"rod_{i}"),
            )
            for i, phi in enumerate(np.radians(THROWS_DEG[n]), start=1)
        )
        turning = ((1.0, at("shaft_1")), (-1.0, at("shaft_2"))) if shafts else ()
        found = (at("crank"), cylinders, turning)
        _LAYOUTS[model] = found
    return found


IMPOSED = Imposed("crank", "motor", place, held_speed, default=True, held_at=math.radians(150))
"""The crankshaft turning at ``speed_rpm``, as the course studies it (1, 7.3): imposed by
default; a fast one read at θ = 60° (the crank's 150°: θ counts from cylinder 1's top
dead centre)."""
