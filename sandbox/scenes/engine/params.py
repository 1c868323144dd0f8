"""Parameter table of the inline engine (:mod:`sandbox.scenes.engine`): the crankshaft's
speed, the number of cylinders, the slider-cranks' lengths and masses, the counterweights,
the Lanchester shafts and the motor's inertia."""

from __future__ import annotations

from typing import Any

from sandbox.physics.spec import Param
from sandbox.scenes import bearings

MAX_CYLINDERS = 4


def _p(name: str, unit: str, default: float, lo: float, hi: float, doc: str, **kw: Any) -> Param:
    return Param(name, unit, default, lo, hi, doc, **kw)


DRIVE, GEOMETRY, MASSES, BALANCE = "Entraînement", "Géométrie", "Masses", "Équilibrage"

PARAMS = (
    _p("speed_rpm", "rpm", 3000.0, 0.0, 17000.0, "Crankshaft speed held by the motor.", live=True, step=50.0, label="Vitesse du vilebrequin ω", hint="Vitesse de rotation que le moteur impose au vilebrequin.", group=DRIVE),
    _p("cylinders", "", 4.0, 1.0, 4.0, "Number of cylinders in line: 1, 2 (throws 0-180) or 4 (flat crank 0-180-180-0).", step=1.0, label="Nombre de cylindres n", hint="Un, deux ou quatre cylindres en ligne, manetons à 0-180 ou 0-180-180-0 degrés.", group=GEOMETRY),
    _p("R", "m", 0.015, 0.005, 0.05, "Crank radius OA of every throw.", step=0.0005, label="Rayon de manivelle R", hint="Distance OA entre l'axe du vilebrequin et chaque maneton.", group=GEOMETRY),
    _p("L", "m", 0.055, 0.0055, 0.25, "Rod length AB (must exceed R).", step=0.0005, label="Longueur de bielle L", hint="Longueur AB de chaque bielle, qui doit dépasser R.", group=GEOMETRY),
    _p("spacing", "m", 0.06, 0.02, 0.3, "Distance a between neighbouring cylinders along the crankshaft.", step=0.005, label="Entraxe des cylindres a", hint="Distance entre deux cylindres voisins le long de l'axe du vilebrequin.", group=GEOMETRY),
    _p("m1", "kg", 0.2, 0.0, 2.0, "Crank mass of one throw (its web and pin).", step=0.005, label="Masse d'un bras de manivelle m₁", hint="Masse du bras et du maneton d'un cylindre, sans le contrepoids.", group=MASSES, advanced=True),
    _p("d1", "m", 0.005, 0.0, 0.05, "Distance from the crankshaft's axis to the centre of mass of one throw.", step=0.0005, label="Position de G₁ d₁", hint="Distance du centre de gravité d'un bras de manivelle à l'axe du vilebrequin.", group=MASSES, advanced=True),
    _p("m2", "kg", 0.06, 0.001, 2.0, "Mass of one rod.", step=0.005, label="Masse d'une bielle m₂", hint="Masse de chaque bielle.", group=MASSES),
    _p("d2", "m", 0.02, 0.0, 0.25, "AG2: rod centre of mass from the crank pin A.", step=0.0005, label="Position de G₂ d₂", hint="Distance AG₂ du centre de gravité de la bielle depuis le maneton A.", group=MASSES, advanced=True),
    _p("C2", "kg·m²", 6.5e-5, 1e-7, 5e-3, "Rod inertia about (A, z0).", step=1e-7, label="Moment d'inertie C₂", hint="Moment d'inertie d'une bielle autour de l'axe (A, z₀), parallèle au vilebrequin.", group=MASSES, advanced=True, log=True),
    _p("m3", "kg", 0.08, 0.001, 2.0, "Mass of one piston.", step=0.005, label="Masse d'un piston m₃", hint="Masse de chaque piston, en translation le long de y₀.", group=MASSES),
    _p("counterweight_rot", "", 1.0, 0.0, 1.0, "Counterweight per throw, fraction of the rotating mass balanced.", step=0.05, label="Part équilibrée des masses tournantes kᵣ", hint="Fraction de la masse tournante de chaque manivelle que son contrepoids compense.", group=BALANCE),
    _p("counterweight_rec", "", 0.0, 0.0, 1.0, "Counterweight per throw, fraction of the reciprocating mass balanced.", step=0.05, label="Part équilibrée des masses alternatives kₐ", hint="Fraction de la masse alternative de chaque cylindre que son contrepoids compense, au prix d'un tamis.", group=BALANCE),
    _p("lanchester", "", 0.0, 0.0, 1.0, "0: none; 1: two balance shafts at twice the crank speed (Lanchester).", step=1.0, label="Arbres d'équilibrage de Lanchester", hint="Deux arbres à balourd tournant en sens contraires à deux fois la vitesse du vilebrequin.", group=BALANCE, choices=("Sans", "Avec")),
    _p("motor_inertia", "kg·m²", 0.02, 0.0, 0.2, "Inertia of the motor's rotor, turning with the crankshaft (a joint armature).", step=0.001, label="Inertie du rotor du moteur J", hint="Moment d'inertie du rotor du moteur, qui tourne avec le vilebrequin.", group=DRIVE, advanced=True, hypothesis="Rotor du moteur d'inertie J = {}, tournant avec le vilebrequin : compté dans T et dans Pₑₓₜ ; le couple de l'actionneur vaut Cₘₒₜ + J·θ''"),
    # Two main bearings at the crankshaft's ends around its 6 mm shaft, 12 mm long.
    *bearings.params(0.006, 0.012),
    bearings.friction_param(),
)  # fmt: skip

DEFAULTS = {p.name: p.default for p in PARAMS}
