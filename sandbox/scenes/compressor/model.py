"""Model of the micro-compressor: the course's parametrisation applied to the MJCF (lengths,
masses, inertias), the velocity servo, the closure's stiffness, the default timestep and
the initial state on the loop."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.errors import BadParameter
from sandbox.french import number
from sandbox.mechanics.imposed import Motion
from sandbox.physics.imposed import Imposed
from sandbox.physics.spec import Values, per_revolution_timestep
from sandbox.scenes.compressor.course import kinematics, loop
from sandbox.scenes.compressor.params import DEFAULTS, RPM
from sandbox.scenes.imposed import held_speed


def _check_geometry(v: Values) -> None:
    if v["L"] <= v["R"] * 1.0001:
        raise BadParameter(
            f"the rod (L = {v['L']:g} m) must be longer than the crank (R = {v['R']:g} m); "
            "raise L or lower R",
            french=f"La bielle (L = {number(v['L'])} m) doit être plus longue que la manivelle "
            f"(R = {number(v['R'])} m) : augmentez L ou diminuez R.",
        )
    m1d1, m2d2 = v["m1"] * v["d1"] ** 2, v["m2"] * v["d2"] ** 2
    crank = np.array(
        [[v["A1"], 0, -v["E1"]], [0, v["B1"] - m1d1, 0], [-v["E1"], 0, v["C1"] - m1d1]]
    )
    rod = np.diag([v["A2"] - m2d2, v["B2"], v["C2"] - m2d2])
    for name, inertia, fix, words in (
        ("crank", crank, "raise A1, B1, C1 or lower m1·d1² and |E1|",
         "à la manivelle : augmentez A₁, B₁, C₁ ou diminuez m₁·d₁² et |E₁|"),
        ("rod", rod, "raise A2, C2 or lower m2·d2²",
         "à la bielle : augmentez A₂, C₂ ou diminuez m₂·d₂²"),
    ):  # fmt: skip
        eig = np.linalg.eigvalsh(inertia)
        if eig[0] <= 0 or eig[2] > eig[0] + eig[1] + 1e-15:
            raise BadParameter(
                f"these values give the {name} an impossible inertia at its centre of mass "
                f"(principal moments {', '.join(f'{e:.3g}' for e in eig)} kg·m²); {fix}",
                french="Ces valeurs donnent une matrice d'inertie impossible (moments "
                f"principaux {' ; '.join(number(e, 3) for e in eig)} kg·m²) {words}.",
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
    # a welded point mass: no mass at all when there is none (the course's counterweight)
    cw.explicitinertial = True
    cw.mass = m_cw
    cw.ipos = [0, 0, 0]
    cw.inertia = [m_cw * 1e-6] * 3
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


def place(model: mujoco.MjModel, data: mujoco.MjData, v: Values, motion: Motion) -> None:
    """The closure equations of the imposed motion: every joint from the crank's θ, θ'
    and θ'' (λ, φ and their derivatives, exact: :func:`kinematics`); the accelerations
    go to ``qacc_warmstart`` (:mod:`sandbox.physics.imposed`)."""
    theta, omega, alpha = motion
    lam, dlam, ddlam, phi, dphi, ddphi, _, _ = loop(
        math.sin(theta), math.cos(theta), omega, alpha, v["R"], v["L"]
    )
    data.qpos[:] = (theta, lam, phi)
    data.qvel[:] = (omega, dlam, dphi)
    data.qacc_warmstart[:] = (alpha, ddlam, ddphi)


IMPOSED = Imposed("crank", "motor", place, held_speed, default=True)
"""The crank turning at ``speed_rpm`` (from rest through the lag ``ramp_s`` when it is
positive), as the course studies it (4, 6.1.2, 7.3): imposed by default."""
