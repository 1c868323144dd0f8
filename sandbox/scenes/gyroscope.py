"""Gyrometer of an inertial unit (course 1, 2.2.2, 3, 5): a rotor in two gimbals.

The rotor spins about the inner gimbal's y; the inner gimbal pivots about the outer
gimbal's x; the outer gimbal pivots about the case's z; all three axes meet at O, the
rotor's centre of mass. The user turns the case (yaw, pitch, roll servos, or a preset
manoeuvre). Spinning, the rotor's axis keeps its direction in R0 and the gimbal angles
read the case's attitude; at spin 0 the small viscous friction of the gimbal pivots drags
the rotor along with the case (with perfect pivots, ``pivot_damping`` = 0, nothing would:
a torque-free rotor keeps its orientation whatever its spin; the spin makes it resist the
small torques a real instrument has). When the rotor's axis lines up with the outer
pivot (inner angle ±90°) the gimbals lock: only two rotations of the case are still free
for the rotor, and a turn of the case about the third drags the axis.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.physics.page import Arrow, Components, Names, Page
from sandbox.physics.presets import XYPreset
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import Accuracy, Effects, Param, Scene, SceneReadout, Series, Values
from sandbox.physics.torsors import spatial_at_origin as _spatial_at_origin

RPM = 2 * math.pi / 60
MANOEUVRES = {
    1: {"case_yaw_deg": 0.0, "case_pitch_deg": 0.0, "case_roll_deg": 120.0},
    2: {"case_yaw_deg": 90.0, "case_pitch_deg": 20.0, "case_roll_deg": 30.0},
}
"""Preset manoeuvres, reached with a 1 s time constant: 1 rolls the case to 120°, through
gimbal lock at 90° (outer pivot along the rotor's axis); 2 turns it without lock."""
LOCK_DEG = 10.0
"""The gimbal_lock flag rises when the rotor's axis is within this angle of the outer pivot."""
LOCK_SIN = math.cos(math.radians(LOCK_DEG))
PIVOT_DAMPING = 0.002  # N·m·s/rad, the default friction of each gimbal pivot

ROTOR, CASE, JOINTS = "Rotor", "Orientation du boîtier", "Liaisons"
PARAMS = (
    Param("spin_rpm", "rpm", 12000.0, 0.0, 30000.0, "Spin of the rotor, given at reset and whenever it is changed (an instant launch); in between the rotor turns freely on a perfect pivot.", live=True, step=100.0, label="Rotation propre du rotor", hint="Vitesse donnée au rotor au départ et à chaque changement ; entre-temps il tourne librement sur un pivot parfait.", group=ROTOR),
    Param("case_yaw_deg", "deg", 0.0, -180.0, 180.0, "Case attitude: yaw about z0.", live=True, step=1.0, label="Lacet du boîtier", hint="Orientation du boîtier : rotation de lacet autour de la verticale z₀.", group=CASE),
    Param("case_pitch_deg", "deg", 0.0, -90.0, 90.0, "Case attitude: pitch about the yawed y.", live=True, step=1.0, label="Tangage du boîtier", hint="Orientation du boîtier : rotation de tangage autour de l'axe y après le lacet.", group=CASE),
    Param("case_roll_deg", "deg", 0.0, -180.0, 180.0, "Case attitude: roll about the case's x.", live=True, step=1.0, label="Roulis du boîtier", hint="Orientation du boîtier : rotation de roulis autour de l'axe x du boîtier.", group=CASE),
    Param("manoeuvre", "", 2.0, 0.0, 2.0, "Preset case motion: 0 none (sliders), 1 roll to 120° through gimbal lock, 2 yaw 90°, pitch 20°, roll 30°.", live=True, step=1.0, label="Manœuvre programmée", hint="Mouvement tout prêt du boîtier ; « Aucune » le laisse aux curseurs de lacet, de tangage et de roulis.", group=CASE, choices=("Aucune (curseurs)", "Roulis jusqu'à 120°, par le blocage de cardan", "Lacet 90°, tangage 20°, roulis 30°")),
    Param("pivot_damping", "N·m·s/rad", PIVOT_DAMPING, 0.0, 0.02, "Viscous friction of each gimbal pivot (0: perfect pivots); the rotor's own pivot stays perfect.", live=True, step=1e-4, label="Frottement des pivots des cadres", hint="Frottement visqueux de chaque pivot des cadres (0 : pivots parfaits) ; le pivot du rotor reste parfait.", group=JOINTS, advanced=True),
)  # fmt: skip

CASE_JOINTS = ("case_yaw", "case_pitch", "case_roll")
CASE_PARAMS = ("case_yaw_deg", "case_pitch_deg", "case_roll_deg")
GIMBALS = ("outer", "inner")
_SPIN_DOF = 5  # qvel index of the rotor's hinge (after the 3 case and 2 gimbal hinges)
_APPLIED_SPIN = 3  # userdata slot holding the spin_rpm last given to the rotor


def set_points(v: Values) -> np.ndarray:
    """Case joint set points [rad]: the sliders, or the manoeuvre's."""
    src = MANOEUVRES.get(int(round(v["manoeuvre"])), v)
    return np.radians([src[n] for n in CASE_PARAMS])


def _launch(data: mujoco.MjData, spin_rpm: float) -> None:
    data.qvel[_SPIN_DOF] = spin_rpm * RPM
    data.userdata[_APPLIED_SPIN] = spin_rpm


def drive(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """Case servos and pivot friction; a new ``spin_rpm`` relaunches the rotor at once.

    The servo set points are filtered over 1 s during a manoeuvre (a smooth motion) and
    50 ms otherwise (the sliders). The spin is set only when ``spin_rpm`` differs from the
    one last applied, so a slider move, a new integrator or timestep leave the free spin
    alone.
    """
    model.actuator_dynprm[:, 0] = 1.0 if v["manoeuvre"] >= 0.5 else 0.05
    data.ctrl[:] = set_points(v)
    for name in GIMBALS:
        model.dof_damping[model.joint(name).dofadr[0]] = v["pivot_damping"]
    if data.userdata[_APPLIED_SPIN] != v["spin_rpm"]:
        _launch(data, v["spin_rpm"])


def _rotor_axis(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "rotor")
    return data.xmat[b].reshape(3, 3)[:, 1].copy()


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """Case at its set points (level for a manoeuvre), gimbals at 0, rotor spinning.

    The rotor's axis in R0 is kept in ``userdata[:3]`` as the reference of ``axis_drift``.
    """
    q = set_points(v) if v["manoeuvre"] < 0.5 else np.zeros(3)
    data.qpos[:] = 0.0
    data.qpos[:3] = q
    data.act[:] = q
    data.qvel[:] = 0.0
    _launch(data, v["spin_rpm"])
    mujoco.mj_kinematics(model, data)
    data.userdata[:3] = _rotor_axis(model, data)


def _axis(s: Snapshot) -> np.ndarray:
    return _rotor_axis(s.model, s.data)


def _sigma_g(s: Snapshot) -> np.ndarray:
    """Angular momentum of the rotor at G in R0: I_G ω (course 3)."""
    return s.kinematics.i_omega[s.body_id("rotor")].copy()


def pivot_moment(model: mujoco.MjModel, data: mujoco.MjData, gimbal: str) -> np.ndarray:
    """Moment at O of the pivot of ``gimbal`` on it (and what it carries), across the axis.

    ``cfrc_int`` is the wrench the parent body exerts on the subtree through the joint
    (``data`` after ``mj_rnePostConstraint``); the axial part (pivot friction) is removed.
    """
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, gimbal)
    _, moment = _spatial_at_origin(model, data, b, data.cfrc_int[b])
    axis = data.xaxis[model.joint(gimbal).id]
    return moment - (moment @ axis) * axis


def _drift(s: Snapshot) -> float:
    """Angle between the axis and its reference, as atan2(|a×a0|, a·a0): exact to round-off
    near 0, where acos(a·a0) reads sqrt(eps) ≈ 1.5e-8 rad for a still axis."""
    a0 = np.asarray(s.data.userdata[:3])
    a = _axis(s)
    return math.atan2(float(np.linalg.norm(np.cross(a, a0))), float(a @ a0))


def _lock(s: Snapshot) -> float:
    """1 when |rotor axis · outer pivot axis| = |sin(inner)| exceeds cos(LOCK_DEG)."""
    return float(abs(math.sin(s.joint_qpos("inner"))) > LOCK_SIN)


READOUTS = (
    SceneReadout("spin", "rad/s", "Spin of the rotor relative to the inner gimbal.", lambda s: s.joint_qvel("spin"), label="Rotation propre mesurée", hint="Vitesse de rotation du rotor par rapport au cadre intérieur."),
    SceneReadout("gimbal_outer", "rad", "Outer gimbal angle: the instrument's first reading.", lambda s: s.joint_qpos("outer"), label="Angle du cadre extérieur", hint="Première lecture de l'instrument : angle du pivot du cadre extérieur."),
    SceneReadout("gimbal_inner", "rad", "Inner gimbal angle: the instrument's second reading.", lambda s: s.joint_qpos("inner"), label="Angle du cadre intérieur", hint="Seconde lecture de l'instrument : angle du pivot du cadre intérieur."),
    SceneReadout("axis_drift", "rad", "Angle between the rotor's axis and its direction at reset, in R0.", _drift, label="Dérive de l'axe du rotor", hint="Angle entre l'axe du rotor et sa direction au départ, mesuré dans R₀."),
    SceneReadout("sigma_G_x", "kg·m²/s", "Rotor's angular momentum at G, on x0.", lambda s: float(_sigma_g(s)[0]), label="Moment cinétique σ en G selon x₀", hint="Composante sur x₀ du moment cinétique du rotor en son centre de gravité G."),
    SceneReadout("sigma_G_y", "kg·m²/s", "Rotor's angular momentum at G, on y0.", lambda s: float(_sigma_g(s)[1]), label="Moment cinétique σ en G selon y₀", hint="Composante sur y₀ du moment cinétique du rotor en son centre de gravité G."),
    SceneReadout("sigma_G_z", "kg·m²/s", "Rotor's angular momentum at G, on z0.", lambda s: float(_sigma_g(s)[2]), label="Moment cinétique σ en G selon z₀", hint="Composante sur z₀ du moment cinétique du rotor en son centre de gravité G."),
    SceneReadout("pivot_moment_inner", "N·m", "Moment the inner gimbal's pivots transmit, across their axis.", lambda s: float(np.linalg.norm(pivot_moment(s.model, s.data, "inner"))), label="Moment des pivots du cadre intérieur", hint="Norme du moment que les pivots du cadre intérieur transmettent, perpendiculairement à leur axe."),
    SceneReadout("pivot_moment_outer", "N·m", "Moment the outer gimbal's pivots transmit, across their axis.", lambda s: float(np.linalg.norm(pivot_moment(s.model, s.data, "outer"))), label="Moment des pivots du cadre extérieur", hint="Norme du moment que les pivots du cadre extérieur transmettent, perpendiculairement à leur axe."),
    SceneReadout("gimbal_lock", "", f"1 when the rotor's axis is within {LOCK_DEG:g}° of the outer pivot (lock), else 0.", _lock, label="Blocage de cardan", hint=f"1 quand l'axe du rotor est à moins de {LOCK_DEG:g}° du pivot du cadre extérieur (blocage), 0 sinon."),
)  # fmt: skip

ARROWS = (
    Arrow("axis", "Axe du rotor", (200, 120, 40), lambda s: (np.zeros(3), _axis(s)), 0.15, point="G", hint="Direction de l'axe de rotation propre du rotor (orange).", magnitude=False),
    Arrow("sigma_G", "Moment cinétique σ en G", (60, 100, 220), lambda s: (np.zeros(3), _sigma_g(s)), 0.15, unit="kg·m²/s", point="G", hint="Moment cinétique du rotor en son centre de gravité G (bleu).")
)  # fmt: skip


def _sigma_drift(series: Series, values: Values) -> float:
    sig = np.stack([series["sigma_G_x"], series["sigma_G_y"], series["sigma_G_z"]], axis=1)
    n = np.linalg.norm(sig, axis=1)
    return float(np.max(np.abs(n - n[0])) / max(n[0], 1e-12))


SCENE = Scene(
    name="gyroscope",
    title="Gyromètre : le rotor garde sa direction",
    summary=(
        "A fast rotor in two gimbals keeps its axis fixed in R0 while the case turns: "
        "the gimbal angles measure the case's attitude."
    ),
    mjcf="gyroscope.xml",
    params=PARAMS,
    effects=Effects(gravity=False, contacts=False, joint_damping=True, actuation=True),
    readouts=READOUTS,
    drive=drive,
    initial_state=initial_state,
    # RK4 at 1.5 ms, measured at 30,000 rpm (integrator x timestep, 0.15 to 5 ms):
    # - case held at a tilted attitude, gimbals nudged by 0.05 rad/s, 10 s: euler and
    #   implicitfast gain energy in this spinning hinge chain and throw the axis away
    #   (|σG| and spin off by ~100 %, drift > 0.6 rad) at every step, or diverge; implicit
    #   and RK4 keep |σG| to 1e-9 and agree on the physical drift (1.4e-4 rad, the nudge).
    # - manoeuvre 2, 2 s, against RK4 at 0.05 ms: implicit's numerical damping bends the
    #   axis (5.8e-4 rad off at 1.5 ms) and bleeds |σG| (2.5e-7); RK4 is within 5e-7 rad
    #   and keeps |σG| to 1e-13, for 30 % more CPU.
    # RK4 diverges at 5 ms (the nutation, ~770 rad/s, leaves its stability region near
    # 3.7 ms); 1.5 ms keeps a 2.4x margin, runs ~100x faster than real time and goes
    # through gimbal lock at 30,000 rpm without a warning.
    integrator="rk4",
    timestep=1.5e-3,
    # Round-off only: the axis drift (atan2: 0 for a still axis, 1e-9 rad and up when it
    # drifts) and the pivots' moments stay visible.
    zero={"N": 1e-9, "N·m": 1e-12, "W": 1e-12, "kg·m/s": 1e-12, "rad": 1e-12},
    sections="1, 2.2.2, 3, 5",
    accuracy=Accuracy(
        key="axis_drift",
        readouts=("axis_drift", "sigma_G_x", "sigma_G_y", "sigma_G_z"),
        duration=2.0,
        error=lambda series, values: float(np.max(series["axis_drift"])),
        invariant="|σG|",
        drift=_sigma_drift,
        values={"spin_rpm": 30000.0, "manoeuvre": 2.0},
        timesteps=(1.5e-4, 5e-4, 1.5e-3, 5e-3, 1.5e-2),
        # |σG| kept to 1e-6 over 10 s (the limit), i.e. 2e-7 over this 2 s run:
        # the implicit integrator, stable and cheap, bleeds σG (numerical damping) past it.
        drift_tol=2e-7,
    ),
    page=Page(
        overlay={
            "gimbal_outer": "Cadre extérieur",
            "gimbal_inner": "Cadre intérieur",
            "axis_drift": "Dérive de l'axe",
        },
        plots=("gimbal_outer", "gimbal_inner", "axis_drift"),
        xy_presets=(
            XYPreset(
                "Angles des cadres au cours du temps",
                "time",
                ("gimbal_outer", "gimbal_inner"),
                hint="Les cadres tournent avec le boîtier pendant que l'axe du rotor garde sa "
                "direction.",
            ),
            XYPreset(
                "Dérive de l'axe selon l'angle du cadre extérieur",
                "gimbal_outer",
                ("axis_drift",),
                hint="Ce que l'axe du rotor perd de sa direction pendant que le boîtier tourne.",
            ),
        ),
        arrows=ARROWS,
        # Longest MJCF names first: the isolate panel replaces them in its texts.
        names=Names(
            solids={
                "case_pitch": "support de tangage",
                "case_yaw": "support de lacet",
                "case": "boîtier",
                "outer": "cadre extérieur",
                "inner": "cadre intérieur",
            }
        ),
        body_frame="rotor",
        camera=((0.8, -1.0, 0.6), (0.0, 0.0, 1.0)),
        trail=lambda s: 0.07 * _axis(s),  # tip of the rotor's axle: stays put while spinning
        # Course 5: σG keeps its direction in R0 (its components stay put while the gimbals
        # turn).
        components=Components(("sigma_G",), "B0", (0, 1, 2), "B0, fixe"),
    ),
)
