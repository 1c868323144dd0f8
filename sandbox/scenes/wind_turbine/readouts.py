"""Readouts of the wind turbine: the speeds, λ and Cp, the torques, every stage's power
and loss, the overall efficiency; and the ``mechanism`` hook that turns the simulated
slow shaft's energies into the machine's (course 6.4)."""

from __future__ import annotations

import math

from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout
from sandbox.scenes.wind_turbine.course import area, chain, tip_speed_ratio, true_inertia


def _state(s: Snapshot) -> dict[str, float]:
    """The chain at this state (ω, ω̇ from MuJoCo's accelerations), cached a snapshot."""
    cached = s.cache.get("wind_chain")
    if cached is None:
        w, w_dot = float(s.data.qvel[0]), float(s.data.qacc[0])
        cached = chain(w, w_dot, s.values)
        cached["omega"], cached["omega_dot"] = w, w_dot
        s.cache["wind_chain"] = cached
    return cached


def _cp(s: Snapshot) -> float:
    v = s.values
    kinetic = 0.5 * v["air_density"] * area(v) * v["wind_speed"] ** 3
    return _state(s)["P_rotor"] / kinetic if kinetic > 0 else math.nan


def _power(name: str, doc: str, label: str, hint: str) -> SceneReadout:
    return SceneReadout(name, "W", doc, lambda s: _state(s)[name], label=label, hint=hint)


READOUTS = (
    SceneReadout("omega", "rad/s", "Rotor (slow shaft) speed.", lambda s: float(s.data.qvel[0]), label="Vitesse du rotor ω", hint="Vitesse de rotation du rotor et de l'arbre lent."),
    SceneReadout("omega_g", "rad/s", "Generator (fast shaft) speed k ω.", lambda s: s.values["gear_ratio"] * float(s.data.qvel[0]), label="Vitesse de l'alternateur ωₐ", hint="Vitesse de l'arbre rapide, k fois celle du rotor."),
    SceneReadout("tip_speed_ratio", "", "Tip-speed ratio λ = ω R / V.", lambda s: tip_speed_ratio(float(s.data.qvel[0]), s.values), label="Vitesse spécifique λ", hint="Rapport entre la vitesse du bout des pales, ω·R, et celle du vent V."),
    SceneReadout("Cp", "", "Power coefficient: P_rotor / (½ ρ S V³) (at most 16/27, Betz).", _cp, label="Coefficient de puissance Cp", hint="Part de la puissance du vent ½·ρ·S·V³ que les pales prennent : au plus 16/27 (limite de Betz)."),
    SceneReadout("rotor_torque", "N·m", "Torque of the wind on the rotor C_a.", lambda s: _state(s)["rotor_torque"], label="Couple du vent sur le rotor", hint="Couple que le vent exerce sur le rotor par les pales."),
    SceneReadout("generator_torque", "N·m", "Generator's braking torque C_g = K ω_g on the fast shaft.", lambda s: _state(s)["generator_torque"], label="Couple résistant de l'alternateur Cₐ", hint="Couple de freinage de l'alternateur sur l'arbre rapide, proportionnel à sa vitesse."),
    _power("P_wind", "Betz's power P1 = 8/27 ρ S V³ (what the course's chain starts from).", "Puissance du vent P₁ (Betz)", "Puissance du vent théoriquement récupérable, 8/27·ρ·S·V³ (limite de Betz)."),
    _power("P_rotor", "Power the blades pass to the slow shaft, C_a ω.", "Puissance captée par l'hélice", "Puissance que le vent transmet à l'arbre par les pales, couple fois vitesse."),
    _power("P_rotor_loss", "P1 − P_rotor: the wind's power the blades do not take.", "Puissance non captée", "Part de la puissance de Betz que les pales ne prennent pas."),
    _power("P_rotor_store", "Power the rotor's inertia stores, J_r ω ω̇ (0 in steady state).", "Puissance stockée par le rotor", "Puissance qui sert à accélérer le rotor : elle remplit son énergie cinétique, nulle en régime établi."),
    _power("P_gearbox_in", "Power entering the gearbox from the slow shaft.", "Puissance d'entrée du multiplicateur", "Puissance que l'arbre lent fait entrer dans le multiplicateur."),
    _power("P_gearbox_loss", "Power the gearbox turns into heat, (1 − ρ_m) P_in.", "Pertes du multiplicateur", "Chaleur que la lubrification du multiplicateur doit évacuer."),
    _power("P_generator_store", "Power the generator's rotor stores, J_g k² ω ω̇.", "Puissance stockée par l'alternateur", "Puissance qui accélère le rotor de l'alternateur, nulle en régime établi."),
    _power("P_generator_in", "Mechanical power the generator receives, C_g ω_g.", "Puissance reçue par l'alternateur", "Puissance mécanique que l'alternateur reçoit de l'arbre rapide."),
    _power("P_generator_loss", "Power the generator loses.", "Pertes de l'alternateur", "Part de la puissance reçue que l'alternateur perd en chaleur."),
    _power("P_electric", "Electric power the generator delivers.", "Puissance électrique produite", "Puissance électrique à la sortie de l'alternateur."),
    _power("P_transformer_loss", "Power the transformer loses.", "Pertes du transformateur", "Part de la puissance électrique perdue dans le transformateur."),
    _power("P_transformer_out", "Power leaving the transformer.", "Puissance sortant du transformateur", "Puissance électrique transmise aux lignes."),
    _power("P_line_loss", "Power the lines lose.", "Pertes en ligne", "Part de la puissance perdue dans les lignes jusqu'à la terre."),
    _power("P_grid", "Power delivered to the grid on shore.", "Puissance livrée au réseau", "Puissance électrique qui arrive à terre."),
    SceneReadout("efficiency", "", "Overall efficiency P_grid / P1.", lambda s: _state(s)["efficiency"], label="Rendement global", hint="Puissance livrée au réseau divisée par la puissance de Betz : le produit des rendements en régime établi (0,52 dans le cours)."),
)  # fmt: skip


def mechanism(s: Snapshot, out: dict[str, float]) -> None:
    """The machine's T, P_acc, P_ext and P_int from the simulated slow shaft's.

    The simulation carries the generator's rotor as the armature J_g k² / ρ_m and the
    generator's torque through the gearbox as k C_g / ρ_m (driving mode). The machine's
    kinetic energy is T = ½ (J_r + J_g k²) ω²; its outside actions are the wind on the
    blades and the generator's stator on its rotor, P_ext = C_a ω − C_g ω_g; the gearbox's
    loss is its inter-efforts' power, P_int = −(1 − ρ_m) P_in. Then dT/dt = P_ext + P_int
    exactly (the frame's power stays 0)."""
    st = _state(s)
    w, w_dot = st["omega"], st["omega_dot"]
    j = true_inertia(s.values)
    if "T" in out:
        out["T"] = 0.5 * j * w * w
    if "P_acc" in out:
        out["P_acc"] = j * w * w_dot
    if "P_ext" in out:
        out["P_ext"] = st["P_rotor"] - st["P_generator_in"]
    if "P_int" in out:
        out["P_int"] = -st["P_gearbox_loss"]
