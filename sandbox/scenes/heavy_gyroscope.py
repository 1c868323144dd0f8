"""Heavy gyroscope: steady precession of a symmetric top (course 2.2.2, 3, 5).

A rotor, symmetric about its axis e3, turns on a fixed point O (ball joint); its centre of
mass G is at OG = d e3. With ψ the precession about z0, θ the angle of e3 from z0 (the
nutation angle) and r = ω·e3 the spin, σ_O = A_O ω⊥ + C r e3 (A_O = I_transverse + m d²,
C = I_spin, course 3 and Huygens 5.5). At constant θ, ψ' = Ω and r, σ_O turns with Ω z0,
and the moment relation at O (2.2.2) with the weight's moment m g d z0 ∧ e3 gives
Ω (C r − A_O Ω cos θ) = m g d, i.e. A_O Ω² cos θ − C r Ω + m g d = 0. Of its two roots, the
scene uses the slow one, Ω = 2 m g d / (C r + √((C r)² − 4 A_O cos θ m g d)), which tends
to the fast-top value Ω = m g d / (C r) as the spin grows (the other root, ≈ C r /
(A_O cos θ), is a fast precession that needs a large initial kick). The scene starts on
that steady state.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.errors import BadParameter
from sandbox.french import number
from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.page import Arrow, Components, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import (
    Accuracy,
    Effects,
    Param,
    Scene,
    SceneReadout,
    Series,
    Values,
    per_revolution_timestep,
)
from sandbox.scenes.measures import energy_drift

G = 9.81
RPM = 2 * math.pi / 60

LAUNCH, ROTOR = "Lancement", "Rotor"
PARAMS = (
    Param("spin_rpm", "rpm", 3000.0, 0.0, 30000.0, "Spin r of the rotor about its own axis (a change relaunches the top on the steady precession).", live=True, step=50.0, label="Rotation propre r", hint="Vitesse de rotation du rotor autour de son axe e₃ ; la changer relance la toupie sur sa précession stationnaire.", group=LAUNCH),
    Param("mass", "kg", 1.0, 0.01, 20.0, "Mass of the rotor.", step=0.01, label="Masse du rotor m", hint="Masse du rotor, qui tourne autour du point fixe O.", group=ROTOR),
    Param("d", "m", 0.1, 0.0, 0.5, "OG: distance from the fixed point to the centre of mass.", step=0.005, label="Distance OG d", hint="Distance du point fixe O au centre de gravité G, le long de l'axe du rotor.", group=ROTOR),
    Param("I_spin", "kg·m²", 0.004, 1e-5, 1.0, "C: inertia about the rotor's axis.", step=1e-4, label="Moment d'inertie axial C", hint="Moment d'inertie du rotor autour de son axe e₃.", group=ROTOR, advanced=True, log=True),
    Param("I_transverse", "kg·m²", 0.002, 1e-5, 1.0, "A: inertia about a transverse axis through G.", step=1e-4, label="Moment d'inertie transversal A", hint="Moment d'inertie du rotor autour d'un axe perpendiculaire à e₃ passant par G.", group=ROTOR, advanced=True, log=True),
    Param("tilt_deg", "deg", 30.0, 0.0, 89.0, "θ: angle of the axis from the vertical z0 at launch (a change relaunches the top).", live=True, step=0.5, label="Inclinaison de l'axe θ", hint="Angle de l'axe e₃ avec la verticale z₀ au lancement ; le changer relance la toupie.", group=LAUNCH),
)  # fmt: skip


def precession(v: Values) -> tuple[float, float]:
    """(exact slow root, fast-top limit) of the steady precession rate Ω [rad/s].

    The slow root is written 2 m g d / (C r + √Δ), free of the cancellation of
    (C r − √Δ) / (2 A_O cos θ) at high spin and valid at θ = 90°. NaN when Δ < 0: the spin
    is too slow for a steady precession at this angle.
    """
    m, d, c = v["mass"], v["d"], v["I_spin"]
    a_o = v["I_transverse"] + m * d * d
    cr = c * v["spin_rpm"] * RPM
    mgd = m * G * d
    fast = mgd / cr if cr else math.inf
    disc = cr * cr - 4.0 * a_o * math.cos(math.radians(v["tilt_deg"])) * mgd
    if disc < 0:
        return math.nan, fast
    root = cr + math.sqrt(disc)
    return (2.0 * mgd / root if root else 0.0), fast


def reference(v: Values) -> dict[str, float]:
    """Exact steady precession rate and the nutation angle θ it keeps (none if too slow)."""
    exact, _ = precession(v)
    if math.isnan(exact):
        return {}
    return {"precession_rate": exact, "nutation": math.radians(v["tilt_deg"])}


def edit(spec: mujoco.MjSpec, v: Values) -> None:
    """Mass, G on the axis at d, inertia diag(A, A, C) at G."""
    body = spec.body("rotor")
    body.mass = v["mass"]
    body.ipos = [0, 0, v["d"]]
    a, c = v["I_transverse"], v["I_spin"]
    if c > 2 * a:
        raise BadParameter(
            f"I_spin = {c:g} exceeds 2 × I_transverse = {2 * a:g}, impossible for a rigid "
            "body; raise I_transverse or lower I_spin",
            french=f"Le moment axial C = {number(c)} kg·m² dépasse 2 × A = {number(2 * a)} kg·m², "
            "impossible pour un solide : augmentez A ou diminuez C.",
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


_LAUNCH = ("spin_rpm", "tilt_deg")  # launch conditions, kept in userdata[0:2]
_ARMED = 2  # userdata slot: 0 on fresh data (reset or model rebuild), 1 once recorded


def drive(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """Relaunch the top on the steady precession when ``spin_rpm`` or ``tilt_deg`` change.

    The two are initial conditions, not model data: on fresh data (a reset, or a rebuild
    after mass, d or an inertia changed, which keeps the running motion) they are only
    recorded; a later change of either restarts the top at the current time.
    """
    launch = [v[n] for n in _LAUNCH]
    if data.userdata[_ARMED] and list(data.userdata[:2]) != launch:
        initial_state(model, data, v)
    data.userdata[:2] = launch
    data.userdata[_ARMED] = 1.0


SPIN_ANGLE = 30000.0 * RPM * 1.5e-4
"""Spin angle per step [rad] (0.47): RK4 at 0.15 ms holds the precession within 6e-4 of
the exact root at 30,000 rpm, the top of the range; the error grows as (r dt)⁴."""
LARGEST_TIMESTEP = 5e-4
"""Default timestep at moderate spin [s]: a minute at 3000 rpm keeps θ to 3.4e-5 rad
(0.002°), Ω to 8.7e-6 and T + V to 8e-8 of T, below the four significant figures the page
writes, for 2.5 times less CPU than 0.2 ms (3.5e-7 rad, 2.2e-7, 1e-9; 30 students at 0.2
ms took 0.6 of the laptop's 2 cores before anything was drawn). At 9000 rpm, where the
spin angle per step reaches :data:`SPIN_ANGLE`, a minute keeps Ω to 6.4e-4, the accuracy
held over the whole range. Gravity sets time scales that do not follow the spin, so the
step cannot grow as 1/r below 9000 rpm the way it shrinks above."""


def default_timestep(v: Values, data: mujoco.MjData | None = None) -> float:
    """RK4 timestep [s]: at most :data:`SPIN_ANGLE` of spin per step, at most
    :data:`LARGEST_TIMESTEP` (0.5 ms up to 9000 rpm, 0.2 ms at 22,500 rpm, 0.15 ms at
    30,000 rpm). A new spin
    relaunches the top at once, so the state adds nothing."""
    return per_revolution_timestep(SPIN_ANGLE, v["spin_rpm"] * RPM, largest=LARGEST_TIMESTEP)


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
    v_g = s.kinematics.v_g[b]
    return i_g @ _omega(s) + _cross(s.data.xipos[b], s.model.body_mass[b] * v_g)


READOUTS = (
    SceneReadout("precession_rate", "rad/s", "ψ': rate at which the axis turns about z0.", _precession_rate, label="Vitesse de précession ψ'", hint="Vitesse à laquelle l'axe du rotor tourne autour de la verticale z₀."),
    SceneReadout("nutation", "rad", "θ: angle of the rotor's axis from z0.", lambda s: float(math.acos(max(-1.0, min(1.0, _axis(s)[2])))), label="Angle de nutation θ", hint="Angle de l'axe du rotor avec la verticale z₀."),
    SceneReadout("spin", "rad/s", "r = ω·e3: spin about the rotor's own axis.", lambda s: float(_omega(s) @ _axis(s)), label="Rotation propre mesurée r", hint="Composante r = ω·e₃ de la rotation du rotor sur son propre axe."),
    SceneReadout("sigma_O_z", "kg·m²/s", "Angular momentum about the vertical z0 through O (conserved).", lambda s: float(_sigma_o(s)[2]), label="Moment cinétique vertical en O", hint="Composante sur z₀ du moment cinétique du rotor en O, conservée car le moment du poids en O est horizontal."),
    SceneReadout("precession_fast_top", "rad/s", "Course's fast-top value m g d / (C r) at the current spin.", lambda s: precession(s.values)[1], label="Précession de la toupie rapide m·g·d/(C·r)", hint="Valeur approchée du cours pour une rotation propre rapide, à la rotation propre actuelle."),
)  # fmt: skip

ARROWS = (
    Arrow("axis", "Axe du rotor e₃", (200, 120, 40), lambda s: (np.zeros(3), _axis(s)), 0.2, point="O", hint="Direction de l'axe e₃ du rotor, depuis le point fixe O (orange).", magnitude=False),
    Arrow("sigma_O", "Moment cinétique σ en O", (60, 100, 220), lambda s: (np.zeros(3), _sigma_o(s)), 0.15, unit="kg·m²/s", point="O", hint="Moment cinétique du rotor au point fixe O (bleu)."),
)  # fmt: skip


def _precession_error(series: Series, values: Values) -> float:
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
    drive=drive,
    initial_state=initial_state,
    reference=reference,
    # RK4, measured (integrator x timestep, 5 s on the steady precession):
    # euler and implicitfast gain energy on the spinning ball joint (Ω off by 6x at 50 µs
    # at 3000 rpm, divergence from 0.5 ms); implicit is stable but damps the motion (Ω off
    # by 0.6 % at 50 µs, 14 % at 1.5 ms; θ off by 0.03 to 1 rad). RK4 keeps T + V to 7e-9
    # and Ω within 9e-6 of the exact root at 0.5 ms and 3000 rpm, but the error grows as
    # (r dt)^4: at 30,000 rpm 0.5 ms is 2.3 % off and 1.5 ms diverges, while 0.15 ms
    # (r dt = 0.47) stays within 6e-4. So the step follows the spin (default_timestep):
    # 0.5 ms up to 9000 rpm (LARGEST_TIMESTEP), 0.15 ms at 30,000 rpm.
    integrator="rk4",
    timestep=5e-4,
    timestep_for=default_timestep,
    # Round-off: {D} and the frame's moment keep 1e-14 N·m about z0 where the course has 0;
    # the powers (2e-8 W: the nutation the launch leaves) stay visible.
    zero={"N": 1e-9, "N·m": 1e-12, "kg·m/s": 1e-12},
    sections="2.2.2, 3, 5",
    accuracy=Accuracy(
        key="precession_rate",
        readouts=("precession_rate", "T", "V"),
        duration=1.0,
        error=_precession_error,
        invariant="T + V",
        drift=energy_drift(),
        timesteps=(5e-5, 2e-4, 5e-4, 1.5e-3, 5e-3),  # the default among them
        drift_tol=1e-3,  # T + V: first-order integrators gain energy on a spinning top
    ),
    page=Page(
        overlay={
            "precession_rate": "Vitesse de précession",
            "nutation": "Nutation",
            "spin": "Rotation propre",
        },
        plots=("precession_rate", "nutation"),
        study_presets=(
            StudyPreset(
                "Vitesse de précession selon la rotation propre",
                ("spin_rpm", 2000.0, 10000.0, 9),
                "precession_rate",
                statistic="mean",
                duration=1.0,
                hint="Plus la toupie tourne vite, plus elle précesse lentement : la vitesse de "
                "précession varie comme l'inverse de la rotation propre.",
            ),
        ),
        xy_presets=(
            XYPreset(
                "Nutation au cours du temps",
                "time",
                ("nutation",),
                hint="L'axe hoche pendant qu'il précesse : la nutation.",
            ),
            XYPreset(
                "Précession selon la nutation",
                "nutation",
                ("precession_rate",),
                refs={"precession_rate": "precession_fast_top"},
                hint="La vitesse de précession oscille avec la nutation ; en tirets, la "
                "précession de la toupie rapide du cours.",
            ),
        ),
        arrows=ARROWS,
        body_frame="rotor",
        camera=((0.6, -1.0, 0.5), (0.0, 0.0, 1.0)),
        trail=lambda s: 1.4 * max(s.values["d"], 0.036) * _axis(s),  # tip of the axle: the cone
        # The heavy top's σO turns about z0 at the precession rate (x0 and y0 components are
        # sinusoids, the z0 one is conserved).
        components=Components(("sigma_O",), "B0", (0, 1, 2), "B0, fixe"),
    ),
)
