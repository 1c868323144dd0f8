"""Unbalanced rotor on a fixed axis (course section 7.2): static and dynamic balancing.

Rotor 1 turns about (O, x0) at constant speed, guided by two bearings A and B. A defect
mass gives a static unbalance (G off the axis) and a skewed disk a couple unbalance
(products of inertia E, F of the x column). Two correction masses, one per plane at a
fixed radius, let the student cancel both: static balance needs Y = 0, dynamic balance
needs Y = 0 and E = F = 0.
"""

from __future__ import annotations

import functools
import math

import mujoco
import numpy as np

from sandbox.mechanics import MassProperties, coefficients, combine, cylinder, huygens, sphere
from sandbox.mechanics.vectors import cross as _cross
from sandbox.physics.snapshot import Snapshot
from sandbox.scenes.base import Accuracy, Arrow, Effects, Param, Scene, SceneReadout, Values
from sandbox.scenes.measures import relative_drift, worst_relative_error
from sandbox.scenes.presets import StudyPreset, XYPreset

# Geometry (metres, kg/m³), shared by the model edits and the closed-form reference.
STEEL = 7800.0
SHAFT_RADIUS, SHAFT_LENGTH = 0.01, 0.40
DISK_RADIUS, DISK_THICKNESS = 0.10, 0.02
FLANGE_RADIUS, FLANGE_THICKNESS = 0.06, 0.01
BEARING_X = 0.15  # A at x = -a, B at x = +a (O mid-span)
PLANE_X = 0.12  # correction planes 1 at x = -c, 2 at x = +c
CORRECTION_RADIUS = 0.05
DEFECT_X, DEFECT_RADIUS = 0.0, 0.08
MASS_SPHERE_RADIUS = 0.006
AXIS = np.array([1.0, 0.0, 0.0])

PARAMS = (
    Param(
        "speed_rpm",
        "rpm",
        1500.0,
        0.0,
        6000.0,
        "Rotation speed imposed by the motor.",
        live=True,
        step=50.0,
        label="Vitesse de rotation ω",
        hint="Vitesse que le moteur impose au rotor autour de l'axe (O, x₀).",
        group="Entraînement",
    ),
    Param(
        "defect_mass_g",
        "g",
        20.0,
        0.0,
        200.0,
        "Defect mass on the disk at 80 mm from the axis (static unbalance).",
        step=1.0,
        label="Masselotte de défaut",
        hint="Masselotte collée sur le disque à 80 mm de l'axe, dans la direction y₁ : "
        "elle écarte G de l'axe (balourd statique).",
        group="Défauts",
    ),
    Param(
        "skew_deg",
        "deg",
        2.0,
        -10.0,
        10.0,
        "Tilt of the disk's axis from the rotation axis (couple unbalance).",
        step=0.1,
        label="Inclinaison du disque",
        hint="Angle entre l'axe du disque et l'axe de rotation : il fait apparaître les "
        "produits d'inertie E et F (balourd de couple).",
        group="Défauts",
    ),
    Param(
        "mass1_g",
        "g",
        0.0,
        0.0,
        200.0,
        "Correction mass in plane 1 (x = -120 mm) at 50 mm from the axis.",
        step=0.1,
        label="Masse de correction m₁",
        hint="Masse placée dans le plan de correction 1 (x = −120 mm), à 50 mm de l'axe.",
        group="Masses de correction",
    ),
    Param(
        "angle1_deg",
        "deg",
        0.0,
        -180.0,
        180.0,
        "Angle of correction mass 1 from y1 towards z1.",
        step=1.0,
        label="Angle de la masse m₁ α₁",
        hint="Position de m₁ autour de l'axe, comptée de y₁ vers z₁ (0° : du côté de la "
        "masselotte de défaut).",
        group="Masses de correction",
    ),
    Param(
        "mass2_g",
        "g",
        0.0,
        0.0,
        200.0,
        "Correction mass in plane 2 (x = +120 mm) at 50 mm from the axis.",
        step=0.1,
        label="Masse de correction m₂",
        hint="Masse placée dans le plan de correction 2 (x = +120 mm), à 50 mm de l'axe.",
        group="Masses de correction",
    ),
    Param(
        "angle2_deg",
        "deg",
        0.0,
        -180.0,
        180.0,
        "Angle of correction mass 2 from y1 towards z1.",
        step=1.0,
        label="Angle de la masse m₂ α₂",
        hint="Position de m₂ autour de l'axe, comptée de y₁ vers z₁ (0° : du côté de la "
        "masselotte de défaut).",
        group="Masses de correction",
    ),
    Param(
        "ramp_s",
        "s",
        0.0,
        0.0,
        10.0,
        "0: start at speed; > 0: start at rest, the motor's set point rising with this time "
        "constant.",
        step=0.1,
        label="Temps de montée en vitesse τ",
        hint="0 : le rotor part à sa vitesse ; sinon il part du repos et la consigne du "
        "moteur monte vers ω avec cette constante de temps (ω atteint 95 % en 3τ).",
        group="Entraînement",
        advanced=True,
    ),
)


