"""Parameter table of the robot axis (:mod:`sandbox.scenes.robot_axis`): the motor's
command (torque, speed, back-and-forth move, sinusoidal torque), the flexible arm, the
transmission and the inertias, with the constants of the servo, the rail and the step."""

from __future__ import annotations

import math
from typing import Any

from sandbox.physics.spec import Param

RPM = 2 * math.pi / 60
SERVO_TIME = 0.01
"""Time constant [s] of the speed servo on the rigid chain: K_v = J_eq / SERVO_TIME."""
POSITION_TIME = 0.1
"""Time constant [s] of the position loop of the back-and-forth move (K_p = 1 / it), ten
times the speed servo's: it only removes the servo's lag from the carriage's position."""
RAIL = (-0.05, 2.05)
"""Travel of the carriage's centre between its two end stops [m] (a 2.2 m rail, the
carriage 0.24 m long): the slide's range in robot_axis.xml."""
TORQUE, SPEED, BACK_AND_FORTH, SINE = 0, 1, 2, 3
"""Values of the parameter ``profile``."""
STEP_ANGLE = 0.3
"""Largest |λ| dt of the model's eigenvalues [-]: RK4 keeps the arm's oscillation within
1e-5 per period (the arm turns 0.06 rad per step at the default 1 ms)."""
LARGEST_TIMESTEP = 1e-3


def _p(name: str, unit: str, default: float, lo: float, hi: float, doc: str, **kw: Any) -> Param:
    return Param(name, unit, default, lo, hi, doc, **kw)


DRIVE, ARM, CHAIN, INERTIAS = "Entraînement", "Bras flexible", "Transmission", "Inerties"
MOVE, SINE_GROUP = "Aller-retour", "Couple sinusoïdal"

