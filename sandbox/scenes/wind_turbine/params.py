"""Parameter table of the wind turbine (:mod:`sandbox.scenes.wind_turbine`): the wind, the
rotor, the chain's efficiencies (the course's estimates, 6.4.2), the gearbox's ratio, the
generator's load and the inertias."""

from __future__ import annotations

from typing import Any

from sandbox.physics.spec import Param

WIND, ROTOR, CHAIN, INERTIAS = "Vent", "Rotor", "Chaîne de puissance", "Inerties et départ"


def _p(name: str, unit: str, default: float, lo: float, hi: float, doc: str, **kw: Any) -> Param:
    return Param(name, unit, default, lo, hi, doc, **kw)


# The course's P₁ = 5 MW: 8/27 ρ S V³ with ρ = 1,225 kg/m³ and V = 10 m/s gives
# S = 13 776 m², a rotor of 132,44 m (5,000 07 MW). The generator's K holds the optimum
# tip-speed ratio in that wind: k² K / ρ_m = b, K = 231,26 N·m·s/rad (course.optimal_load).
PARAMS = (
    _p("wind_speed", "m/s", 10.0, 0.0, 25.0, "Wind speed V upstream of the rotor.", live=True, step=0.1, label="Vitesse du vent V", hint="Vitesse du vent en amont du rotor : la puissance qu'il apporte croît comme V³.", group=WIND),
    _p("air_density", "kg/m³", 1.225, 0.9, 1.4, "Air density ρ.", live=True, step=0.005, label="Masse volumique de l'air ρ", hint="Masse volumique de l'air : 1,225 kg/m³ au niveau de la mer à 15 °C.", group=WIND, advanced=True),
    _p("diameter", "m", 132.44, 20.0, 200.0, "Rotor diameter D (swept area S = π D²/4).", step=0.01, label="Diamètre du rotor D", hint="Diamètre balayé par les pales : la surface S = π·D²/4 reçoit le vent.", group=ROTOR),
    _p("tsr_opt", "", 8.0, 3.0, 12.0, "Tip-speed ratio λ* = ω R / V at which the blades take the most power.", live=True, step=0.1, label="Vitesse spécifique optimale λₒₚₜ", hint="Rapport entre la vitesse du bout des pales et celle du vent pour lequel les pales captent le plus de puissance.", group=ROTOR, advanced=True),
    _p("eta_rotor", "", 0.75, 0.1, 1.0, "Rotor efficiency at the optimum: its power over Betz's (the course's 0.75).", live=True, step=0.01, label="Rendement de l'hélice", hint="Part de la puissance de Betz que les pales transmettent à l'arbre, au meilleur réglage (0,75 dans le cours).", group=CHAIN),
    _p("eta_gearbox", "", 0.9, 0.3, 1.0, "Gearbox efficiency ρ_m (driving mode).", step=0.01, label="Rendement du multiplicateur", hint="Part de la puissance entrant dans le multiplicateur qui en ressort vers l'alternateur (0,9 dans le cours).", group=CHAIN),
    _p("eta_generator", "", 0.9, 0.3, 1.0, "Generator efficiency: electric power over the mechanical power it receives.", live=True, step=0.01, label="Rendement de l'alternateur", hint="Part de la puissance mécanique reçue que l'alternateur rend en électricité (0,9 dans le cours).", group=CHAIN),
    _p("eta_transformer", "", 0.9, 0.3, 1.0, "Transformer efficiency.", live=True, step=0.01, label="Rendement du transformateur", hint="Part de la puissance électrique que le transformateur transmet (0,9 dans le cours).", group=CHAIN),
    _p("eta_lines", "", 0.95, 0.3, 1.0, "Efficiency of the power lines to the shore.", live=True, step=0.01, label="Rendement des lignes électriques", hint="Part de la puissance qui arrive à terre au bout des lignes (0,95 dans le cours).", group=CHAIN),
    _p("gear_ratio", "", 100.0, 10.0, 200.0, "Gearbox ratio k = ω_g / ω (the generator turns k times faster).", step=1.0, label="Rapport du multiplicateur k", hint="L'alternateur tourne k fois plus vite que le rotor.", group=CHAIN),
    _p("generator_load", "N·m·s/rad", 231.26, 0.0, 1000.0, "Generator load K: its torque C_g = K ω_g on the fast shaft.", live=True, step=0.1, label="Charge de l'alternateur K", hint="L'alternateur freine son arbre d'un couple proportionnel à sa vitesse, Cₐ = K·ωₐ : K règle où le rotor se stabilise.", group=CHAIN),
    _p("rotor_inertia", "kg·m²", 3.5e7, 1e5, 1e8, "Rotor (hub and blades) inertia J_r about its shaft.", step=1e5, label="Moment d'inertie du rotor Jᵣ", hint="Moment d'inertie du moyeu et des pales autour de l'arbre lent.", group=INERTIAS, advanced=True, log=True),
    _p("generator_inertia", "kg·m²", 500.0, 0.0, 5000.0, "Generator rotor inertia J_g about the fast shaft.", step=1.0, label="Moment d'inertie de l'alternateur Jₐ", hint="Moment d'inertie du rotor de l'alternateur autour de l'arbre rapide : vu du rotor, il compte k² fois.", group=INERTIAS, advanced=True),
    _p("start", "", 0.0, 0.0, 1.0, "0: start at the steady speed; 1: start at rest (the kinetic energy fills first); a change relaunches the rotor.", live=True, step=1.0, label="Départ", hint="En régime établi, ou arrêté : le changer relance aussitôt le rotor, qui prend alors de la vitesse pendant qu'une part de la puissance remplit son énergie cinétique.", group=INERTIAS, choices=("En régime établi", "À l'arrêt")),
)  # fmt: skip
