"""Readouts and arrows of the inline engine: pilon and tamis on the block, each cylinder's
share, the orders and rocking moment over a revolution, the course's values at the current
angle and speed, motor torque and closure error."""

from __future__ import annotations

import math

import numpy as np

from sandbox.mechanics.engine import Engine, shaking_force, shaking_moment
from sandbox.physics.page import Arrow, Bearing
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout
from sandbox.physics.torsors import joint_drive
from sandbox.scenes import bearings
from sandbox.scenes.engine.course import cylinder_count, engine_of
from sandbox.scenes.engine.cycle import orders
from sandbox.scenes.engine.params import MAX_CYLINDERS


def _theta_c(s: Snapshot) -> float:
    return s.joint_qpos("crank")


def _theta(s: Snapshot) -> float:
    return _theta_c(s) - math.pi / 2


def _engine(s: Snapshot) -> Engine:
    return engine_of(s.values, s.joint_qvel("crank"))


def _block(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """(force, moment at C) of the moving parts on the block: minus the frame's action."""
    r, m = s.support
    return -np.asarray(r), -np.asarray(m)


def _cylinder_pilons(s: Snapshot) -> np.ndarray:
    """Each cylinder's −Σ m Γ(G)·y0 [N], 0 for the absent ones, shape (4,): computed once a
    snapshot for the four readouts that read it."""
    cached = s.cache.get("engine_pilons")
    if cached is not None:
        return cached
    out = s.cache["engine_pilons"] = np.zeros(MAX_CYLINDERS)
    acc = s.kinematics.a_g
    mass = s.model.body_mass
    for i in range(1, cylinder_count(s.values) + 1):
        ids = [s.body_id(f"{b}_{i}") for b in ("piston", "rod", "throw", "cw")]
        out[i - 1] = -float(mass[ids] @ acc[ids, 1])
    return out


def _closure(s: Snapshot) -> float:
    d, worst = s.data, 0.0
    for i in range(1, cylinder_count(s.values) + 1):
        a = d.site(f"A_crank_{i}").xpos
        b = d.site(f"A_rod_{i}").xpos
        worst = max(worst, float(np.linalg.norm(a - b)))
    return worst


def _force_ref(s: Snapshot) -> np.ndarray:
    """The course's force on the block at the snapshot's angle and speed (tamis, pilon)."""
    out = s.cache.get("engine_force_ref")
    if out is None:
        out = s.cache["engine_force_ref"] = shaking_force(_engine(s), _theta(s))
    return out


def _pilon_ref(s: Snapshot) -> float:
    return float(_force_ref(s)[1])


def _tamis_ref(s: Snapshot) -> float:
    return float(_force_ref(s)[0])


def _moment_ref(s: Snapshot) -> float:
    return float(np.linalg.norm(shaking_moment(_engine(s), _theta(s))))


def _pilon_i(i: int) -> SceneReadout:
    return SceneReadout(
        f"pilon_{i}", "N",
        f"Share of cylinder {i} in the pilon: -sum m Gamma(G).y0 of its piston, rod, throw and counterweight (0 when absent).",
        lambda s: float(_cylinder_pilons(s)[i - 1]),
        label=f"Pilon du cylindre {i}",
        hint=f"Part du cylindre {i} dans l'effet de pilon, nulle quand ce cylindre n'existe pas.",
    )  # fmt: skip


MAIN_BEARINGS_Z = 0.13
"""The crankshaft's main bearings A and B at z = ∓130 mm, beyond the outer throws."""
_ENDS = (np.array([0.0, 0.0, -MAIN_BEARINGS_Z]), np.array([0.0, 0.0, MAIN_BEARINGS_Z]))


def _main(s: Snapshot, k: int) -> np.ndarray:
    return bearings.two_bearings(s, "crank", *_ENDS)[k]


BEARINGS = (
    Bearing("A", "Palier A", lambda s: _main(s, 0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), ("x₀", "y₀")),
    Bearing("B", "Palier B", lambda s: _main(s, 1), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), ("x₀", "y₀")),
)  # fmt: skip
"""The crankshaft's two main bearings on the block: its pivot's action split between
them (isostatic: a ball joint at A, an annular joint at B)."""

