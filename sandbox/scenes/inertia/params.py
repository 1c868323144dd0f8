"""Parameters of the inertia scene: the solids of the course, the point and basis of the matrix,
the launch of the torque-free spin.

The solids are the square-based block of 5.4, the shapes of 5.6, the rod and the
three-cylinder crankshaft of 5.7; the table :data:`PARAMS` is what the page and the CLI
offer, one :class:`~sandbox.physics.spec.Param` per parameter.
"""

from __future__ import annotations

import math

from sandbox.physics.spec import Param, Values

RPM = 2 * math.pi / 60
SOLIDS = (
    "Pavé à base carrée (5.4)",
    "Pavé de côtés a, b, c (5.6.1)",
    "Cylindre plein (5.6.2)",
    "Sphère pleine (5.6.3)",
    "Bielle assimilée à une tige (5.7)",
    "Vilebrequin en trois cylindres (5.7)",
    "Cylindre creux (5.6.2)",
)
SQUARE_BLOCK, BLOCK, CYLINDER, SPHERE, ROD, CRANKSHAFT, HOLLOW = range(7)
POINTS = ("O, origine du paramétrage", "G, centre de gravité", "Point P de coordonnées x, y, z")
AXES = (
    "Axe principal 1, plus petit moment I₁",
    "Axe principal 2, moment intermédiaire I₂",
    "Axe principal 3, plus grand moment I₃",
)
ROD_SLENDERNESS = 100.0
"""The rod is simulated as a cylinder of radius L / 100 (MuJoCo needs a volume): its
moments differ from the thin rod's m L²/3 by 3/(4·100²) = 7.5e-5, and its own-axis moment
m r²/2 is 1.5e-4 of m L²/3."""
TUBE_SIDES = 256
"""The hollow cylinder is simulated as a mesh (MuJoCo has no tube primitive) whose
circles are 256-gons: its mass is set, and its moments come within 1e-4 of the circle's."""
CRANK_RADIUS = 0.015
"""OA of the micro-compressor's crank [m] (the compressor scene's R)."""
CRANKSHAFT_PARTS = (
    # (name, radius [m], length [m], centre in R_S [m], own axis in R_S)
    ("journal", 0.008, 0.030, (0.0, 0.0, -0.020), (0.0, 0.0, 1.0)),
    ("web", 0.005, CRANK_RADIUS, (CRANK_RADIUS / 2, 0.0, 0.0), (1.0, 0.0, 0.0)),
    ("pin", 0.005, 0.012, (CRANK_RADIUS, 0.0, 0.011), (0.0, 0.0, 1.0)),
)
"""The 5.7 crankshaft as three cylinders of one material, touching without overlapping: the journal
on the axis (O, z) below the web, the web along x from O to A, the crank pin along z at A.
O is on the axis in the web's mid-plane: (O, x, z) is a plane of symmetry, so D = F = 0,
and the pin, above the plane z = 0 and off the axis, makes E = ∫ x·z dm positive (the
compressor's E₁)."""

