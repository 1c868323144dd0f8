"""Parameter table of the micro-compressor (:mod:`sandbox.scenes.compressor`): the crank
speed, the slider-crank's lengths, centres of gravity, masses and inertias, the
counterweight and the motor's ramp."""

from __future__ import annotations

import math
from typing import Any

from sandbox.physics.spec import Param
from sandbox.scenes import bearings

RPM = 2 * math.pi / 60


def _p(name: str, unit: str, default: float, lo: float, hi: float, doc: str, **kw: Any) -> Param:
    return Param(name, unit, default, lo, hi, doc, **kw)


DRIVE, GEOMETRY, CENTRES, MASSES, BALANCE, INERTIAS = (
    "Entraînement", "Géométrie", "Centres de gravité", "Masses", "Contrepoids", "Inerties",
)  # fmt: skip

# Inertias: from about a hundredth of the course's values (A1 = 1.2e-4, B2 = 2e-6 kg·m²) up
# to what the heaviest crank the sliders allow needs (m1 d1² reaches 1.25e-2 kg·m²); they
# span decades, so the page types them as numbers (``log``): no slider reaches 2e-4 in 2e-2.
PARAMS = (
    _p("speed_rpm", "rpm", 3000.0, 0.0, 17000.0, "Crank speed held by the motor.", live=True, step=50.0, label="Vitesse du vilebrequin ω", hint="Vitesse de rotation que le moteur impose au vilebrequin 1.", group=DRIVE),
    _p("R", "m", 0.015, 0.005, 0.05, "Crank radius OA.", step=0.0005, label="Rayon de manivelle R", hint="Longueur OA de la manivelle du vilebrequin 1.", group=GEOMETRY),
    _p("L", "m", 0.055, 0.0055, 0.25, "Rod length AB (must exceed R).", step=0.0005, label="Longueur de bielle L", hint="Longueur AB de la bielle 2, qui doit dépasser R.", group=GEOMETRY),
    _p("d1", "m", 0.003, -0.03, 0.05, "OG1: crank centre of mass along x1.", step=0.0005, label="Position de G₁ d₁", hint="Distance OG₁ du centre de gravité du vilebrequin, comptée le long de x₁.", group=CENTRES, advanced=True),
    _p("d2", "m", 0.02, 0.0, 0.25, "AG2: rod centre of mass from the pin A along y2.", step=0.0005, label="Position de G₂ d₂", hint="Distance AG₂ du centre de gravité de la bielle depuis le maneton A, le long de y₂.", group=CENTRES, advanced=True),
    _p("d3", "m", 0.005, -0.05, 0.05, "BG3: piston centre of mass from B along y0.", step=0.0005, label="Position de G₃ d₃", hint="Distance BG₃ du centre de gravité du piston depuis l'axe B, le long de y₀.", group=CENTRES, advanced=True),
    _p("m1", "kg", 0.35, 0.01, 5.0, "Mass of the crank.", step=0.01, label="Masse du vilebrequin m₁", hint="Masse du vilebrequin 1, sans le contrepoids.", group=MASSES),
    _p("m2", "kg", 0.06, 0.001, 2.0, "Mass of the rod.", step=0.005, label="Masse de la bielle m₂", hint="Masse de la bielle 2.", group=MASSES),
    _p("m3", "kg", 0.08, 0.001, 2.0, "Mass of the piston.", step=0.005, label="Masse du piston m₃", hint="Masse du piston 3, en translation le long de y₀.", group=MASSES),
    _p("A1", "kg·m²", 1.2e-4, 1e-6, 2e-2, "Crank inertia about (O, x1).", step=1e-6, label="Moment d'inertie A₁", hint="Moment d'inertie du vilebrequin autour de l'axe (O, x₁).", group=INERTIAS, advanced=True, log=True),
    _p("B1", "kg·m²", 2.0e-4, 1e-6, 2e-2, "Crank inertia about (O, y1).", step=1e-6, label="Moment d'inertie B₁", hint="Moment d'inertie du vilebrequin autour de l'axe (O, y₁).", group=INERTIAS, advanced=True, log=True),
    _p("C1", "kg·m²", 2.2e-4, 1e-6, 2e-2, "Crank inertia about (O, z0), the rotation axis.", step=1e-6, label="Moment d'inertie C₁", hint="Moment d'inertie du vilebrequin autour de son axe de rotation (O, z₀).", group=INERTIAS, advanced=True, log=True),
    _p("E1", "kg·m²", 1.0e-6, -1e-3, 1e-3, "Crank product of inertia E1 = ∫ x z dm at O.", step=1e-7, label="Produit d'inertie E₁", hint="Produit d'inertie E₁ = ∫ x·z dm du vilebrequin en O, dans la base B₁.", group=INERTIAS, advanced=True, log=True),
    _p("A2", "kg·m²", 6.5e-5, 1e-7, 1e-1, "Rod inertia about (A, x2).", step=1e-7, label="Moment d'inertie A₂", hint="Moment d'inertie de la bielle autour de l'axe (A, x₂).", group=INERTIAS, advanced=True, log=True),
    _p("B2", "kg·m²", 2.0e-6, 1e-9, 1e-3, "Rod inertia about (A, y2), its own axis.", step=1e-8, label="Moment d'inertie B₂", hint="Moment d'inertie de la bielle autour de son propre axe (A, y₂).", group=INERTIAS, advanced=True, log=True),
    _p("C2", "kg·m²", 6.5e-5, 1e-7, 1e-1, "Rod inertia about (A, z0).", step=1e-7, label="Moment d'inertie C₂", hint="Moment d'inertie de la bielle autour de l'axe (A, z₀), parallèle à l'axe du vilebrequin.", group=INERTIAS, advanced=True, log=True),
    _p("counterweight_mass", "kg", 0.0, 0.0, 2.0, "Balancing mass on the crank, opposite A.", step=0.005, label="Masse du contrepoids", hint="Masse d'équilibrage fixée sur le vilebrequin, à l'opposé du maneton A (un balourd volontaire).", group=BALANCE),
    _p("counterweight_radius", "m", 0.015, 0.0, 0.06, "Distance of the balancing mass from O.", step=0.0005, label="Rayon du contrepoids", hint="Distance du contrepoids à l'axe de rotation (O, z₀).", group=BALANCE),
    _p("motor_inertia", "kg·m²", 0.02, 0.0, 0.2, "Inertia of the motor's rotor, turning with the crank (a joint armature).", step=0.001, label="Inertie du rotor du moteur J", hint="Moment d'inertie du rotor du moteur, qui tourne avec le vilebrequin.", group=INERTIAS, advanced=True, hypothesis="Rotor du moteur d'inertie J = {}, tournant avec le vilebrequin : compté dans T et dans Pₑₓₜ ; le couple de l'actionneur vaut Cₘₒₜ + J·θ''"),
    _p("ramp_s", "s", 0.0, 0.0, 5.0, "0: start at speed; > 0: start at rest, motor set point rising with this time constant.", step=0.05, label="Temps de montée en vitesse τ", hint="0 : le vilebrequin part à sa vitesse ; sinon il part du repos et la consigne du moteur monte avec cette constante de temps.", group=DRIVE),
    # The crank's bush at O around its 6 mm shaft, 24 mm long (2RL = 2,9 cm²).
    *bearings.params(0.006, 0.024, group=GEOMETRY),
    bearings.friction_param(group=DRIVE),
)  # fmt: skip


DEFAULTS = {p.name: p.default for p in PARAMS}
