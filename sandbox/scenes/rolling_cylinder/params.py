"""Parameter table of the rolling cylinder (:mod:`sandbox.scenes.rolling_cylinder`): the
cylinder (radius, length, mass, bore), the inclined plane (slope, friction, length), the
eccentric mass and the start (initial speed, race)."""

from __future__ import annotations

from sandbox.physics.spec import Param

CYLINDER, PLANE, ECCENTRIC, START = "Cylindre", "Plan incliné", "Masse excentrée", "Lancement"
PARAMS = (
    Param("R", "m", 0.1, 0.01, 0.5, "Outer radius of the cylinder.", step=0.005, label="Rayon du cylindre R", hint="Rayon extérieur du cylindre, celui qui roule sur le plan.", group=CYLINDER),
    Param("length", "m", 0.2, 0.01, 1.0, "Length of the cylinder along its axis.", step=0.01, label="Longueur du cylindre", hint="Longueur du cylindre le long de son axe, sans effet sur la descente.", group=CYLINDER, advanced=True),
    Param("mass", "kg", 1.0, 0.01, 100.0, "Mass of the cylinder (without the eccentric mass).", step=0.01, label="Masse du cylindre m", hint="Masse du cylindre seul, sans la masse excentrée.", group=CYLINDER),
    Param("inner_radius", "m", 0.0, 0.0, 0.499, "Inner radius: 0 for a solid cylinder, close to R for a thin tube.", step=0.005, label="Rayon intérieur r", hint="Rayon intérieur : 0 pour un cylindre plein, proche de R pour un tube mince.", group=CYLINDER),
    Param("slope_deg", "deg", 20.0, 0.0, 60.0, "Slope α of the plane.", step=0.5, label="Pente du plan α", hint="Angle α du plan incliné avec l'horizontale.", group=PLANE),
    Param("mu", "", 0.3, 0.0, 2.0, "Coulomb friction coefficient between cylinder and plane.", step=0.01, label="Coefficient de frottement μ", hint="Coefficient de frottement de Coulomb entre le cylindre et le plan.", group=PLANE),
    Param("eccentric_mass", "kg", 0.0, 0.0, 10.0, "Point mass fixed in the cylinder off its axis.", step=0.01, label="Masse excentrée", hint="Masse ponctuelle fixée dans le cylindre, hors de son axe (0 : pas de masse excentrée).", group=ECCENTRIC),
    Param("eccentric_radius", "m", 0.05, 0.0, 0.5, "Distance of the eccentric mass from the axis.", step=0.005, label="Excentricité e", hint="Distance de la masse excentrée à l'axe du cylindre.", group=ECCENTRIC),
    Param("v0", "m/s", 0.0, -10.0, 10.0, "Initial speed of the centre down the slope (rolling).", step=0.05, label="Vitesse initiale v₀", hint="Vitesse initiale du centre vers le bas de la pente, le cylindre roulant sans glisser.", group=START),
    Param("plane_length", "m", 12.0, 1.0, 200.0, "Length of the drawn plane (the default holds a 3 s run); on_plane turns 0 beyond it.", step=1.0, label="Longueur du plan", hint="Longueur du plan dessiné (3 s de descente par défaut) : au-delà, l'indicateur « Sur le plan » passe à 0.", group=PLANE, advanced=True),
    Param("race", "", 0.0, 0.0, 1.0, "1: a thin tube and a solid sphere (same R and mass) race the cylinder side by side.", step=1.0, label="Course contre un tube et une sphère", hint="Oui : un tube mince et une sphère pleine, de même rayon et de même masse, descendent à côté du cylindre.", group=START, choices=("Non", "Oui")),
)  # fmt: skip
