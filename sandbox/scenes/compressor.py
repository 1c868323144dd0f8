"""Micro-compressor, a slider-crank (course sections 1, 4, 5.7, 6.1.2, 6.2, 7.3).

Frame 0, crank 1 (OA = R x1, OG1 = d1 x1, inertia I_O,1 with A1, B1, C1 and the product
E1), rod 2 (AB = L y2, AG2 = d2 y2, I_A,2 = diag(A2, B2, C2)), piston 3 sliding along
(O, y0) with BG3 = d3 y0 and OB = λ y0. θ is the angle from x0 to x1 about z0. A motor
holds the crank at ``speed_rpm``; a counterweight on the crank, opposite the pin, trades
part of the order-1 pilon for a tamis. Weight neglected, perfect joints, links never touch.

Closed forms: λ = R sin θ + √(L² − R² cos² θ); every centre of mass moves on a known
curve, so the force the moving parts transmit to the frame is −Σ m_i Γ(G_i), and the
kinetic-energy theorem gives the motor torque C_mot ω = dT/dt (course, constant ω). The
readouts' references use the exact slider-crank at the current θ, θ' and θ'' (the
simulated crank acceleration): during a ramp (ramp_s = 0.2 s) the θ'' terms reach 27 % of
the torque's peak, and the constant-speed formulas would blame the simulation for them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from sandbox.physics.snapshot import Snapshot
from sandbox.physics.torsors import joint_drive
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
from sandbox.scenes.measures import largest, residual_over_peak
from sandbox.scenes.presets import StudyPreset, XYPreset
from sandbox.scenes.revolutions import PerModel

RPM = 2 * math.pi / 60
HARMONIC_SAMPLES = 64
"""Samples per revolution for the pilon's orders 1 and 2."""
LOOP_SAMPLES = 32
"""Crank angles of :func:`loop_forces` (orders 0..4 need 9; 32 keeps aliasing out)."""


def _p(name: str, unit: str, default: float, lo: float, hi: float, doc: str, **kw: Any) -> Param:
    return Param(name, unit, default, lo, hi, doc, **kw)


DRIVE, GEOMETRY, CENTRES, MASSES, BALANCE, INERTIAS = (
    "Entraînement", "Géométrie", "Centres de gravité", "Masses", "Contrepoids", "Inerties",
)  # fmt: skip