def omega(values: Values) -> float:
    """Imposed speed [rad/s]."""
    return values["speed_rpm"] * 2.0 * math.pi / 60.0


def _radial(x: float, radius: float, angle_deg: float) -> np.ndarray:
    a = math.radians(angle_deg)
    return np.array([x, radius * math.cos(a), radius * math.sin(a)])


def disk_axis(values: Values) -> np.ndarray:
    """Unit axis of the skewed disk in the rotor frame (tilted about z1)."""
    b = math.radians(values["skew_deg"])
    return np.array([math.cos(b), math.sin(b), 0.0])


def _mass_points(values: Values) -> list[tuple[str, float, np.ndarray]]:
    return [
        ("defect", values["defect_mass_g"] / 1000.0, _radial(DEFECT_X, DEFECT_RADIUS, 0.0)),
        (
            "correction1",
            values["mass1_g"] / 1000.0,
            _radial(-PLANE_X, CORRECTION_RADIUS, values["angle1_deg"]),
        ),
        (
            "correction2",
            values["mass2_g"] / 1000.0,
            _radial(PLANE_X, CORRECTION_RADIUS, values["angle2_deg"]),
        ),
    ]


def edit(spec: mujoco.MjSpec, values: Values) -> None:
    """Place the defect and correction masses and tilt the disk."""
    quat = np.zeros(4)
    mujoco.mju_quatZ2Vec(quat, disk_axis(values))
    disk = spec.geom("disk")
    disk.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT  # the XML gives a zaxis
    disk.quat = quat
    for name, mass, pos in _mass_points(values):
        geom = spec.geom(name)
        geom.mass = mass
        geom.pos = pos
        geom.rgba[3] = 1.0 if mass > 0 else 0.0
    motor = spec.actuator("motor")  # a first-order set point: a start from rest
    if values["ramp_s"] > 0:
        motor.dyntype = mujoco.mjtDyn.mjDYN_FILTEREXACT
        motor.dynprm[0] = values["ramp_s"]
    else:
        motor.dyntype = mujoco.mjtDyn.mjDYN_NONE


