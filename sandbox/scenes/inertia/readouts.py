"""Readouts and arrows of the inertia scene: the matrix at the chosen point and basis, the
principal moments and Huygens' terms read from the simulated model, and the free spin
(ω, σ_G, the angle to the launch axis).
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.mechanics.inertia import coefficients
from sandbox.physics.page import Arrow
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout
from sandbox.scenes.inertia.course import basis, course_inertia, huygens_terms, matrix_at
from sandbox.scenes.inertia.model import simulated
from sandbox.scenes.inertia.params import choice_index


def _matrix(s: Snapshot) -> np.ndarray:
    found = s.cache.get("inertia_matrix")
    if found is None:
        sim = simulated(s.model, s.values)
        found = s.cache["inertia_matrix"] = matrix_at(sim.mass, sim.com, sim.inertia_G, s.values)
    return found


def _coefficient(k: int):
    return lambda s: coefficients(_matrix(s))[k] + 0.0  # + 0.0: no "−0" for a product


def _gap(s: Snapshot) -> float:
    """Largest |I_sim − I_course| over the largest |I_course| (at the chosen point, basis)."""
    props = course_inertia(s.values)
    ref = matrix_at(props.mass, props.com, props.inertia_G, s.values)
    return float(np.max(np.abs(_matrix(s) - ref)) / np.max(np.abs(ref)))


def _huygens_terms(s: Snapshot) -> np.ndarray:
    found = s.cache.get("inertia_huygens")
    if found is None:
        sim = simulated(s.model, s.values)
        found = s.cache["inertia_huygens"] = huygens_terms(sim.mass, sim.com, s.values)
    return found


def _omega_local(s: Snapshot) -> np.ndarray:
    return np.asarray(s.data.qvel[3:6], dtype=float)


def _spin_angle(s: Snapshot) -> float:
    """Angle [deg] between ω and the launch principal axis e_k (0 to 180: a flip reads 180)."""
    w = _omega_local(s)
    norm = float(np.linalg.norm(w))
    if norm == 0.0:
        return 0.0
    e = simulated(s.model, s.values).axes[:, choice_index(s.values, "spin_axis")]
    return math.degrees(math.acos(float(np.clip(w @ e / norm, -1.0, 1.0))))


def _sigma_world(s: Snapshot) -> np.ndarray:
    """σ_G = I_G ω in R₀ [kg·m²/s]."""
    b = s.body_id("solid")
    r = s.data.xmat[b].reshape(3, 3)
    return r @ (simulated(s.model, s.values).inertia_G @ _omega_local(s))


def _omega_world(s: Snapshot) -> np.ndarray:
    b = s.body_id("solid")
    return s.data.xmat[b].reshape(3, 3) @ _omega_local(s)


def _principal(k: int):
    return lambda s: float(simulated(s.model, s.values).moments[k])


def _huygens(k: int):
    def fn(s: Snapshot) -> float:
        return float(_huygens_terms(s)[k])

    return fn


_AXIS_WORDS = ("x", "y", "z")
READOUTS = (
    *(
        SceneReadout(
            n,
            "kg·m²",
            f"Moment of inertia {n} about the chosen {ax} axis through the chosen point.",
            _coefficient(k),
            label=f"Moment d'inertie {n}",
            hint=f"Moment d'inertie {n} autour de l'axe {ax} de la base choisie, passant par le "
            "point choisi, calculé sur le modèle simulé.",
        )
        for k, (n, ax) in enumerate(zip("ABC", _AXIS_WORDS, strict=True))
    ),
    *(
        SceneReadout(
            n,
            "kg·m²",
            f"Product of inertia {n} = ∫ {w} dm at the chosen point, in the chosen basis.",
            _coefficient(k + 3),
            label=f"Produit d'inertie {n}",
            hint=f"Produit d'inertie {n} = ∫ {w} dm au point choisi et dans la base choisie ; "
            f"la matrice porte −{n}.",
        )
        for k, (n, w) in enumerate(zip("DEF", ("y·z", "x·z", "x·y"), strict=True))
    ),
    *(
        SceneReadout(
            f"I_{k + 1}",
            "kg·m²",
            f"Principal moment of inertia {k + 1} at G (ascending order).",
            _principal(k),
            label=f"Moment principal en G I{sub}",
            hint=f"Moment principal d'inertie en G numéro {k + 1}, les trois étant rangés du "
            "plus petit au plus grand.",
        )
        for k, sub in enumerate("₁₂₃")
    ),
    *(
        SceneReadout(
            f"huygens_{n}",
            "kg·m²",
            f"Huygens term of {n}: what moving the matrix from G to the chosen point adds.",
            _huygens(k),
            label=f"Terme de Huygens sur {n}",
            hint=f"Terme diagonal de la matrice de Huygens ajouté à {n} quand on passe de G au "
            f"point choisi : m·({sq}) avec GP = (a, b, c).",
        )
        for k, (n, sq) in enumerate(zip("ABC", ("b² + c²", "a² + c²", "a² + b²"), strict=True))
    ),
    SceneReadout(
        "gap",
        "",
        "Largest gap between the simulated matrix and the course's, over its largest term.",
        _gap,
        label="Écart au formulaire",
        hint="Plus grand écart entre la matrice du modèle simulé et celle du formulaire, "
        "rapporté au plus grand de ses termes.",
    ),
    SceneReadout(
        "spin_angle",
        "deg",
        "Angle between the rotation vector and the launch principal axis (180: flipped).",
        _spin_angle,
        label="Angle entre ω et l'axe de lancement",
        hint="Angle entre le vecteur rotation et l'axe principal de lancement, lié au solide : "
        "180° quand le solide s'est retourné.",
    ),
    SceneReadout(
        "omega",
        "rad/s",
        "Norm of the rotation vector of the solid.",
        lambda s: float(np.linalg.norm(_omega_local(s))),
        label="Norme de la rotation ω",
        hint="Norme du vecteur rotation du solide par rapport au repère R₀.",
    ),
    SceneReadout(
        "sigma_G",
        "kg·m²/s",
        "Norm of the angular momentum at G, conserved without torque.",
        lambda s: float(np.linalg.norm(_sigma_world(s))),
        label="Moment cinétique en G σ",
        hint="Norme du moment cinétique en G, constante en l'absence de couple extérieur.",
    ),
)


def _at_g(s: Snapshot) -> np.ndarray:
    return np.array(s.data.xipos[s.body_id("solid")])


def _launch_axis_world(s: Snapshot) -> np.ndarray:
    """The launch principal axis e_k in R₀ (unit vector)."""
    b = s.body_id("solid")
    e = simulated(s.model, s.values).axes[:, choice_index(s.values, "spin_axis")]
    return np.asarray(s.data.xmat[b].reshape(3, 3) @ e)


def _axis_component(k: int):
    def fn(s: Snapshot) -> float:
        e = simulated(s.model, s.values).axes[:, choice_index(s.values, "spin_axis")]
        if e[int(np.argmax(np.abs(e)))] < 0:  # an axis has no sign: show it pointing "up"
            e = -e
        return float(basis(s.values)[:, k] @ e) + 0.0

    return fn


AXIS_READOUTS = tuple(
    SceneReadout(
        f"axis_{c}",
        "",
        f"Component on the chosen basis' {c} of the launch principal axis at G.",
        _axis_component(k),
        label=f"Axe principal choisi, composante sur {c}",
        hint=f"Composante sur l'axe {c} de la base choisie du vecteur unitaire de l'axe "
        "principal d'inertie de lancement, en G.",
    )
    for k, c in enumerate("xyz")
)


ARROWS = (
    Arrow(
        "axis",
        "Axe principal de lancement",
        (220, 180, 30),
        lambda s: (_at_g(s), _launch_axis_world(s)),
        scale=0.25,
        point="G",
        hint="Axe principal d'inertie en G autour duquel le solide a été lancé (jaune).",
        magnitude=False,
    ),
    Arrow(
        "omega",
        "Rotation ω",
        (230, 80, 40),
        lambda s: (_at_g(s), _omega_world(s)),
        scale=0.02,
        unit="rad/s",
        point="G",
        hint="Vecteur rotation du solide, tracé depuis G (orange).",
    ),
    Arrow(
        "sigma_G",
        "Moment cinétique σ en G",
        (120, 60, 160),
        lambda s: (_at_g(s), _sigma_world(s)),
        scale=2.0,
        unit="kg·m²/s",
        point="G",
        hint="Moment cinétique en G, fixe dans R₀ puisqu'aucun couple n'agit (violet).",
    ),
)
