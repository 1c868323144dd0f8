"""Heavy gyroscope: steady precession of a symmetric top (course 2.2.2, 3, 5).

A rotor, symmetric about its axis e3, turns on a fixed point O (ball joint); its centre of
mass G is at OG = d e3. With ψ the precession about z0, θ the angle of e3 from z0 (the
nutation angle) and r = ω·e3 the spin, steady precession at constant θ needs
A_O Ω² cos θ − C r Ω + m g d = 0 (A_O = I_transverse + m d², C = I_spin): the slow root
tends to the fast-top value Ω = m g d / (C r). The scene starts on that steady state.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.physics.readouts import _cross
from sandbox.physics.snapshot import Snapshot
from sandbox.scenes.base import Accuracy, Arrow, Effects, Param, Scene, SceneReadout, Values
from sandbox.scenes.measures import energy_drift

G = 9.81
RPM = 2 * math.pi / 60

PARAMS = (
    Param("spin_rpm", "rpm", 3000.0, 0.0, 30000.0, "Spin r of the rotor about its own axis.", step=50.0),
    Param("mass", "kg", 1.0, 0.01, 20.0, "Mass of the rotor.", step=0.01),
    Param("d", "m", 0.1, 0.0, 0.5, "OG: distance from the fixed point to the centre of mass.", step=0.005),
    Param("I_spin", "kg·m²", 0.004, 1e-5, 1.0, "C: inertia about the rotor's axis.", step=1e-4),
    Param("I_transverse", "kg·m²", 0.002, 1e-5, 1.0, "A: inertia about a transverse axis through G.", step=1e-4),
    Param("tilt_deg", "deg", 30.0, 0.0, 89.0, "θ: angle of the axis from the vertical z0.", step=0.5),
)  # fmt: skip


def precession(v: Values) -> tuple[float, float]:
    """(exact slow root, fast-top limit) of the steady precession rate Ω [rad/s]."""
    m, d, c = v["mass"], v["d"], v["I_spin"]
    a_o = v["I_transverse"] + m * d * d
    r = v["spin_rpm"] * RPM
    theta = math.radians(v["tilt_deg"])
    fast = m * G * d / (c * r) if r else math.inf
    k = a_o * math.cos(theta)
    if abs(k) < 1e-15:
        return fast, fast
    disc = (c * r) ** 2 - 4 * k * m * G * d
    if disc < 0:
        return math.nan, fast  # too slow a spin: no steady precession at this angle
    return (c * r - math.sqrt(disc)) / (2 * k), fast


def reference(v: Values) -> dict[str, float]:
    exact, _ = precession(v)
    return {"precession_rate": exact, "nutation": math.radians(v["tilt_deg"])}


def edit(spec: mujoco.MjSpec, v: Values) -> None:
    """Mass, G on the axis at d, inertia diag(A, A, C) at G."""
    body = spec.body("rotor")
    body.mass = v["mass"]
    body.ipos = [0, 0, v["d"]]
    a, c = v["I_transverse"], v["I_spin"]
    if c > 2 * a:
        from sandbox.errors import BadParameter

        raise BadParameter(
            f"I_spin = {c:g} exceeds 2 × I_transverse = {2 * a:g}, impossible for a rigid "
            "body; raise I_transverse or lower I_spin"
        )
    body.inertia = [a, a, c]
    spec.geom("disk").pos = [0, 0, v["d"]]
    spec.geom("mark").pos = [0.04, 0, v["d"]]
    spec.geom("axle").fromto = [0, 0, 0, 0, 0, max(v["d"] * 1.4, 0.05)]


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """Axis tilted by θ in the (x0, z0) plane, spinning at r, precessing at the exact Ω."""
    theta = math.radians(v["tilt_deg"])
    quat = np.array([math.cos(theta / 2), 0.0, math.sin(theta / 2), 0.0])
    data.qpos[:4] = quat
    omega_p, _ = precession(v)
    if not math.isfinite(omega_p):
        omega_p = 0.0
    r = v["spin_rpm"] * RPM
    e3 = np.array([math.sin(theta), 0.0, math.cos(theta)])
    # ω = Ω z0 + φ' e3 with φ' = r − Ω cos θ, so that ω·e3 = r.
    omega = omega_p * np.array([0, 0, 1.0]) + (r - omega_p * math.cos(theta)) * e3
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, quat)
    data.qvel[:3] = rot.reshape(3, 3).T @ omega  # ball joints use body axes


def _axis(s: Snapshot) -> np.ndarray:
    return s.data.xmat[s.body_id("rotor")].reshape(3, 3)[:, 2].copy()


def _omega(s: Snapshot) -> np.ndarray:
    return s.data.cvel[s.body_id("rotor"), :3].copy()


def _precession_rate(s: Snapshot) -> float:
    e3 = _axis(s)
    de3 = _cross(_omega(s), e3)
    h = e3[0] ** 2 + e3[1] ** 2
    return float((e3[0] * de3[1] - e3[1] * de3[0]) / h) if h > 1e-12 else 0.0


def _sigma_o(s: Snapshot) -> np.ndarray:
    b = s.body_id("rotor")
    rot = s.data.ximat[b].reshape(3, 3)
    i_g = rot @ np.diag(s.model.body_inertia[b]) @ rot.T
    w = _omega(s)
    from sandbox.physics.readouts import Kinematics, _cross

    v_g = Kinematics(s.model, s.data).v_g[b]
    return i_g @ w + _cross(s.data.xipos[b], s.model.body_mass[b] * v_g)


READOUTS = (
    SceneReadout("precession_rate", "rad/s", "ψ': rate at which the axis turns about z0.", _precession_rate),
    SceneReadout("nutation", "rad", "θ: angle of the rotor's axis from z0.", lambda s: float(math.acos(max(-1.0, min(1.0, _axis(s)[2]))))),
    SceneReadout("spin", "rad/s", "r = ω·e3: spin about the rotor's own axis.", lambda s: float(_omega(s) @ _axis(s))),
    SceneReadout("sigma_O_z", "kg·m²/s", "Angular momentum about the vertical z0 through O (conserved).", lambda s: float(_sigma_o(s)[2])),
    SceneReadout("precession_fast_top", "rad/s", "Course's fast-top value m g d / (C r) at the current spin.", lambda s: precession(s.values)[1]),
)  # fmt: skip

ARROWS = (
    Arrow("axis", "Axe e3", (200, 120, 40), lambda s: (np.zeros(3), _axis(s)), 0.2),
    Arrow("sigma_O", "σO", (60, 100, 220), lambda s: (np.zeros(3), _sigma_o(s)), 0.15),
)


def _precession_error(series, values) -> float:
    exact, _ = precession(values)
    return float(np.max(np.abs(np.asarray(series["precession_rate"]) - exact)) / abs(exact))


SCENE = Scene(
    name="heavy_gyroscope",
    title="Gyroscope pesant : précession",
    summary=(
        "A spinning rotor on a fixed point, its centre of mass off the point: weight makes "
        "the axis precess about the vertical instead of falling."
    ),
    mjcf="heavy_gyroscope.xml",
    params=PARAMS,
    effects=Effects(gravity=True, contacts=False, actuation=False),
    readouts=READOUTS,
    edit=edit,
    initial_state=initial_state,
    reference=reference,
    # RK4: first-order integrators gain energy on a spinning ball joint (sandbox bench);
    # 0.5 ms is ω dt = 0.16 at 3000 rpm.
    integrator="rk4",
    timestep=5e-4,
    plots=("precession_rate", "nutation"),
    arrows=ARROWS,
    body_frame="rotor",
    sections="2.2.2, 3, 5",
    camera=((0.6, -1.0, 0.5), (0.0, 0.0, 1.0)),
    trail=lambda s: 1.4 * max(s.values["d"], 0.036) * _axis(s),  # tip of the axle: the cone
    accuracy=Accuracy(
        key="precession_rate",
        readouts=("precession_rate", "T", "V"),
        duration=1.0,
        error=_precession_error,
        invariant="T + V",
        drift=energy_drift(),
        timesteps=(5e-5, 1.5e-4, 5e-4, 1.5e-3, 5e-3),
        drift_tol=1e-3,  # T + V: first-order integrators gain energy on a spinning top
    ),
)
