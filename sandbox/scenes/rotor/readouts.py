"""Readouts and arrows of the unbalanced rotor: the bearing forces at A and B and the
course's values at the measured speed, the static unbalance, the products of inertia and
the rotating resultant and moment of the frame's action."""

from __future__ import annotations

import functools
import math

import numpy as np

from sandbox.mechanics import coefficients, huygens
from sandbox.physics.page import Arrow, Bearing
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout
from sandbox.scenes import bearings
from sandbox.scenes.rotor.course import bearing_split, reference
from sandbox.scenes.rotor.params import AXIS, BEARING_X


@functools.lru_cache(maxsize=64)
def _bearing_gains(key: tuple[tuple[str, float], ...]) -> tuple[float, float]:
    """|F_A| / ω² and |F_B| / ω² of the course (7.2) for the rotor of these values."""
    ref = reference({**dict(key), "speed_rpm": 30.0 / math.pi})  # ω = 1 rad/s
    return ref["bearing_A"], ref["bearing_B"]


def _bearing_ref(s: Snapshot, k: int) -> float:
    """The course's bearing force at the measured ω (the speed may be ramping)."""
    key = tuple(sorted((n, float(v)) for n, v in s.values.items() if n != "speed_rpm"))
    w = s.joint_qvel("spin")
    return _bearing_gains(key)[k] * w * w


def _rotor_id(s: Snapshot) -> int:
    return s.body_id("rotor")


def _bearings(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """Forces of the frame on the rotor at A and B: split once a snapshot (both arrows
    and the readouts share it)."""
    cached = s.cache.get("rotor_bearings")
    if cached is None:
        cached = s.cache["rotor_bearings"] = bearing_split(*s.support)
    return cached


def _products(s: Snapshot) -> float:
    b = _rotor_id(s)
    rot = s.data.ximat[b].reshape(3, 3)
    i_g = rot @ np.diag(s.model.body_inertia[b]) @ rot.T
    i_o = huygens(i_g, float(s.model.body_mass[b]), -s.data.xipos[b])
    _, _, _, _, e, f = coefficients(i_o)
    return math.hypot(e, f)


def _static(s: Snapshot) -> float:
    b = _rotor_id(s)
    g = s.data.subtree_com[b]
    return float(s.model.body_subtreemass[b]) * math.hypot(g[1], g[2])


def _perp(v: np.ndarray) -> float:
    return float(np.linalg.norm(v - np.dot(v, AXIS) * AXIS))


_X0, _Y0, _PLANE = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), ("y₀", "z₀")
BEARINGS = (
    Bearing("A", "Palier A", lambda s: _bearings(s)[0], _X0, _Y0, _PLANE),
    Bearing("B", "Palier B", lambda s: _bearings(s)[1], _X0, _Y0, _PLANE),
)
"""Bearings A (x = −150 mm) and B (x = +150 mm): bronze bushes around the 10 mm shaft."""

READOUTS = (
    SceneReadout(
        "omega",
        "rad/s",
        "Rotation speed of the rotor.",
        lambda s: s.joint_qvel("spin"),
        label="Vitesse de rotation mesurée ω",
        hint="Vitesse de rotation du rotor par rapport au bâti.",
    ),
    SceneReadout(
        "bearing_A",
        "N",
        "Force of the frame on the rotor at bearing A, across the axis.",
        lambda s: float(np.linalg.norm(_bearings(s)[0])),
        label="Effort du palier A",
        hint="Norme de l'effort du bâti sur le rotor au palier A, perpendiculaire à l'axe.",
    ),
    SceneReadout(
        "bearing_B",
        "N",
        "Force of the frame on the rotor at bearing B, across the axis.",
        lambda s: float(np.linalg.norm(_bearings(s)[1])),
        label="Effort du palier B",
        hint="Norme de l'effort du bâti sur le rotor au palier B, perpendiculaire à l'axe.",
    ),
    SceneReadout(
        "bearing_A_ref",
        "N",
        "Course value of bearing_A at the measured speed (m, E, F and ω²).",
        lambda s: _bearing_ref(s, 0),
        label="Effort du palier A selon le cours",
        hint="Ce que donne le cours (7.2) pour l'effort du palier A à la vitesse mesurée : "
        "proportionnel à ω².",
    ),
    SceneReadout(
        "bearing_B_ref",
        "N",
        "Course value of bearing_B at the measured speed.",
        lambda s: _bearing_ref(s, 1),
        label="Effort du palier B selon le cours",
        hint="Ce que donne le cours (7.2) pour l'effort du palier B à la vitesse mesurée.",
    ),
    SceneReadout(
        "static_unbalance",
        "kg·m",
        "m × distance of G to the axis.",
        _static,
        label="Balourd statique m·Y",
        hint="Masse du rotor multipliée par la distance Y de son centre de gravité G à "
        "l'axe : nul quand le rotor est équilibré statiquement.",
    ),
    SceneReadout(
        "products_EF",
        "kg·m²",
        "√(E²+F²): products of inertia of the axis column at O.",
        _products,
        label="Produits d'inertie √(E²+F²)",
        hint="Produits d'inertie E et F de la colonne de l'axe x dans la matrice d'inertie "
        "en O : nuls, avec Y = 0, quand le rotor est équilibré dynamiquement.",
    ),
    SceneReadout(
        "F_rot",
        "N",
        "Rotating resultant of the frame's action on the rotor.",
        lambda s: _perp(s.support[0]),
        label="Résultante tournante Fᵣₒₜ",
        hint="Résultante de l'action du bâti sur le rotor, qui tourne avec lui : "
        "m·ω²·Y d'après le cours.",
    ),
    SceneReadout(
        "M_rot",
        "N·m",
        "Rotating moment at O of the frame's action on the rotor.",
        lambda s: _perp(s.support[1]),
        label="Moment tournant en O Mᵣₒₜ",
        hint="Moment en O de l'action du bâti sur le rotor, qui tourne avec lui : "
        "ω²·√(E²+F²) d'après le cours.",
    ),
    *bearings.readouts(BEARINGS),
)

ARROWS = (
    Arrow(
        "bearing_A",
        "Palier A",
        (40, 110, 230),
        lambda s: (np.array([-BEARING_X, 0.0, 0.0]), _bearings(s)[0]),
        scale=4e-3,
        unit="N",
        point="A",
        hint="Effort du bâti sur le rotor au palier A (bleu).",
    ),
    Arrow(
        "bearing_B",
        "Palier B",
        (230, 80, 40),
        lambda s: (np.array([BEARING_X, 0.0, 0.0]), _bearings(s)[1]),
        scale=4e-3,
        unit="N",
        point="B",
        hint="Effort du bâti sur le rotor au palier B (orange).",
    ),
)