# Inertias: from about a hundredth of the course's values (A1 = 1.2e-4, B2 = 2e-6 kg·m²) up
# to what the heaviest crank the sliders allow needs (m1 d1² reaches 1.25e-2 kg·m²); they
# span decades, so the page types them as numbers (``log``): no slider reaches 2e-4 in 2e-2.
PARAMS = (
    _p("speed_rpm", "rpm", 3000.0, 0.0, 17000.0, "Crank speed held by the motor.", live=True, step=50.0, label="Vitesse du vilebrequin ω", hint="Vitesse de rotation que le moteur impose au vilebrequin 1.", group=DRIVE),
    _p("R", "m", 0.015, 0.005, 0.05, "Crank radius OA.", step=0.0005, label="Rayon de manivelle R", hint="Longueur OA de la manivelle du vilebrequin 1.", group=GEOMETRY),
    _p("L", "m", 0.055, 0.0055, 0.25, "Rod length AB (must exceed R).", step=0.0005, label="Longueur de bielle L", hint="Longueur AB de la bielle 2, qui doit dépasser R.", group=GEOMETRY),
    _p("d1", "m", 0.003, -0.03, 0.05, "OG1: crank centre of mass along x1.", step=0.0005, label="Position de G₁ d₁", hint="Distance OG₁ du centre de gravité du vilebrequin, comptée le long de x₁.", group=CENTRES, advanced=True),
    _p("d2", "m", 0.02, 0.0, 0.25, "AG2: rod centre of mass from the pin A along y2.", step=0.0005, label="Position de G₂ d₂", hint="Distance AG₂ du centre de gravité de la bielle depuis le maneton A, le long de y₂.", group=CENTRES, advanced=True),
    _p("d3", "m", 0.005, -0.05, 0.05, "BG3: piston centre of mass from B along y0.", step=0.0005, label="Position de G₃ d₃", hint="Distance BG₃ du centre de gravité du piston depuis l'axe B, le long de y₀.", group=CENTRES, advanced=True),
    _p("m1", "kg", 0.35, 0.01, 5.0, "Mass of the crank.", step=0.01, label="Masse du vilebrequin m₁", hint="Masse du vilebrequin 1, sans le contrepoids.", group=MASSES),
    _p("m2", "kg", 0.06, 0.001, 2.0, "Mass of the rod.", step=0.005, label="Masse de la bielle m₂", hint="Masse de la bielle 2.", group=MASSES),
    _p("m3", "kg", 0.08, 0.001, 2.0, "Mass of the piston.", step=0.005, label="Masse du piston m₃", hint="Masse du piston 3, en translation le long de y₀.", group=MASSES),
    _p("A1", "kg·m²", 1.2e-4, 1e-6, 2e-2, "Crank inertia about (O, x1).", step=1e-6, label="Moment d'inertie A₁", hint="Moment d'inertie du vilebrequin autour de l'axe (O, x₁).", group=INERTIAS, advanced=True, log=True),
    _p("B1", "kg·m²", 2.0e-4, 1e-6, 2e-2, "Crank inertia about (O, y1).", step=1e-6, label="Moment d'inertie B₁", hint="Moment d'inertie du vilebrequin autour de l'axe (O, y₁).", group=INERTIAS, advanced=True, log=True),
    _p("C1", "kg·m²", 2.2e-4, 1e-6, 2e-2, "Crank inertia about (O, z0), the rotation axis.", step=1e-6, label="Moment d'inertie C₁", hint="Moment d'inertie du vilebrequin autour de son axe de rotation (O, z₀).", group=INERTIAS, advanced=True, log=True),
    _p("E1", "kg·m²", 1.0e-6, -1e-3, 1e-3, "Crank product of inertia E1 = ∫ x z dm at O.", step=1e-7, label="Produit d'inertie E₁", hint="Produit d'inertie E₁ = ∫ x·z dm du vilebrequin en O, dans la base B₁.", group=INERTIAS, advanced=True, log=True),
    _p("A2", "kg·m²", 6.5e-5, 1e-7, 1e-1, "Rod inertia about (A, x2).", step=1e-7, label="Moment d'inertie A₂", hint="Moment d'inertie de la bielle autour de l'axe (A, x₂).", group=INERTIAS, advanced=True, log=True),
    _p("B2", "kg·m²", 2.0e-6, 1e-9, 1e-3, "Rod inertia about (A, y2), its own axis.", step=1e-8, label="Moment d'inertie B₂", hint="Moment d'inertie de la bielle autour de son propre axe (A, y₂).", group=INERTIAS, advanced=True, log=True),
    _p("C2", "kg·m²", 6.5e-5, 1e-7, 1e-1, "Rod inertia about (A, z0).", step=1e-7, label="Moment d'inertie C₂", hint="Moment d'inertie de la bielle autour de l'axe (A, z₀), parallèle à l'axe du vilebrequin.", group=INERTIAS, advanced=True, log=True),
    _p("counterweight_mass", "kg", 0.0, 0.0, 2.0, "Balancing mass on the crank, opposite A.", step=0.005, label="Masse du contrepoids", hint="Masse d'équilibrage fixée sur le vilebrequin, à l'opposé du maneton A (un balourd volontaire).", group=BALANCE),
    _p("counterweight_radius", "m", 0.015, 0.0, 0.06, "Distance of the balancing mass from O.", step=0.0005, label="Rayon du contrepoids", hint="Distance du contrepoids à l'axe de rotation (O, z₀).", group=BALANCE),
    _p("motor_inertia", "kg·m²", 0.02, 0.0, 0.2, "Inertia of the motor's rotor, turning with the crank (a joint armature).", step=0.001, label="Inertie du rotor du moteur J", hint="Moment d'inertie du rotor du moteur, qui tourne avec le vilebrequin.", group=INERTIAS, advanced=True),
    _p("ramp_s", "s", 0.0, 0.0, 5.0, "0: start at speed; > 0: start at rest, motor set point rising with this time constant.", step=0.05, label="Temps de montée en vitesse τ", hint="0 : le vilebrequin part à sa vitesse ; sinon il part du repos et la consigne du moteur monte avec cette constante de temps.", group=DRIVE),
)  # fmt: skip


# -- closed form ------------------------------------------------------------------------------
@dataclass(frozen=True)
class Kinematics:
    """Slider-crank kinematics at crank angle θ [rad], speed ω = θ' [rad/s] and angular
    acceleration α = θ'' [rad/s²] (exact, every harmonic).

    Positions [m], velocities [m/s], accelerations [m/s²] in B0 (x, y); φ is the rod's
    angle from y0 to y2 about z0, with its rates. ``lam_theta`` = dλ/dθ [m] and
    ``phi_theta`` = dφ/dθ: the velocities are ``lam_theta`` ω and ``phi_theta`` ω, and the
    accelerations gain ``lam_theta`` α and ``phi_theta`` α when the speed changes.
    """

    theta: float
    omega: float
    lam: float
    dlam: float
    ddlam: float
    phi: float
    dphi: float
    ddphi: float
    alpha: float = 0.0
    lam_theta: float = 0.0
    phi_theta: float = 0.0


def kinematics(theta: float, omega: float, R: float, L: float, *, alpha: float = 0.0) -> Kinematics:
    """λ = R sin θ + √(L² − R² cos² θ) and its derivatives; sin φ = R cos θ / L.

    With q = √(L² − R² cos² θ): λ_θ = R cos θ + R² sin θ cos θ / q,
    λ_θθ = −R sin θ + R² (cos² θ − sin² θ) / q − R⁴ sin² θ cos² θ / q³, and
    λ'' = λ_θθ ω² + λ_θ α; φ_θ = −R sin θ / (L cos φ),
    φ_θθ = −(R / L) (cos θ / cos φ + sin θ sin φ φ_θ / cos² φ), φ'' = φ_θθ ω² + φ_θ α.
    """
    s, c = math.sin(theta), math.cos(theta)
    q = math.sqrt(L * L - R * R * c * c)
    lam = R * s + q
    lam_t = R * c + R * R * s * c / q
    lam_tt = -R * s + R * R * (c * c - s * s) / q - R**4 * s * s * c * c / q**3
    phi = math.asin(R * c / L)
    cp = math.cos(phi)
    phi_t = -R * s / (L * cp)
    phi_tt = -(R / L) * (c / cp + s * math.sin(phi) * phi_t / cp**2)
    return Kinematics(
        theta,
        omega,
        lam,
        lam_t * omega,
        lam_tt * omega**2 + lam_t * alpha,
        phi,
        phi_t * omega,
        phi_tt * omega**2 + phi_t * alpha,
        alpha,
        lam_t,
        phi_t,
    )