def drive(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """The velocity servo holds the imposed speed."""
    data.ctrl[0] = omega(values)


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """Start already at the imposed speed (steady state), or at rest for a start."""
    data.qvel[0] = 0.0 if values["ramp_s"] > 0 else omega(values)


# -- closed-form reference (course 7.2) ---------------------------------------------------
def mass_properties(values: Values) -> MassProperties:
    """Mass, centre of mass and inertia of rotor 1 in its own frame, from the shapes."""

    def shaped(inertia: np.ndarray, mass: float, com: np.ndarray, axis: np.ndarray):
        rot = np.zeros(9)
        quat = np.zeros(4)
        mujoco.mju_quatZ2Vec(quat, axis)
        mujoco.mju_quat2Mat(rot, quat)
        return MassProperties.of_shape(inertia, mass, com, rotation=rot.reshape(3, 3))

    def cyl_mass(r: float, h: float) -> float:
        return STEEL * math.pi * r * r * h

    parts = []
    m = cyl_mass(SHAFT_RADIUS, SHAFT_LENGTH)
    parts.append(shaped(cylinder(m, SHAFT_RADIUS, SHAFT_LENGTH), m, np.zeros(3), AXIS))
    m = cyl_mass(DISK_RADIUS, DISK_THICKNESS)
    parts.append(
        shaped(cylinder(m, DISK_RADIUS, DISK_THICKNESS), m, np.zeros(3), disk_axis(values))
    )
    m = cyl_mass(FLANGE_RADIUS, FLANGE_THICKNESS)
    for x in (-PLANE_X, PLANE_X):
        parts.append(
            shaped(cylinder(m, FLANGE_RADIUS, FLANGE_THICKNESS), m, np.array([x, 0, 0]), AXIS)
        )
    for _, mass, pos in _mass_points(values):
        parts.append(MassProperties.of_shape(sphere(mass, MASS_SPHERE_RADIUS), mass, pos))
    return combine(parts)


def unbalance(values: Values) -> tuple[float, np.ndarray, float, float]:
    """(m, G, E, F) of the rotor: mass [kg], centre [m], products at O [kg·m²]."""
    props = mass_properties(values)
    _, _, _, _, e, f = coefficients(props.inertia_at(np.zeros(3)))
    return props.mass, props.com, e, f


def bearing_split(r: np.ndarray, m_o: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Forces of the frame at A and B from its action (R, M_O) across the axis.

    Bearing A (ball joint at x = -a) and B (linear annular joint at x = +a) make the
    guidance isostatic: R⊥ = F_A + F_B and M_O⊥ = OA ∧ F_A + OB ∧ F_B.
    """
    r_perp = r - np.dot(r, AXIS) * AXIS
    twist = _cross(m_o, AXIS) / BEARING_X
    return 0.5 * (r_perp - twist), 0.5 * (r_perp + twist)


def reference(values: Values) -> dict[str, float]:
    """Course 7.2: F_rot = m ω² Y, M_rot = ω² √(E²+F²), and the bearing forces."""
    w = omega(values)
    mass, g, e, f = unbalance(values)
    r = -mass * w * w * np.array([0.0, g[1], g[2]])
    m_o = w * w * np.array([0.0, e, -f])
    f_a, f_b = bearing_split(r, m_o)
    return {
        "omega": w,
        "static_unbalance": mass * math.hypot(g[1], g[2]),
        "products_EF": math.hypot(e, f),
        "F_rot": float(np.linalg.norm(r)),
        "M_rot": float(np.linalg.norm(m_o)),
        "bearing_A": float(np.linalg.norm(f_a)),
        "bearing_B": float(np.linalg.norm(f_b)),
    }


@functools.lru_cache(maxsize=64)
def _bearing_gains(key: tuple[tuple[str, float], ...]) -> tuple[float, float]:
    """|F_A| / ω² and |F_B| / ω² of the course (7.2) for the rotor of these values."""
    ref = reference({**dict(key), "speed_rpm": 30.0 / math.pi})  # ω = 1 rad/s
    return ref["bearing_A"], ref["bearing_B"]


def _bearing_ref(s: Snapshot, k: int) -> float:
    """The course's bearing force at the measured ω (the speed may be ramping)."""
    key = tuple(sorted((n, float(v)) for n, v in s.values.items() if n != "speed_rpm"))
    w = s.joint_qvel("spin")
    return _bearing_gains(key)[k] * w * w


def balancing_solution(values: Values) -> dict[str, float]:
    """Correction masses that balance statically and dynamically (course 7.2.2–7.2.3).

    A point mass m_k at (x_k, r cos φ_k, r sin φ_k) adds u_k = m_k r (cos φ_k, sin φ_k)
    to m·(Y_y, Y_z) and x_k·u_k to (F, E). With the planes at x = ∓c, the conditions
    Y = 0 and E = F = 0 give u2 = -(S + Q/c)/2 and u1 = -(S - Q/c)/2.
    """
    bare = {**values, "mass1_g": 0.0, "mass2_g": 0.0}
    mass, g, e, f = unbalance(bare)
    s = mass * np.array([g[1], g[2]])
    q = np.array([f, e])
    u1 = -(s - q / PLANE_X) / 2.0
    u2 = -(s + q / PLANE_X) / 2.0
    out = {}
    for k, u in (("1", u1), ("2", u2)):
        out[f"mass{k}_g"] = float(np.linalg.norm(u) / CORRECTION_RADIUS * 1000.0)
        out[f"angle{k}_deg"] = float(math.degrees(math.atan2(u[1], u[0])))
    return out


# -- scene readouts -----------------------------------------------------------------------
def _rotor_id(s: Snapshot) -> int:
    return s.body_id("rotor")


def _bearings(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """Forces of the frame on the rotor at A and B: split once a snapshot (both arrows
    and the readouts share it)."""
    cached = s.cache.get("rotor_bearings")
    if cached is None:
        cached = s.cache["rotor_bearings"] = bearing_split(*s.support)
    return cached


def _products(s: Snapshot) -> float:
    b = _rotor_id(s)
    rot = s.data.ximat[b].reshape(3, 3)
    i_g = rot @ np.diag(s.model.body_inertia[b]) @ rot.T
    i_o = huygens(i_g, float(s.model.body_mass[b]), -s.data.xipos[b])
    _, _, _, _, e, f = coefficients(i_o)
    return math.hypot(e, f)


def _static(s: Snapshot) -> float:
    b = _rotor_id(s)
    g = s.data.subtree_com[b]
    return float(s.model.body_subtreemass[b]) * math.hypot(g[1], g[2])


def _perp(v: np.ndarray) -> float:
    return float(np.linalg.norm(v - np.dot(v, AXIS) * AXIS))


READOUTS = (
    SceneReadout(
        "omega",
        "rad/s",
        "Rotation speed of the rotor.",
        lambda s: s.joint_qvel("spin"),
        label="Vitesse de rotation mesurée ω",
        hint="Vitesse de rotation du rotor par rapport au bâti.",
    ),
    SceneReadout(
        "bearing_A",
        "N",
        "Force of the frame on the rotor at bearing A, across the axis.",
        lambda s: float(np.linalg.norm(_bearings(s)[0])),
        label="Effort du palier A",
        hint="Norme de l'effort du bâti sur le rotor au palier A, perpendiculaire à l'axe.",
    ),
    SceneReadout(
        "bearing_B",
        "N",
        "Force of the frame on the rotor at bearing B, across the axis.",
        lambda s: float(np.linalg.norm(_bearings(s)[1])),
        label="Effort du palier B",
        hint="Norme de l'effort du bâti sur le rotor au palier B, perpendiculaire à l'axe.",
    ),
    SceneReadout(
        "bearing_A_ref",
        "N",
        "Course value of bearing_A at the measured speed (m, E, F and ω²).",
        lambda s: _bearing_ref(s, 0),
        label="Effort du palier A selon le cours",
        hint="Ce que donne le cours (7.2) pour l'effort du palier A à la vitesse mesurée : "
        "proportionnel à ω².",
    ),
    SceneReadout(
        "bearing_B_ref",
        "N",
        "Course value of bearing_B at the measured speed.",
        lambda s: _bearing_ref(s, 1),
        label="Effort du palier B selon le cours",
        hint="Ce que donne le cours (7.2) pour l'effort du palier B à la vitesse mesurée.",
    ),
    SceneReadout(
        "static_unbalance",
        "kg·m",
        "m × distance of G to the axis.",
        _static,
        label="Balourd statique m·Y",
        hint="Masse du rotor multipliée par la distance Y de son centre de gravité G à "
        "l'axe : nul quand le rotor est équilibré statiquement.",
    ),
    SceneReadout(
        "products_EF",
        "kg·m²",
        "√(E²+F²): products of inertia of the axis column at O.",
        _products,
        label="Produits d'inertie √(E²+F²)",
        hint="Produits d'inertie E et F de la colonne de l'axe x dans la matrice d'inertie "
        "en O : nuls, avec Y = 0, quand le rotor est équilibré dynamiquement.",
    ),
    SceneReadout(
        "F_rot",
        "N",
        "Rotating resultant of the frame's action on the rotor.",
        lambda s: _perp(s.support[0]),
        label="Résultante tournante Fᵣₒₜ",
        hint="Résultante de l'action du bâti sur le rotor, qui tourne avec lui : "
        "m·ω²·Y d'après le cours.",
    ),
    SceneReadout(
        "M_rot",
        "N·m",
        "Rotating moment at O of the frame's action on the rotor.",
        lambda s: _perp(s.support[1]),
        label="Moment tournant en O Mᵣₒₜ",
        hint="Moment en O de l'action du bâti sur le rotor, qui tourne avec lui : "
        "ω²·√(E²+F²) d'après le cours.",
    ),
)

ARROWS = (
    Arrow(
        "bearing_A",
        "Palier A",
        (40, 110, 230),
        lambda s: (np.array([-BEARING_X, 0.0, 0.0]), _bearings(s)[0]),
        scale=4e-3,
        unit="N",
        point="A",
        hint="Effort du bâti sur le rotor au palier A (bleu).",
    ),
    Arrow(
        "bearing_B",
        "Palier B",
        (230, 80, 40),
        lambda s: (np.array([BEARING_X, 0.0, 0.0]), _bearings(s)[1]),
        scale=4e-3,
        unit="N",
        point="B",
        hint="Effort du bâti sur le rotor au palier B (orange).",
    ),
)

SCENE = Scene(
    name="rotor",
    overlay={"omega": "ω", "bearing_A": "Palier A", "bearing_B": "Palier B"},
    title="Rotor déséquilibré à équilibrer",  # one line in a projected panel
    summary=(
        "A rotor on two bearings turns at constant speed. A defect mass and a skewed disk "
        "make the frame feel rotating forces; two correction masses cancel them."
    ),
    mjcf="rotor.xml",
    params=PARAMS,
    effects=Effects(gravity=False, contacts=False, actuation=True),
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    initial_state=initial_state,
    reference=reference,
    # A uniform rotation is integrated exactly by every integrator (sandbox bench: errors
    # ~1e-14 at every timestep), so the default is the cheapest run on the Pareto front;
    # implicitfast also keeps the speed servo stable through slider jumps.
    integrator="implicitfast",
    timestep=1e-2,
    plots=("bearing_A", "bearing_B"),
    xy_presets=(
        XYPreset(
            "Efforts des paliers selon ω, au démarrage",
            "omega",
            ("bearing_A", "bearing_B"),
            values={"ramp_s": 2.0, "speed_rpm": 6000.0},
            hint="Le rotor part du repos et monte à 6000 tr/min : les efforts des paliers "
            "suivent la parabole du cours en ω² (tirets).",
        ),
        XYPreset(
            "Efforts des paliers au cours du temps",
            "time",
            ("bearing_A", "bearing_B"),
            hint="À vitesse constante, les efforts tournent avec le rotor mais gardent leur "
            "intensité : celle du cours (tirets).",
        ),
    ),
    study_presets=(
        StudyPreset(
            "Effort du palier A selon la vitesse (0 à 6000 tr/min)",
            ("speed_rpm", 0.0, 6000.0, 13),
            "bearing_A",
            duration=0.1,
            hint="Chaque point est une simulation à vitesse constante : l'effort croît "
            "comme ω² (cours 7.2).",
        ),
    ),
    arrows=ARROWS,
    body_frame="rotor",
    sections="2–3, 5, 6, 7.2",
    extra={
        "balancing_solution": balancing_solution,
        "solid_names": {"rotor": "1 (rotor)"},
        "markers": {"defect": "Défaut", "correction1": "m₁", "correction2": "m₂"},
    },
    # Round-off: at 1500 rpm {D} and the frame's action keep 6e-12 N and 2e-12 N·m on
    # axes where the course has 0 (1e-13 of the 54 N peak), 1e-10 N at 6000 rpm.
    zero={
        "N": 1e-9,
        "N·m": 1e-10,
        "W": 1e-9,
        "J": 1e-12,
        "kg·m/s": 1e-12,
        "kg·m²/s": 1e-12,
        "kg·m": 1e-13,
        "kg·m²": 1e-14,
    },
    # Key quantity: the bearing force at A against 7.2's closed form; invariant: T, constant
    # at constant speed (the servo holds ω, so a drift of T means the motion is wrong).
    accuracy=Accuracy(
        key="bearing_A",
        readouts=("bearing_A", "T"),
        duration=0.5,
        error=worst_relative_error("bearing_A", reference),
        invariant="T (constant speed)",
        drift=relative_drift("T"),
        values={"speed_rpm": 3000.0},
        timesteps=(1e-4, 3e-4, 1e-3, 3e-3, 1e-2),
    ),
)