SOLID, SIZES, POINT, SPIN = "Solide", "Dimensions", "Point et base", "Rotation libre"
PARAMS = (
    Param(
        "solid",
        "",
        1.0,
        0.0,
        float(len(SOLIDS) - 1),
        (
            "Solid: 0 square-based block (5.4), 1 block a, b, c (5.6.1), 2 solid cylinder, "
            "3 sphere, 4 rod (5.7), 5 three-cylinder crankshaft (5.7), 6 hollow cylinder."
        ),
        step=1.0,
        label="Solide étudié",
        hint=(
            "Solide dont on lit la matrice d'inertie, choisi parmi les exemples des paragraphes "
            "5.4, 5.6 et 5.7 du cours."
        ),
        group=SOLID,
        choices=SOLIDS,
    ),
    Param(
        "mass",
        "kg",
        1.0,
        0.01,
        100.0,
        "Mass m of the solid (uniform density).",
        step=0.01,
        label="Masse m",
        hint="Masse du solide, de masse volumique uniforme.",
        group=SOLID,
    ),
    Param(
        "a",
        "m",
        0.1,
        0.005,
        1.0,
        (
            "First dimension: side a of the block's base or edge a, radius R of the cylinder "
            "and the sphere."
        ),
        step=0.005,
        label="Dimension a",
        hint="Côté a de la base du pavé ou arête selon x, rayon R du cylindre et de la sphère.",
        group=SIZES,
    ),
    Param(
        "b",
        "m",
        0.2,
        0.005,
        1.0,
        (
            "Second dimension: height b of the 5.4 block or edge b, height h of the cylinder, "
            "length L of the rod."
        ),
        step=0.005,
        label="Dimension b",
        hint=(
            "Hauteur b du pavé à base carrée ou arête selon y, hauteur h du cylindre, longueur L"
            " de la bielle."
        ),
        group=SIZES,
    ),
    Param(
        "c",
        "m",
        0.3,
        0.005,
        1.0,
        "Third dimension: edge c along z of the 5.6.1 block.",
        step=0.005,
        label="Dimension c",
        hint=(
            "Arête c selon z du pavé du paragraphe 5.6.1 ; les autres solides ne s'en servent pas."
        ),
        group=SIZES,
        advanced=True,
    ),
    Param(
        "hole_ratio",
        "",
        0.6,
        0.05,
        0.95,
        "Inner radius of the hollow cylinder over its outer radius a.",
        step=0.01,
        label="Rapport des rayons du cylindre creux r/R",
        hint=(
            "Rayon intérieur r du cylindre creux divisé par son rayon extérieur R = a ; les "
            "autres solides ne s'en servent pas."
        ),
        group=SIZES,
        advanced=True,
    ),
    Param(
        "point",
        "",
        0.0,
        0.0,
        2.0,
        (
            "Point of the matrix: 0 the origin O of the course's parametrisation, 1 the centre of "
            "mass G, 2 the point P (point_x, point_y, point_z)."
        ),
        live=True,
        step=1.0,
        label="Point de calcul de la matrice",
        hint=(
            "Point où la matrice est calculée : l'origine O du paramétrage du cours (A pour la "
            "bielle), le centre de gravité G ou un point P."
        ),
        group=POINT,
        choices=POINTS,
    ),
    Param(
        "point_x",
        "m",
        0.0,
        -1.0,
        1.0,
        "x of the point P in the solid's frame.",
        live=True,
        step=0.005,
        label="Abscisse x du point P",
        hint="Coordonnée x du point P dans le repère du solide, depuis son origine O.",
        group=POINT,
        advanced=True,
    ),
    Param(
        "point_y",
        "m",
        0.0,
        -1.0,
        1.0,
        "y of the point P in the solid's frame.",
        live=True,
        step=0.005,
        label="Ordonnée y du point P",
        hint="Coordonnée y du point P dans le repère du solide, depuis son origine O.",
        group=POINT,
        advanced=True,
    ),
    Param(
        "point_z",
        "m",
        0.0,
        -1.0,
        1.0,
        "z of the point P in the solid's frame.",
        live=True,
        step=0.005,
        label="Cote z du point P",
        hint="Coordonnée z du point P dans le repère du solide, depuis son origine O.",
        group=POINT,
        advanced=True,
    ),
    Param(
        "basis_z_deg",
        "deg",
        0.0,
        -180.0,
        180.0,
        "Basis of the matrix: first rotation of the solid's basis, about z.",
        live=True,
        step=1.0,
        label="Rotation de la base autour de z ψ",
        hint=(
            "Première rotation qui amène la base du solide sur la base de calcul, autour de son "
            "axe z."
        ),
        group=POINT,
    ),
    Param(
        "basis_y_deg",
        "deg",
        0.0,
        -90.0,
        90.0,
        "Basis of the matrix: second rotation, about the new y.",
        live=True,
        step=1.0,
        label="Rotation de la base autour de y θ",
        hint="Deuxième rotation de la base de calcul, autour du nouvel axe y.",
        group=POINT,
    ),
    Param(
        "basis_x_deg",
        "deg",
        0.0,
        -180.0,
        180.0,
        "Basis of the matrix: third rotation, about the new x.",
        live=True,
        step=1.0,
        label="Rotation de la base autour de x φ",
        hint="Troisième rotation de la base de calcul, autour du nouvel axe x.",
        group=POINT,
    ),
    Param(
        "spin_axis",
        "",
        1.0,
        0.0,
        2.0,
        (
            "Principal axis at G the solid is launched about: 0 the smallest moment, 1 the "
            "intermediate, 2 the largest."
        ),
        live=True,
        step=1.0,
        label="Axe principal de lancement",
        hint=(
            "Axe principal d'inertie en G autour duquel le solide est lancé, repéré par son "
            "moment principal."
        ),
        group=SPIN,
        choices=AXES,
    ),
    Param(
        "spin_rpm",
        "rpm",
        120.0,
        0.0,
        3000.0,
        (
            "Rotation speed given at launch (at reset and whenever a spin parameter or the solid "
            "changes)."
        ),
        live=True,
        step=10.0,
        label="Vitesse de lancement ω₀",
        hint=(
            "Vitesse de rotation donnée au solide au lancement, puis il tourne librement sans "
            "aucun couple."
        ),
        group=SPIN,
    ),
    Param(
        "perturbation_deg",
        "deg",
        1.0,
        0.0,
        30.0,
        "Angle between the launch rotation and the principal axis, towards the next axis.",
        live=True,
        step=0.1,
        label="Écart de lancement à l'axe ε",
        hint=(
            "Petit angle entre la rotation de lancement et l'axe principal choisi, vers l'axe "
            "principal suivant."
        ),
        group=SPIN,
    ),
)

SHAPE = ("solid", "mass", "a", "b", "c", "hole_ratio")
"""Parameters that shape the solid (a change rebuilds the model)."""
LAUNCH = (*SHAPE, "spin_axis", "spin_rpm", "perturbation_deg")
"""Parameters of a launch, stored in ``userdata`` (a change relaunches the spin)."""


def choice_index(values: Values, name: str) -> int:
    """Index chosen by the choice parameter ``name`` (its value rounded to an integer)."""
    return int(round(values[name]))
