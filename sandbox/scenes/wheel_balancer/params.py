"""Parameters of the wheel-balancing machine: its dimensions, the hidden wheels of
:data:`MYSTERIES`, the parameter table, and what the parameters mean for the physics (the
imposed speed, rigid or soft supports, the effective unbalance of a mystery wheel).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from sandbox.physics.spec import Effects, Param, Values
from sandbox.scenes import bearings

RPM = 2.0 * math.pi / 60.0
AXIS = np.array([1.0, 0.0, 0.0])

# Geometry [m], densities [kg/m³], masses [kg]: shared by the model edits and the closed forms.
STEEL, ALUMINIUM = 7800.0, 2700.0
X_A, X_B = -0.30, -0.10  # machine bearings: A inside, B next to the wheel
X_M = -0.20  # centre of the housing (the soft supports' centre M)
X_INNER, X_OUTER = 0.015, 0.185  # rim planes of the clips
CLIP_RADIUS = 0.19
X_WHEEL = 0.10  # mid-plane of the rim and tyre
DEFECT_RADIUS = 0.31  # heavy spot on the tread
MASS_SPHERE_RADIUS = 0.008
SHAFT_RADIUS, SHAFT_FROM, SHAFT_TO = 0.02, -0.36, 0.26
FLANGE_RADIUS, FLANGE_THICKNESS, FLANGE_X = 0.07, 0.02, -0.01
DISC_RADIUS, DISC_THICKNESS, DISC_X = 0.18, 0.012, 0.006
RIM_MASS, RIM_OUTER, RIM_INNER, RIM_WIDTH = 4.0, 0.19, 0.18, 0.176
TYRE_MASS, TYRE_OUTER, TYRE_INNER, TYRE_WIDTH = 8.0, 0.31, 0.19, 0.15
HOUSING_RADIUS, HOUSING_LENGTH = 0.05, 0.26

# Lab bench (figure 40): each bearing's housing on springs of K [N/m] and dampers of
# C [N·s/m] across the axis, the bearings at ±D from M: translation k_t = 2K, c_t = 2C;
# tilt k_r = 2K D², c_r = 2C D². Critical speeds: :func:`supports_model`.
SPRING, DAMPER, HALF_SPAN = 1.0e5, 600.0, 0.10

MYSTERIES: tuple[Mapping[str, float], ...] = (
    {"defect_mass_g": 42.0, "defect_angle_deg": 113.0, "skew_deg": -0.35, "skew_angle_deg": 20.0},
    {"defect_mass_g": 18.0, "defect_angle_deg": 251.0, "skew_deg": 0.6, "skew_angle_deg": 305.0},
    {"defect_mass_g": 65.0, "defect_angle_deg": 8.0, "skew_deg": 0.15, "skew_angle_deg": 160.0},
)
"""Hidden unbalances of the "Roue mystère" choices 1, 2, 3 (never shown by the page)."""
HIDDEN = ("defect_mass_g", "defect_angle_deg", "skew_deg", "skew_angle_deg")

DRIVE, WHEEL, CLIPS, TRIAL = "Entraînement", "Roue à équilibrer", "Masselottes", "Masse d'essai"
PARAMS = (
    Param(
        "speed_rpm", "rpm", 200.0, 0.0, 2000.0,
        "Rotation speed the machine imposes on the wheel.",
        live=True, step=10.0, label="Vitesse de rotation ω",
        hint="Vitesse à laquelle le moteur de l'équilibreuse fait tourner la roue.",
        group=DRIVE,
    ),
    Param(
        "supports", "", 0.0, 0.0, 1.0,
        "0: rigid bearings (the garage's machine); 1: bearings on springs (the lab bench).",
        step=1.0, label="Montage des paliers",
        hint="Paliers rigides de l'équilibreuse du garagiste, ou paliers sur lames souples "
        "du banc du laboratoire, qui vibrent.",
        group=DRIVE, choices=("Paliers rigides", "Paliers souples"),
    ),
    Param(
        "mystery", "", 0.0, 0.0, 3.0,
        "0: the unbalance set below; 1-3: a wheel whose unbalance the page does not show.",
        step=1.0, label="Roue",
        hint="Réglage libre du balourd avec les curseurs ci-dessous, ou roue mystère dont "
        "seule la machine connaît le balourd.",
        group=WHEEL,
        choices=("Réglage libre", "Roue mystère 1", "Roue mystère 2", "Roue mystère 3"),
    ),
    Param(
        "defect_mass_g", "g", 30.0, 0.0, 100.0,
        "Heavy spot on the tread, 310 mm from the axis in the wheel's mid-plane.",
        step=0.5, label="Point lourd du pneu mₚ",
        hint="Surépaisseur du pneu sur la bande de roulement, à 310 mm de l'axe dans le "
        "plan médian de la roue : elle écarte G de l'axe.",
        group=WHEEL,
    ),
    Param(
        "defect_angle_deg", "deg", 60.0, 0.0, 360.0,
        "Angle of the heavy spot from the valve (y1) towards z1.",
        step=1.0, label="Angle du point lourd φₚ",
        hint="Position du point lourd autour de l'axe, comptée depuis la valve (y₁) vers z₁.",
        group=WHEEL,
    ),
    Param(
        "skew_deg", "deg", 0.25, -1.0, 1.0,
        "Tilt of the tyre's axis from the rotation axis (couple unbalance).",
        step=0.01, label="Voile du pneu β",
        hint="Angle entre l'axe du pneu, monté de travers sur la jante, et l'axe de "
        "rotation : il crée les produits d'inertie E et F.",
        group=WHEEL,
    ),
    Param(
        "skew_angle_deg", "deg", 200.0, 0.0, 360.0,
        "Direction, from the valve towards z1, towards which the tyre's axis leans.",
        step=1.0, label="Direction du voile ψ",
        hint="Direction vers laquelle penche l'axe du pneu, comptée depuis la valve vers z₁.",
        group=WHEEL,
    ),
    Param(
        "mass_inner_g", "g", 0.0, 0.0, 150.0,
        "Clip-on mass on the inner rim edge (x = 15 mm), 190 mm from the axis.",
        step=0.1, label="Masselotte intérieure m₁",
        hint="Masselotte sertie sur le bord intérieur de la jante (plan 1, côté machine), "
        "à 190 mm de l'axe.",
        group=CLIPS,
    ),
    Param(
        "angle_inner_deg", "deg", 0.0, 0.0, 360.0,
        "Angle of the inner clip from the valve (y1) towards z1.",
        step=0.1, label="Angle de la masselotte intérieure α₁",
        hint="Position de la masselotte intérieure autour de l'axe, comptée depuis la valve.",
        group=CLIPS,
    ),
    Param(
        "mass_outer_g", "g", 0.0, 0.0, 150.0,
        "Clip-on mass on the outer rim edge (x = 185 mm), 190 mm from the axis.",
        step=0.1, label="Masselotte extérieure m₂",
        hint="Masselotte sertie sur le bord extérieur de la jante (plan 2, côté visible), "
        "à 190 mm de l'axe.",
        group=CLIPS,
    ),
    Param(
        "angle_outer_deg", "deg", 0.0, 0.0, 360.0,
        "Angle of the outer clip from the valve (y1) towards z1.",
        step=0.1, label="Angle de la masselotte extérieure α₂",
        hint="Position de la masselotte extérieure autour de l'axe, comptée depuis la valve.",
        group=CLIPS,
    ),
    Param(
        "trial_g", "g", 20.0, 1.0, 100.0,
        "Trial mass of the influence-coefficient method, at the valve's angle.",
        step=1.0, label="Masse d'essai mₑ",
        hint="Masse connue posée à l'angle de la valve pour mesurer l'effet d'un balourd "
        "ajouté sur les vibrations (coefficients d'influence).",
        group=TRIAL,
    ),
    Param(
        "trial_plane", "", 0.0, 0.0, 2.0,
        "Where the trial mass is: 0 nowhere, 1 inner rim plane, 2 outer rim plane.",
        step=1.0, label="Position de la masse d'essai",
        hint="Plan de la jante qui reçoit la masse d'essai, ou aucun pour la mesure de "
        "référence.",
        group=TRIAL, choices=("Aucune", "Plan intérieur", "Plan extérieur"),
    ),
    # Bushes around the 20 mm shaft, 20 mm long (2RL = 8 cm²).
    *bearings.params(SHAFT_RADIUS, 0.02),
    bearings.friction_param(),
)  # fmt: skip


def omega(values: Values) -> float:
    """Imposed speed [rad/s]."""
    return values["speed_rpm"] * RPM


def effects(values: Values) -> Effects:
    """Rigid bearings: a perfect pivot, nothing else; the soft bench adds the springs and
    dampers of its blades."""
    return Effects(
        gravity=False,
        contacts=False,
        actuation=True,
        springs=soft(values),
        joint_damping=soft(values),
        joint_friction=bearings.friction_on(values),
    )


def soft(values: Values) -> bool:
    """True for the lab bench's bearings on springs."""
    return int(round(values["supports"])) == 1


def effective(values: Values) -> dict[str, float]:
    """The values the physics uses: a mystery wheel's hidden unbalance replaces the four
    unbalance sliders (which keep showing the free setting)."""
    out = dict(values)
    k = int(round(values.get("mystery", 0.0)))
    if k > 0:
        out.update(MYSTERIES[k - 1])
    return out