def _crank_mass_moment(v: Values) -> float:
    """Σ m·(distance along x1) of the crank and its counterweight [kg·m]."""
    return v["m1"] * v["d1"] - v["counterweight_mass"] * v["counterweight_radius"]


def _crank_point(theta: float, omega: float, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """(∂P/∂θ, Γ(P)) of a crank point at unit distance from O on x1: y1 and
    −ω² x1 + α y1 (x1 = (cos θ, sin θ), y1 = (−sin θ, cos θ) in B0)."""
    s, c = math.sin(theta), math.cos(theta)
    x1, y1 = np.array([c, s]), np.array([-s, c])
    return y1, -(omega**2) * x1 + alpha * y1


def frame_force(theta: float, omega: float, v: Values, *, alpha: float = 0.0) -> np.ndarray:
    """Force (x0, y0) the moving parts transmit to the frame: −Σ m_i Γ(G_i) [N].

    Exact slider-crank at θ, ω = θ' and α = θ'' (α = 0: the course's constant speed).
    G1 and the counterweight are on x1, G3 moves with B (Γ(B) = λ'' y0) and G2 lies on AB
    at AG2 = d2: Γ(G2) = (1 − d2/L) Γ(A) + (d2/L) Γ(B).
    """
    k = kinematics(theta, omega, v["R"], v["L"], alpha=alpha)
    _, unit = _crank_point(theta, omega, alpha)
    g_a = v["R"] * unit
    g_b = np.array([0.0, k.ddlam])
    w = v["d2"] / v["L"]
    g_2 = (1 - w) * g_a + w * g_b
    total = _crank_mass_moment(v) * unit + v["m2"] * g_2 + v["m3"] * g_b
    return -total


def motor_torque(theta: float, omega: float, v: Values, *, alpha: float = 0.0) -> float:
    """C_mot: torque the motor passes on to the crank (its rotor's own J α excluded) [N·m].

    Virtual power (Lagrange on θ; at constant ω it is the course's C_mot ω = dT/dt):
    C_mot = (C1 + m_cw r_cw²) α + m2 Γ(G2)·∂G2/∂θ + m3 λ'' λ_θ + I_G2,z φ'' φ_θ, with
    I_G2,z = C2 − m2 d2² and ∂G2/∂θ = (1 − d2/L) R y1 + (d2/L) λ_θ y0. Defined at ω = 0
    too (a start from rest: C_mot = inertia seen by the motor × α).
    """
    k = kinematics(theta, omega, v["R"], v["L"], alpha=alpha)
    y1, unit = _crank_point(theta, omega, alpha)
    w = v["d2"] / v["L"]
    dg_2 = (1 - w) * v["R"] * y1 + w * np.array([0.0, k.lam_theta])
    g_2 = (1 - w) * v["R"] * unit + w * np.array([0.0, k.ddlam])
    i_g2 = v["C2"] - v["m2"] * v["d2"] ** 2
    i_crank = v["C1"] + v["counterweight_mass"] * v["counterweight_radius"] ** 2
    return (
        i_crank * alpha
        + v["m2"] * float(g_2 @ dg_2)
        + v["m3"] * k.ddlam * k.lam_theta
        + i_g2 * k.ddphi * k.phi_theta
    )


def reference(v: Values) -> dict[str, float]:
    """The course's constant values at ``speed_rpm``: ω, the pilon's orders 1 and 2 and the
    tamis' order 1 (angle-dependent ones are readouts: pilon_ref, tamis_ref...)."""
    omega = v["speed_rpm"] * RPM
    thetas = np.linspace(0, 2 * math.pi, HARMONIC_SAMPLES, endpoint=False)
    forces = np.array([frame_force(t, omega, v) for t in thetas])
    amp = fit_orders(thetas, forces[:, 1])
    tamis = fit_orders(thetas, forces[:, 0])
    return {
        "omega": omega,
        "pilon_h1": float(amp[1]),
        "pilon_h2": float(amp[2]),
        "tamis_h1": float(tamis[1]),
    }


# -- model ------------------------------------------------------------------------------------
def _check_geometry(v: Values) -> None:
    from sandbox.errors import BadParameter

    if v["L"] <= v["R"] * 1.0001:
        raise BadParameter(
            f"the rod (L = {v['L']:g} m) must be longer than the crank (R = {v['R']:g} m); "
            "raise L or lower R"
        )
    m1d1, m2d2 = v["m1"] * v["d1"] ** 2, v["m2"] * v["d2"] ** 2
    crank = np.array(
        [[v["A1"], 0, -v["E1"]], [0, v["B1"] - m1d1, 0], [-v["E1"], 0, v["C1"] - m1d1]]
    )
    rod = np.diag([v["A2"] - m2d2, v["B2"], v["C2"] - m2d2])
    for name, inertia, fix in (
        ("crank", crank, "raise A1, B1, C1 or lower m1·d1² and |E1|"),
        ("rod", rod, "raise A2, C2 or lower m2·d2²"),
    ):
        eig = np.linalg.eigvalsh(inertia)
        if eig[0] <= 0 or eig[2] > eig[0] + eig[1] + 1e-15:
            raise BadParameter(
                f"these values give the {name} an impossible inertia at its centre of mass "
                f"(principal moments {', '.join(f'{e:.3g}' for e in eig)} kg·m²); {fix}"
            )


def _inertial(body: mujoco.MjsBody, mass: float, pos, full) -> None:
    body.explicitinertial = True
    body.mass = mass
    body.ipos = pos
    body.fullinertia = full


def edit(spec: mujoco.MjSpec, v: Values) -> None:
    """Lengths, masses and inertias of the course's parametrisation (section 4)."""
    _check_geometry(v)
    R, L, d1, d2 = v["R"], v["L"], v["d1"], v["d2"]
    m1, m2 = v["m1"], v["m2"]
    # Crank: I_O,1 = [[A1, 0, -E1], [0, B1, 0], [-E1, 0, C1]] in B1; at G1 (Huygens, OG1 on x1).
    crank = spec.body("crank")
    _inertial(crank, m1, [d1, 0, 0], [v["A1"], v["B1"] - m1 * d1 * d1, v["C1"] - m1 * d1 * d1,
                                      0.0, -v["E1"], 0.0])  # fmt: skip
    spec.site("A_crank").pos = [R, 0, 0]
    spec.geom("pin").pos = [R, 0, 0]
    web = spec.geom("web")
    web.pos = [R / 2, 0, -0.004]
    web.size = [R / 2 + 0.006, 0.008, 0.003]
    cw = spec.body("counterweight")
    cw.pos = [-v["counterweight_radius"], 0, 0]
    m_cw = v["counterweight_mass"]
    tiny = m_cw * 1e-6 + 1e-12
    _inertial(cw, max(m_cw, 1e-9), [0, 0, 0], [tiny, tiny, tiny, 0, 0, 0])
    spec.geom("counterweight").rgba = [0.3, 0.3, 0.8, 1.0 if m_cw > 0 else 0.15]
    # Rod: frame at B, y2 from A to B, so A = -L y2 and G2 = A + d2 y2;
    # I_A,2 = diag(A2, B2, C2) in B2, at G2 (AG2 along y2).
    rod = spec.body("rod")
    _inertial(rod, m2, [0, -L + d2, 0], [v["A2"] - m2 * d2 * d2, v["B2"], v["C2"] - m2 * d2 * d2,
                                         0.0, 0.0, 0.0])  # fmt: skip
    spec.site("A_rod").pos = [0, -L, 0]
    spec.geom("rod").fromto = [0, 0, 0.004, 0, -L, 0.004]
    piston = spec.body("piston")
    tiny3 = v["m3"] * 1e-4
    _inertial(piston, v["m3"], [0, v["d3"], 0], [tiny3, tiny3, tiny3, 0, 0, 0])
    spec.geom("cylinder").pos = [0, L + R + 0.01, 0]
    spec.geom("cylinder").size = [0.022, R + 0.02, 0]
    spec.joint("crank").armature = v["motor_inertia"]
    motor = spec.actuator("motor")
    if v["ramp_s"] > 0:
        motor.dyntype = mujoco.mjtDyn.mjDYN_FILTEREXACT
        motor.dynprm[0] = v["ramp_s"]
    else:
        motor.dyntype = mujoco.mjtDyn.mjDYN_NONE


SERVO_STIFFNESS = 1.4
"""Servo gain × dt / (C1 + J): the velocity servo's time constant (C1 + J)/kv is then
0.7 dt, inside RK4's stability limit (2.8 dt). With the motor's rotor inertia J = 0.02
kg·m² (100 C1) the speed ripple is 2e-5 at 3000 rpm and 5e-5 at 17,000 rpm (dt = 1e-4 s)
and the crank's own C1·dω/dt a negligible part of the torque: the shaft torque matches
C_mot = (dT/dt)/ω within 0.1 % of its peak at 3000 rpm."""

CLOSURE_TIMECONST = 5.0
"""Time constant of the closure constraint, in timesteps (impedance 0.9999, critical
damping). MuJoCo 4 puts the velocity-product term J̇·q̇ into the constraint's reference
acceleration, so the closure needs no drift to hold and the time constant only sets how
fast integration errors are pulled back. At 2 dt (MuJoCo's stiffest safe value) that pull
is at the edge of what RK4 resolves: a step-to-step velocity violation (1.4e-4 m/s at 3000
rpm) survives, its damping term biases every acceleration by 0.27 % and the constraint
works at 4e-4 of the motor's power at 17,000 rpm. At 5 dt (measured, RK4, dt = 1e-4 s) the
violation is resolved: pilon within 5e-5 of its peak at 3000 rpm and 2e-4 at 17,000 rpm,
|P_int| below 2e-5 (3000 rpm) and 6e-5 (17,000 rpm) of the shaft's peak power, loop closed
to 4.5e-8 m and 7.8e-7 m. 4 dt already opens it to 1e-6 m at 17,000 rpm, and softer ones
(20 dt) open it more and let it work more (1e-4 of the power).
"""


DEFAULTS = {p.name: p.default for p in PARAMS}
STEP_ANGLE = 17000.0 * RPM * 1e-4
"""Crank angle per step [rad] (0.178) the benchmark admits: RK4 at dt = 1e-4 s and
17,000 rpm keeps the pilon within 2e-4 of its peak, |P_int| within 7e-5 of the shaft's
power and the loop closed to 7.8e-7 m (drift and closure limits 1e-3 and 1e-6 m)."""
LARGEST_TIMESTEP = 1e-3
"""Default timestep at low speed and at rest [s] (1700 rpm and below)."""


def _cos_phi_max(v: Values) -> float:
    """cos of the rod's largest angle from y0 (at θ = 0): √(1 − (R/L)²)."""
    return math.sqrt(max(1.0 - (v["R"] / v["L"]) ** 2, 1e-4))


FASTER = 1.02
"""A crank turning faster than its set point by more than this factor (a lower speed was
just asked for) keeps the timestep of its current speed until it has slowed down."""


def default_timestep(v: Values, data: mujoco.MjData | None = None) -> float:
    """RK4 timestep [s] that turns the crank by at most :data:`STEP_ANGLE` per step at
    ``speed_rpm``: 5e-4 s at 3000 rpm, 2e-4 s at 6000 rpm, 1e-4 s at 17,000 rpm.

    Without weight, the scene has no time scale of its own: the servo's (0.7 dt) and the
    closure's (5 dt) follow the timestep, so the motion at speed ω and step dt is the one
    at k ω and dt / k, slowed down k times. Every error per revolution (pilon, energy
    theorem, closure) is then a function of ω dt alone (measured: 17,000 rpm at 1e-4 s and
    3000 rpm at 5.67e-4 s agree to 3 %: pilon 2.0e-4, |P_int| 6e-5, closure 7.8e-7 m).
    A rod much shorter than the default one swings faster near θ = 0 (φ' = −R ω sin θ /
    (L cos φ), λ'' grows with R² / (L cos φ)): the angle shrinks with cos φ_max, measured at
    L/R = 1.1 (closure 1.0e-6 m at 0.157 rad per step, 2.2e-7 m at 0.063). A ramp starts
    from rest with the final speed's step (finer than needed while it is slow). With the
    current state ``data``, a crank still turning faster than :data:`FASTER` × its set
    point (after a lower speed was set) gets the step of that speed ÷ :data:`FASTER`: a
    live drop from 17,000 to 1000 rpm at 1 ms would open the loop by 12 mm while the servo
    brakes it.
    """
    angle = STEP_ANGLE * min(1.0, _cos_phi_max(v) / _cos_phi_max(DEFAULTS))
    omega = v["speed_rpm"] * RPM
    if data is not None:  # within FASTER of the set point: the set point's step
        omega = max(omega, abs(float(data.qvel[0])) / FASTER)
    return per_revolution_timestep(angle, omega, largest=LARGEST_TIMESTEP)


def drive(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """Motor set point (the crank speed, filtered when ``ramp_s`` > 0); servo gain and
    closure stiffness follow the timestep so that any dt stays stable."""
    dt = float(model.opt.timestep)
    kv = SERVO_STIFFNESS * (v["C1"] + v["motor_inertia"]) / dt
    model.actuator_gainprm[0, 0] = kv
    model.actuator_biasprm[0, :3] = [0.0, 0.0, -kv]
    model.eq_solref[0] = [CLOSURE_TIMECONST * dt, 1.0]
    model.eq_solimp[0, :3] = [0.9999, 0.9999, 0.001]
    data.ctrl[0] = v["speed_rpm"] * RPM


def set_loop_state(model: mujoco.MjModel, data: mujoco.MjData, theta: float, omega: float,
                   v: Values) -> None:  # fmt: skip
    """Put the mechanism on the loop at angle θ and speed ω (consistent velocities)."""
    k = kinematics(theta, omega, v["R"], v["L"])
    data.qpos[:] = [theta, k.lam, k.phi]
    data.qvel[:] = [omega, k.dlam, k.dphi]


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """At speed on the loop (θ = 0), or at rest when a ramp is asked for."""
    omega = v["speed_rpm"] * RPM
    if v["ramp_s"] > 0:
        set_loop_state(model, data, 0.0, 0.0, v)
        if model.na:
            data.act[:] = 0.0
    else:
        set_loop_state(model, data, 0.0, omega, v)
        if model.na:
            data.act[:] = omega


# -- readouts -----------------------------------------------------------------------------------
def _force(s: Snapshot) -> np.ndarray:
    """Force of the moving parts on the frame (= −action of the frame), world axes."""
    r, _ = s.support
    return -np.asarray(r)


def _theta(s: Snapshot) -> float:
    return s.joint_qpos("crank")


def _closure(s: Snapshot) -> float:
    d, m = s.data, s.model
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "A_crank")
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "A_rod")
    return float(np.linalg.norm(d.site_xpos[a] - d.site_xpos[b]))