PARAMS = (
    _p("profile", "", 2, 0, 3, "0: constant motor torque from rest; 1: speed set point reached through a first-order filter; 2: back-and-forth point-to-point moves (trapezoidal speed profile); 3: sinusoidal motor torque.", step=1, label="Commande du moteur", hint="Couple constant, consigne de vitesse filtrée, allers-retours d'un bout à l'autre de la course, ou couple sinusoïdal.", group=DRIVE, choices=("Couple constant", "Consigne de vitesse", "Aller-retour", "Couple sinusoïdal")),
    _p("torque_Nm", "N·m", 1.0, -20.0, 20.0, "Motor torque C_m of the constant-torque command.", live=True, step=0.05, label="Couple moteur Cₘ", hint="Couple que le moteur applique à son arbre quand la commande est un couple constant.", group=DRIVE),
    _p("speed_rpm", "rpm", 500.0, -3000.0, 3000.0, "Motor speed set point of the speed command; top motor speed of the back-and-forth move (its magnitude).", live=True, step=10.0, label="Consigne de vitesse du moteur ωₘ", hint="Vitesse de l'arbre moteur visée par l'asservissement, ou vitesse de croisière des allers-retours.", group=DRIVE),
    _p("ramp_s", "s", 0.1, 0.0, 2.0, "Time constant of the speed set point's first-order filter (0: a step).", step=0.01, label="Temps de montée de la consigne τ", hint="Constante de temps du filtre du premier ordre appliqué à la consigne de vitesse (0 : un échelon).", group=DRIVE),
    _p("stroke", "m", 1.5, 0.0, 2.0, "Distance of one move of the back-and-forth command, from the rail's start.", live=True, step=0.01, label="Course d'un déplacement L", hint="Distance que le chariot parcourt à chaque aller, puis à chaque retour, depuis le début du rail.", group=MOVE),
    _p("accel_s", "s", 0.05, 0.0, 2.0, "Time of the back-and-forth move to reach the top speed from rest (trapezoidal profile; 0: a speed step).", live=True, step=0.01, label="Durée d'accélération tₐ", hint="Durée de la rampe de vitesse au départ et à l'arrivée de chaque déplacement.", group=MOVE),
    _p("pause_s", "s", 1.0, 0.0, 10.0, "Standstill at each end of the back-and-forth move.", live=True, step=0.1, label="Pause à chaque extrémité", hint="Durée de l'arrêt du chariot à chaque bout de sa course, pendant laquelle le bras oscille librement.", group=MOVE),
    _p("sine_Nm", "N·m", 1.0, 0.0, 20.0, "Amplitude C_0 of the sinusoidal motor torque C_m = C_0 sin(2π f t).", live=True, step=0.05, label="Amplitude du couple sinusoïdal C₀", hint="Amplitude du couple moteur qui varie sinusoïdalement avec le temps.", group=SINE_GROUP),
    _p("sine_Hz", "Hz", 2.0, 0.1, 50.0, "Frequency f of the sinusoidal motor torque.", live=True, step=0.01, label="Fréquence du couple sinusoïdal f", hint="Nombre de périodes du couple sinusoïdal par seconde ; le bras résonne vers 9,3 Hz.", group=SINE_GROUP),
    _p("flexible", "", 1, 0, 1, "1: the arm is a mass on a spring and a damper; 0: the arm is rigid (M2 moves with the carriage).", step=1, label="Modèle du bras", hint="Bras souple (masse M₂ sur un ressort et un amortisseur) ou rigide (M₂ comptée dans l'inertie équivalente).", group=ARM, choices=("Bras rigide", "Bras flexible")),
    _p("M2", "kg", 46.0, 0.5, 500.0, "Equivalent mass of the flexible parts (arm z).", step=0.5, label="Masse des parties flexibles M₂", hint="Masse équivalente du bras z, qui oscille par rapport au chariot.", group=ARM),
    _p("K_t", "N/m", 124000.0, 1000.0, 1e7, "Equivalent stiffness of the arm.", step=1000.0, label="Raideur équivalente du bras Kₜ", hint="Raideur du ressort qui relie le bras au chariot.", group=ARM, advanced=True),
    _p("mu_t", "N·s/m", 64.0, 0.0, 5000.0, "Equivalent internal damping of the arm.", step=1.0, label="Amortissement interne du bras μₜ", hint="Coefficient de l'amortisseur qui relie le bras au chariot.", group=ARM, advanced=True),
    _p("eta", "", 1.0, 0.3, 1.0, "Efficiency of the reducer (1: no loss), simulated with the motor driving the load.", step=0.01, label="Rendement du réducteur ρ", hint="Rapport de la puissance sortant du réducteur à celle qui y entre, quand le moteur entraîne la charge.", group=CHAIN),
    _p("k", "", 0.2, 0.02, 1.0, "Reduction ratio k = ω_p / ω_m.", step=0.01, label="Rapport de réduction k", hint="Rapport de la vitesse des poulies à celle du moteur.", group=CHAIN, advanced=True),
    _p("R_p", "m", 0.020, 0.005, 0.1, "Pitch radius of a toothed pulley.", step=0.001, label="Rayon primitif des poulies Rₚ", hint="Rayon primitif d'une poulie crantée : la courroie avance de Rₚ par radian de poulie.", group=CHAIN, advanced=True),
    _p("M1", "kg", 136.0, 1.0, 1000.0, "Equivalent mass of the rigid parts (carriage ch).", step=1.0, label="Masse des parties rigides M₁", hint="Masse équivalente du chariot et des pièces qui le suivent rigidement.", group=CHAIN, advanced=True),
    _p("f_v", "N·m·s/rad", 0.0171, 0.0, 1.0, "Viscous friction referred to the motor shaft.", step=0.0001, label="Frottement visqueux ramené au moteur fᵥ", hint="Coefficient du couple de frottement visqueux ramené sur l'arbre moteur, proportionnel à ωₘ.", group=CHAIN, advanced=True),
    _p("J_m", "kg·m²", 4.2e-4, 1e-6, 1e-2, "Inertia of the motor shaft.", step=1e-6, label="Moment d'inertie de l'arbre moteur Jₘ", hint="Moment d'inertie du rotor du moteur autour de son axe.", group=INERTIAS, advanced=True, log=True),
    _p("J_r", "kg·m²", 1.2e-4, 0.0, 1e-2, "Inertia of the reducer referred to the motor shaft.", step=1e-6, label="Moment d'inertie du réducteur Jᵣ", hint="Moment d'inertie du réducteur ramené sur l'arbre moteur.", group=INERTIAS, advanced=True, log=True),
    _p("J_p", "kg·m²", 6e-5, 0.0, 1e-2, "Inertia of one pulley (there are two).", step=1e-6, label="Moment d'inertie d'une poulie Jₚ", hint="Moment d'inertie d'une des deux poulies crantées autour de son axe.", group=INERTIAS, advanced=True, log=True),
)  # fmt: skip

DEFAULTS = {p.name: p.default for p in PARAMS}