READOUTS = (
    SceneReadout("theta", "rad", "Engine angle θ: cylinder 1's crank from its top dead centre (unwrapped).", _theta, label="Angle du vilebrequin θ", hint="Angle de la manivelle du premier cylindre depuis son point mort haut, qui croît tour après tour."),
    SceneReadout("omega", "rad/s", "Crankshaft speed θ'.", lambda s: s.joint_qvel("crank"), label="Vitesse mesurée du vilebrequin ω", hint="Vitesse de rotation θ' du vilebrequin par rapport au bloc moteur."),
    SceneReadout("pilon", "N", "Force of the moving parts on the block along y0 (the cylinders' axis).", lambda s: float(_block(s)[0][1]), label="Effet de pilon", hint="Effort des pièces mobiles sur le bloc moteur le long de l'axe des cylindres y₀."),
    SceneReadout("tamis", "N", "Force of the moving parts on the block along x0 (across the cylinders).", lambda s: float(_block(s)[0][0]), label="Effet de tamis", hint="Effort des pièces mobiles sur le bloc moteur perpendiculairement aux cylindres, le long de x₀."),
    SceneReadout("pilon_ref", "N", "Course value of the pilon at the current angle and speed (exact slider-cranks, constant speed).", _pilon_ref, label="Pilon selon le cours", hint="Pilon calculé par le cours pour les systèmes bielle-manivelle exacts, à l'angle et à la vitesse actuels."),
    SceneReadout("tamis_ref", "N", "Course value of the tamis at the current angle and speed (as pilon_ref): zero when the counterweights balance the rotating masses exactly, and for two or four cylinders whatever they balance (their throws cancel the first order).", _tamis_ref, label="Tamis selon le cours", hint="Tamis calculé par le cours, nul quand les contrepoids compensent juste les masses tournantes ou quand les manivelles sont opposées deux à deux."),
    *(_pilon_i(i) for i in range(1, MAX_CYLINDERS + 1)),
    SceneReadout("shaking_force_h1", "N", "Order-1 amplitude of the pilon over a revolution simulated ahead (least-squares projection).", lambda s: float(orders(s)[0]), label="Pilon, ordre 1", hint="Amplitude de la composante du pilon à la fréquence de rotation, sur un tour simulé."),
    SceneReadout("shaking_force_h2", "N", "Order-2 amplitude of the pilon over a revolution simulated ahead (as shaking_force_h1).", lambda s: float(orders(s)[1]), label="Pilon, ordre 2", hint="Amplitude de la composante du pilon à deux fois la fréquence de rotation, sur un tour simulé."),
    SceneReadout("shaking_moment", "N·m", "Rocking moment of the moving parts on the block about its centre C (norm of its x0 and y0 components).", lambda s: float(np.hypot(*_block(s)[1][:2])), label="Moment de basculement en C", hint="Moment des pièces mobiles sur le bloc moteur en son centre C, autour des axes x₀ et y₀."),
    SceneReadout("shaking_moment_ref", "N·m", "Course value of the rocking moment at the current angle and speed.", _moment_ref, label="Moment de basculement selon le cours", hint="Moment de basculement en C calculé par le cours à l'angle et à la vitesse actuels."),
    SceneReadout("shaking_moment_max", "N·m", "Largest rocking moment over a revolution simulated ahead.", lambda s: float(orders(s)[2]), label="Moment de basculement maximal", hint="Plus grande valeur du moment de basculement en C sur un tour simulé."),
    SceneReadout("motor_torque", "N·m", "Torque of the motor on the crankshaft (its rotor's own inertia excluded).", lambda s: float(joint_drive(s.model, s.data)[0]), label="Couple moteur Cₘₒₜ", hint="Couple que le moteur transmet au vilebrequin, sans J·θ'' qui accélère son propre rotor : le couple de l'actionneur vaut Cₘₒₜ + J·θ''.", imposed_label="Couple nécessaire Cₘₒₜ", imposed_hint="Couple que le moteur doit transmettre au vilebrequin pour lui imposer sa vitesse, donné par la dynamique inverse (sans celui qui accélère son propre rotor)."),
    SceneReadout("actuator_torque", "N·m", "Torque of the actuator: C_mot plus what accelerates the motor's own rotor, C_act = C_mot + J θ'' (P_ext = C_act ω).", lambda s: float(s.data.qfrc_actuator[0]), label="Couple de l'actionneur Cₘₒₜ + J·θ''", hint="Couple total produit par le moteur, celui qu'il transmet au vilebrequin (Cₘₒₜ) plus J·θ'' qui accélère son propre rotor : la puissance extérieure Pₑₓₜ vaut ce couple multiplié par ω.", imposed_label="Couple nécessaire de l'actionneur Cₘₒₜ + J·θ''", imposed_hint="Couple total que le moteur doit produire, Cₘₒₜ plus J·θ'' pour son propre rotor, donné par la dynamique inverse : la puissance extérieure Pₑₓₜ vaut ce couple multiplié par ω."),
    SceneReadout("closure_error", "m", "Largest distance between a rod's end and its crank pin.", _closure, label="Écart de fermeture des boucles", hint="Plus grande distance entre l'extrémité d'une bielle et son maneton, quasi nulle quand les chaînes restent fermées."),
    *bearings.readouts(BEARINGS),
)  # fmt: skip

FORCE_SCALE = 3e-4
"""Metres of arrow per newton."""
MOMENT_SCALE = 1e-2
"""Metres of arrow per newton-metre."""


def _at_c(vec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(3), np.array([vec[0], vec[1], 0.0])


ARROWS = (
    Arrow("frame_force", "Effort sur le bloc", (220, 60, 60), lambda s: _at_c(_block(s)[0]), FORCE_SCALE, unit="N", point="C", hint="Effort des pièces mobiles sur le bloc moteur, pilon et tamis ensemble (rouge)."),
    Arrow("shaking_moment", "Moment de basculement", (120, 60, 160), lambda s: _at_c(_block(s)[1]), MOMENT_SCALE, unit="N·m", point="C", hint="Moment de basculement des pièces mobiles sur le bloc en C, autour de x₀ et y₀ (violet)."),
)  # fmt: skip
