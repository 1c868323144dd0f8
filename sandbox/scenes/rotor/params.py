"""Parameter table and fixed geometry of the unbalanced rotor (:mod:`sandbox.scenes.rotor`):
the imposed speed, the defects (mass, skewed disk), the two correction masses and the
start's ramp; the shapes' dimensions shared by the model edits and the closed form."""

from __future__ import annotations

import numpy as np

from sandbox.physics.spec import Param
from sandbox.scenes import bearings

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
    # Bronze bushes around the shaft (radius SHAFT_RADIUS), 10 mm long: 20 g of defect
    # gives 3,5 bar at 1500 rpm in A (hypothesis 2), 200 g passes 200 bar near 5500 rpm.
    *bearings.params(SHAFT_RADIUS, 0.01),
    bearings.friction_param(),
)