_REVOLUTIONS: PerModel[dict[str, np.ndarray]] = PerModel()


FITTED_ORDERS = 12
"""Orders fitted together (as many as the samples allow): a slider-crank's force has
every even order, and a revolution sampled 29 times at the engine's default step leaked
its orders 4 to 8 into order 1 when only orders up to 4 were fitted (2x10⁻³ N where the
course says 0; 4x10⁻¹⁰ N with twelve)."""


def fit_orders(theta: np.ndarray, values: np.ndarray, orders: int = 4) -> np.ndarray:
    """Least-squares amplitudes of orders 0..``orders`` of ``values`` sampled at angles θ
    (fitted with orders up to :data:`FITTED_ORDERS`, or as many as the samples allow)."""
    fitted = max(orders, min(FITTED_ORDERS, (len(theta) - 3) // 2))
    cols = [np.ones_like(theta)]
    for k in range(1, fitted + 1):
        cols += [np.cos(k * theta), np.sin(k * theta)]
    coef, *_ = np.linalg.lstsq(np.stack(cols, axis=1), values, rcond=None)
    amp = np.concatenate([[abs(coef[0])], np.hypot(coef[1::2], coef[2::2])])
    return amp[: orders + 1]


def revolution(s: Snapshot) -> dict[str, np.ndarray]:
    """One revolution simulated from the current state on a scratch copy (the trajectory
    itself is untouched): crank angle [deg], pilon, tamis and motor torque, and the
    course's values at the same angles. Cached while the model, the parameters and the
    speed (to 0.1 %) stay the same: in steady state the revolution does not change."""
    from sandbox.physics import torsors as generic

    model, v = s.model, s.values
    omega = float(s.data.qvel[0])
    kept = _REVOLUTIONS.get(model, v, omega, float(s.data.time))
    if kept is not None:
        return kept
    data = mujoco.MjData(model)
    mujoco.mj_copyData(data, model, s.data)
    period = 2 * math.pi / max(abs(omega), 1e-9)
    per = max(1, int(round(period / HARMONIC_SAMPLES / model.opt.timestep)))
    rows = []
    while data.time < s.data.time + period and abs(omega) > 1e-6:
        mujoco.mj_forward(model, data)
        mujoco.mj_rnePostConstraint(model, data)
        theta, w = float(data.qpos[0]), float(data.qvel[0])
        force = -generic.support_torsor(model, data)[0]
        alpha = float(data.qacc[0])
        ref = frame_force(theta, w, v, alpha=alpha)
        rows.append((theta, force[1], force[0], float(joint_drive(model, data)[0]), ref[1], ref[0],
                     motor_torque(theta, w, v, alpha=alpha)))  # fmt: skip
        mujoco.mj_step(model, data, per)
    a = np.array(rows).reshape(-1, 7)
    order = np.argsort(np.mod(a[:, 0], 2 * math.pi))
    a = a[order]
    out = {
        "angle_deg": np.degrees(np.mod(a[:, 0], 2 * math.pi)),
        "theta": a[:, 0],
        "pilon": a[:, 1],
        "tamis": a[:, 2],
        "motor_torque": a[:, 3],
        "pilon_ref": a[:, 4],
        "tamis_ref": a[:, 5],
        "motor_torque_ref": a[:, 6],
    }
    _REVOLUTIONS.put(model, v, omega, out, float(s.data.time))
    return out


def steady(s: Snapshot, tol: float = 1e-3) -> bool:
    """True when the crank turns at its set point (and a ramp has reached it), to ``tol``."""
    target = float(s.data.ctrl[0])
    if target == 0.0:
        return False
    near = abs(float(s.data.qvel[0]) - target) <= tol * abs(target)
    if s.model.na:
        near = near and abs(float(s.data.act[0]) - target) <= tol * abs(target)
    return near


def loop_forces(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """Pilon and tamis [N] that MuJoCo computes for the mechanism put on the loop at
    ``LOOP_SAMPLES`` crank angles, at the current speed and motor state, without
    stepping (a scratch copy: the trajectory is untouched). Returns (θ, forces (n, 2))."""
    from sandbox.physics import torsors as generic

    model, v = s.model, s.values
    data = mujoco.MjData(model)
    mujoco.mj_copyData(data, model, s.data)
    omega = float(s.data.qvel[0])
    thetas = np.linspace(0, 2 * math.pi, LOOP_SAMPLES, endpoint=False)
    forces = np.empty((LOOP_SAMPLES, 2))
    for i, theta in enumerate(thetas):
        set_loop_state(model, data, float(theta), omega, v)
        mujoco.mj_forward(model, data)
        mujoco.mj_rnePostConstraint(model, data)
        forces[i] = -generic.support_torsor(model, data)[0][[1, 0]]
    return thetas, forces


def _pilon_harmonics(s: Snapshot) -> np.ndarray:
    """Orders 0..4 of the pilon (row 0) and the tamis (row 1) over one revolution.

    In steady state the revolution is simulated ahead from the current state on a scratch
    copy (:func:`revolution`, cached while nothing changes): at constant speed it is the
    last revolution again. During a speed change (ramp, new set point) that would cost a
    whole revolution of steps at every reading and mix several speeds, so the orders come
    from :func:`loop_forces` at the current speed instead (same values in steady state,
    within 1e-4 of the peak). Shared by the three order readouts through the snapshot.
    """
    cached = s.cache.get("compressor_orders")
    if cached is not None:
        return cached[0]
    rev = None
    if steady(s):
        rev = revolution(s)
        hit = _ORDERS.get(id(rev))
        if hit is not None and hit[0] is rev:  # the same cached revolution: same orders
            s.cache["compressor_orders"] = (hit[1], hit[1])
            return hit[1]
        theta, pilon, tamis = rev["theta"], rev["pilon"], rev["tamis"]
    else:
        theta, forces = loop_forces(s)
        pilon, tamis = forces[:, 0], forces[:, 1]
    if len(theta) < 10 or float(s.data.qvel[0]) == 0.0:
        orders = np.zeros((2, 5))
    else:
        orders = np.stack([fit_orders(theta, pilon), fit_orders(theta, tamis)])
    if rev is not None:
        if len(_ORDERS) > 64:
            _ORDERS.clear()
        _ORDERS[id(rev)] = (rev, orders)
    s.cache["compressor_orders"] = (orders, orders)
    return orders


_ORDERS: dict[int, tuple[dict[str, np.ndarray], np.ndarray]] = {}
"""Orders of each cached revolution (a least-squares fit per reading cost 80 µs)."""


def _alpha(s: Snapshot) -> float:
    """θ'' [rad/s²]: the crank's acceleration at this state (0 in steady state)."""
    return float(s.data.qacc[s.model.jnt_dofadr[s.model.joint("crank").id]])


def _reference(s: Snapshot) -> np.ndarray:
    """The course's frame force at the current θ, θ' and θ'', shared by pilon_ref and
    tamis_ref."""
    ref = s.cache.get("compressor_ref")
    if ref is None:
        ref = frame_force(_theta(s), s.joint_qvel("crank"), s.values, alpha=_alpha(s))
        s.cache["compressor_ref"] = ref
    return ref


def _motor_torque_ref(s: Snapshot) -> float:
    return motor_torque(_theta(s), s.joint_qvel("crank"), s.values, alpha=_alpha(s))


READOUTS = (
    SceneReadout("theta", "rad", "Crank angle θ from x0 to x1 (unwrapped).", _theta, label="Angle du vilebrequin θ", hint="Angle de x₀ à x₁ autour de z₀, qui continue de croître tour après tour."),
    SceneReadout("omega", "rad/s", "Crank speed θ'.", lambda s: s.joint_qvel("crank"), label="Vitesse mesurée du vilebrequin ω", hint="Vitesse de rotation θ' du vilebrequin par rapport au bâti."),
    SceneReadout("lambda", "m", "OB: position of the piston pin on y0.", lambda s: s.joint_qpos("piston"), label="Position du piston λ", hint="Distance OB de l'axe du vilebrequin à l'axe du piston, le long de y₀."),
    SceneReadout("pilon", "N", "Force of the moving parts on the frame along y0 (cylinder axis).", lambda s: float(_force(s)[1]), label="Effet de pilon", hint="Effort des pièces mobiles sur le bâti le long de l'axe du cylindre y₀."),
    SceneReadout("tamis", "N", "Force of the moving parts on the frame along x0 (across).", lambda s: float(_force(s)[0]), label="Effet de tamis", hint="Effort des pièces mobiles sur le bâti perpendiculairement à l'axe du cylindre, le long de x₀."),
    SceneReadout("motor_torque", "N·m", "Torque of the motor on the crank shaft (its rotor's own inertia excluded).", lambda s: float(joint_drive(s.model, s.data)[0]), label="Couple moteur Cₘₒₜ", hint="Couple que le moteur transmet au vilebrequin, sans celui qui accélère son propre rotor."),
    SceneReadout("closure_error", "m", "Distance between the rod's end and the crank pin A.", _closure, label="Écart de fermeture en A", hint="Distance entre l'extrémité de la bielle et le maneton A du vilebrequin, quasi nulle quand la chaîne reste fermée."),
    SceneReadout("pilon_h1", "N", "Order-1 amplitude of the pilon over a revolution (simulated ahead in steady state, on the loop at the current speed during a speed change).", lambda s: float(_pilon_harmonics(s)[0, 1]), label="Pilon, ordre 1", hint="Amplitude de la composante du pilon à la fréquence de rotation, sur un tour de vilebrequin."),
    SceneReadout("pilon_h2", "N", "Order-2 amplitude of the pilon over a revolution (as pilon_h1).", lambda s: float(_pilon_harmonics(s)[0, 2]), label="Pilon, ordre 2", hint="Amplitude de la composante du pilon à deux fois la fréquence de rotation, sur un tour."),
    SceneReadout("tamis_h1", "N", "Order-1 amplitude of the tamis over a revolution (as pilon_h1).", lambda s: float(_pilon_harmonics(s)[1, 1]), label="Tamis, ordre 1", hint="Amplitude de la composante du tamis à la fréquence de rotation, sur un tour."),
    SceneReadout("pilon_ref", "N", "Course value of the pilon at the current θ, θ' and θ'' (exact slider-crank; θ'' terms during a speed change).", lambda s: float(_reference(s)[1]), label="Pilon selon le cours", hint="Pilon calculé par le cours pour le système bielle-manivelle exact, à l'angle, à la vitesse et à l'accélération actuels."),
    SceneReadout("tamis_ref", "N", "Course value of the tamis at the current θ, θ' and θ'' (as pilon_ref).", lambda s: float(_reference(s)[0]), label="Tamis selon le cours", hint="Tamis calculé par le cours pour le système bielle-manivelle exact, à l'angle, à la vitesse et à l'accélération actuels."),
    SceneReadout("motor_torque_ref", "N·m", "Course value of C_mot at the current θ, θ' and θ'' (virtual power; (dT/dt)/ω at constant speed).", _motor_torque_ref, label="Couple moteur selon le cours", hint="Couple Cₘₒₜ calculé par les puissances, égal à (dT/dt)/ω à vitesse constante."),
)  # fmt: skip

ARROW_SCALE = 2e-4
"""Metres of arrow per newton."""


def _at_o(vec: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(3), np.array([vec[0], vec[1], 0.0])


ARROWS = (
    Arrow("pilon", "Pilon", (220, 60, 60), lambda s: _at_o([0.0, _force(s)[1]]), ARROW_SCALE, unit="N", point="O", hint="Effet de pilon : effort des pièces mobiles sur le bâti le long de y₀ (rouge)."),
    Arrow("tamis", "Tamis", (60, 140, 220), lambda s: _at_o([_force(s)[0], 0.0]), ARROW_SCALE, unit="N", point="O", hint="Effet de tamis : effort des pièces mobiles sur le bâti le long de x₀ (bleu)."),
    Arrow("frame_force", "Pilon + tamis", (120, 60, 160), lambda s: _at_o(_force(s)), ARROW_SCALE, unit="N", point="O", hint="Effort total des pièces mobiles sur le bâti (violet)."),
)  # fmt: skip


def _peak_error(series, values) -> float:
    """max |pilon − course| / max |course pilon| over the run."""
    ref = np.asarray(series["pilon_ref"])
    return float(np.max(np.abs(np.asarray(series["pilon"]) - ref)) / np.max(np.abs(ref)))


SCENE = Scene(
    name="compressor",
    overlay={
        "theta": "θ",
        "pilon": "Effet de pilon",
        "tamis": "Effet de tamis",
        "motor_torque": "Couple moteur",
    },
    title="Micro-compresseur : effets de pilon et de tamis",
    summary=(
        "A slider-crank held at constant speed by a motor. The moving parts shake the frame "
        "along the cylinder (pilon) and across it (tamis); a counterweight on the crank "
        "trades part of the first one for the second."
    ),
    mjcf="compressor.xml",
    params=PARAMS,
    effects=Effects(gravity=False, contacts=False, equality=True, actuation=True),
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    initial_state=initial_state,
    reference=reference,
    # RK4 keeps the closure from draining energy: first-order integrators (euler,
    # implicitfast...) lose 1-5 % of the motor power in it at 2e-5 to 1e-4 s, whatever the
    # closure's time constant. dt = 1e-4 s (ω dt = 0.18 at 17,000 rpm) keeps the 17,000 rpm
    # loop closed to 1e-6 m (7.8e-7 measured; 7e-5 s gives 4.8e-7) and costs ~0.15 s of
    # CPU per simulated second; the same angle per step is enough at every speed
    # (default_timestep), so 3000 rpm runs at 5e-4 s, five times cheaper.
    integrator="rk4",
    timestep=5e-4,
    timestep_for=default_timestep,
    # Time plots of slow quantities (the pilon itself is drawn against θ in "Sur un tour").
    plots=("pilon_h1", "pilon_h2", "tamis_h1", "omega"),
    xy_presets=(
        XYPreset(
            "Pilon et tamis sur un tour du vilebrequin",
            "theta",
            ("pilon", "tamis"),
            hint="Les efforts transmis au bâti selon l'angle θ du vilebrequin ; en tirets, "
            "les expressions du cours (7.3).",
        ),
        XYPreset(
            "Couple moteur sur un tour du vilebrequin",
            "theta",
            ("motor_torque",),
            hint="Le couple que le moteur fournit selon θ ; en tirets, celui que donne le "
            "théorème de l'énergie cinétique.",
        ),
    ),
    study_presets=(
        StudyPreset(
            "Pilon d'ordre 2 selon R/L",
            ("L", 0.04, 0.2, 9),
            "pilon",
            statistic="order2",
            duration=0.1,
            settle=0.02,
            hint="L'harmonique d'ordre 2 de l'effet de pilon est proportionnelle à R/L "
            "(cours 7.3) : une bielle plus longue secoue moins le bâti.",
            x=("Rapport R/L", lambda v: v["R"] / v["L"]),
        ),
    ),
    arrows=ARROWS,
    body_frame="crank",
    sections="1, 4, 5.7, 6.1.2, 6.2, 7.3",
    camera=((0.35, -0.45, 1.0), (0.0, 1.0, 0.0)),  # facing the mechanism's plane, y0 up
    cycle=revolution,
    extra={
        "solid_names": {"crank": "1 (vilebrequin)", "rod": "2 (bielle)", "piston": "3 (piston)"}
    },
    # Round-off: the closure error (1e-8 m and more) stays visible; forces reach 1e4 N.
    zero={
        "N": 1e-9,
        "N·m": 1e-10,
        "W": 1e-9,
        "J": 1e-12,
        "kg·m/s": 1e-12,
        "kg·m²/s": 1e-12,
        "m": 1e-13,
    },
    # Measured at 17,000 rpm, the hardest speed the course mentions: at 3000 rpm every RK4
    # timestep up to 1e-4 s gives the pilon within 1e-4, so only the top speed separates
    # them; first-order integrators drain 1-20 % of the motor power in the closure.
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
        settle=0.003,  # the servo takes a few steps to build its torque
        drift_tol=1e-3,  # the limit on the energy-theorem residual
        constraint_tol=1e-6,
    ),
)
