"""Generic readouts for any MJCF model: energy, powers and torsors of the mechanism.

Pure functions of (model, data). Everything is at the world origin O, on the world axes,
relative to the world frame R0 (Galilean). The *mechanism* is every body not welded to
the world (``model.body_weldid != 0``).

Call :func:`prepare` once at the current state (after ``mj_step`` MuJoCo's derived
quantities belong to the state *before* the step), then :func:`compute`.

This module names the readouts (:data:`GENERIC_READOUTS`) and computes those asked; the
quantities themselves come from :mod:`~sandbox.physics.kinematics`,
:mod:`~sandbox.physics.torsors` and :mod:`~sandbox.physics.energy`, on the structure of
:mod:`~sandbox.physics.mechanism`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import mujoco

from sandbox.physics.energy import acceleration_power, kinetic_energy, potential_energy, powers
from sandbox.physics.kinematics import Pair, cached_kinematics
from sandbox.physics.torsors import dynamic_torsor, kinetic_torsor, support_torsor
from sandbox.physics.units import display_unit


@dataclass(frozen=True)
class ReadoutInfo:
    """Name, unit and one-line doc of a readout; ``label`` and ``hint``: the French words
    (with the course's symbol) and tooltip of the web page ("": the name and the doc)."""

    name: str
    unit: str
    doc: str
    label: str = ""
    hint: str = ""

    @property
    def display_unit(self) -> str:
        """The unit as the web page shows it ("tr/min" for "rpm", "°" for "deg")."""
        return display_unit(self.unit)


AXES = {"x": "x₀", "y": "y₀", "z": "z₀"}
"""The world axes as the course writes them (basis B0 of R0)."""


def _torsor_infos(
    prefix: str, what: str, ru: str, mu: str, words: tuple[str, str, str, str]
) -> list[ReadoutInfo]:
    """Six components of a torsor at O; ``words``: French (resultant label, resultant
    hint, moment label, moment hint), each with ``{axis}`` for the axis."""
    rl, rh, ml, mh = words
    out = [
        ReadoutInfo(
            f"{prefix}_R_{c}",
            ru,
            f"{what}: resultant, {c} component",
            rl.format(axis=AXES[c]),
            rh.format(axis=AXES[c]),
        )
        for c in "xyz"
    ]
    out += [
        ReadoutInfo(
            f"{prefix}_M_{c}",
            mu,
            f"{what}: moment at O, {c} component",
            ml.format(axis=AXES[c]),
            mh.format(axis=AXES[c]),
        )
        for c in "xyz"
    ]
    return out


GENERIC_READOUTS: tuple[ReadoutInfo, ...] = (
    ReadoutInfo("time", "s", "Simulated time.", "Temps t", "Temps simulé écoulé depuis le départ."),
    ReadoutInfo(
        "T",
        "J",
        "Kinetic energy of the mechanism in R0.",
        "Énergie cinétique T",
        "Énergie cinétique de l'ensemble des pièces mobiles dans leur mouvement par rapport "
        "au bâti (repère R₀, supposé galiléen).",
    ),
    ReadoutInfo(
        "V",
        "J",
        "Potential energy of weight and joint springs.",
        "Énergie potentielle V",
        "Énergie potentielle de la pesanteur et des ressorts des liaisons (nulle quand le "
        "poids est négligé).",
    ),
    ReadoutInfo(
        "P_ext",
        "W",
        "Power of weight, motors and applied loads.",
        "Puissance des efforts extérieurs Pₑₓₜ",
        "Puissance du poids, des moteurs et des charges appliquées aux pièces mobiles, dans "
        "leur mouvement par rapport à R₀.",
    ),
    ReadoutInfo(
        "P_int",
        "W",
        "Power of inter-efforts, non-perfect joints and contacts.",
        "Puissance des efforts intérieurs Pᵢₙₜ",
        "Puissance des inter-efforts : frottements et amortissements des liaisons non "
        "parfaites et des contacts, toujours négative ou nulle.",
    ),
    ReadoutInfo(
        "P_acc",
        "W",
        "Power of the accelerations, equal to dT/dt.",
        "Puissance des quantités d'accélération dT/dt",
        "Somme sur les solides du comoment {D} ⊗ {V}, égale à la dérivée de l'énergie cinétique T.",
    ),
    *_torsor_infos(
        "kin",
        "Kinetic torsor {C}",
        "kg·m/s",
        "kg·m²/s",
        (
            "Résultante cinétique m·V(G) selon {axis}",
            "Composante sur {axis} de la résultante du torseur cinétique {{C}} des pièces "
            "mobiles, leur quantité de mouvement.",
            "Moment cinétique σ en O selon {axis}",
            "Composante sur {axis} du moment en O du torseur cinétique {{C}} des pièces mobiles.",
        ),
    ),
    *_torsor_infos(
        "dyn",
        "Dynamic torsor {D}",
        "N",
        "N·m",
        (
            "Résultante dynamique m·Γ(G) selon {axis}",
            "Composante sur {axis} de la résultante du torseur dynamique {{D}} des pièces mobiles.",
            "Moment dynamique δ en O selon {axis}",
            "Composante sur {axis} du moment en O du torseur dynamique {{D}} des pièces mobiles.",
        ),
    ),
    *_torsor_infos(
        "sup",
        "Action of the frame on the mechanism",
        "N",
        "N·m",
        (
            "Action du bâti : résultante selon {axis}",
            "Composante sur {axis} de la résultante des actions du bâti 0 sur les pièces "
            "mobiles, par les liaisons et les contacts (moteurs exclus).",
            "Action du bâti : moment en O selon {axis}",
            "Composante sur {axis} du moment en O des actions du bâti 0 sur les pièces "
            "mobiles, par les liaisons et les contacts (moteurs exclus).",
        ),
    ),
)
GENERIC_NAMES: tuple[str, ...] = tuple(r.name for r in GENERIC_READOUTS)
GENERIC_SET: frozenset[str] = frozenset(GENERIC_NAMES)
_NEEDS_RNE = ("dyn_", "sup_", "P_acc")


_TORSORS = ("kin", "dyn", "sup")


def torsor(
    model: mujoco.MjModel, data: mujoco.MjData, prefix: str, cache: dict[str, Any] | None = None
) -> Pair:
    """The mechanism's torsor ``prefix`` ("kin", "dyn" or "sup") at O, memoised in cache."""
    if cache is not None and prefix in cache:
        return cache[prefix]
    if prefix == "sup":
        value = support_torsor(model, data)
    elif prefix in ("kin", "dyn"):
        fn = kinetic_torsor if prefix == "kin" else dynamic_torsor
        value = fn(model, data, kin=cached_kinematics(model, data, cache))
    else:
        raise KeyError(f"unknown torsor {prefix!r}; valid: {', '.join(_TORSORS)}")
    if cache is not None:
        cache[prefix] = value
    return value


def prepare(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    names: Iterable[str] = (),
    *,
    forces: bool = False,
) -> None:
    """Bring ``data`` up to date at its current state for the readouts ``names``, and
    for the forces (the frame's actions, the dynamic torsor: ``mj_rnePostConstraint``)
    when ``forces`` is set or a name needs them."""
    mujoco.mj_forward(model, data)
    if forces or any(n.startswith(_NEEDS_RNE) for n in names):
        mujoco.mj_rnePostConstraint(model, data)


def compute(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    names: Iterable[str],
    cache: dict[str, Any] | None = None,
) -> dict[str, float]:
    """Values of the generic readouts ``names`` (after :func:`prepare`); only those asked.

    ``cache`` (prefix -> torsor) lets several consumers share one torsor computation.
    """
    names = list(names)
    asked = set(names)
    unknown = [n for n in names if n not in GENERIC_SET]
    if unknown:
        raise KeyError(f"unknown readout {unknown[0]!r}; valid: {', '.join(GENERIC_NAMES)}")
    out: dict[str, float] = {}
    heads = {n[:4] for n in asked}
    for prefix in _TORSORS:
        if prefix + "_" in heads:
            r, m = torsor(model, data, prefix, cache)
            for c, ri, mi in zip("xyz", r.tolist(), m.tolist(), strict=True):
                out[f"{prefix}_R_{c}"], out[f"{prefix}_M_{c}"] = ri, mi
    if "time" in asked:
        out["time"] = float(data.time)
    kin = cached_kinematics(model, data, cache)
    if "T" in asked:
        out["T"] = kinetic_energy(model, data, kin=kin)
    if "V" in asked:
        out["V"] = potential_energy(model, data)
    if "P_ext" in asked or "P_int" in asked:
        out.update(powers(model, data, kin=kin))
    if "P_acc" in asked:
        out["P_acc"] = acceleration_power(model, data, kin=kin)
    return {n: out[n] for n in names}
