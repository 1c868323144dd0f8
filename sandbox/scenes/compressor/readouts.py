"""Readouts and arrows of the micro-compressor: pilon and tamis (the force of the moving
parts on the frame), motor torque, closure error, the orders over a revolution and the
course's values at the current θ, θ' and θ''."""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from sandbox.physics.page import Arrow, Bearing
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout
from sandbox.physics.torsors import joint_drive
from sandbox.scenes import bearings
from sandbox.scenes.compressor.course import frame_force, motor_torque
from sandbox.scenes.compressor.cycle import pilon_harmonics


def _force(s: Snapshot) -> np.ndarray:
    """Force of the moving parts on the frame (= −action of the frame), world axes."""
    r, _ = s.support
    return -np.asarray(r)


def _theta(s: Snapshot) -> float:
    return s.joint_qpos("crank")


def _closure(s: Snapshot) -> float:
    d, m = s.data, s.model
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "A_crank")
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "A_rod")
    return float(np.linalg.norm(d.site_xpos[a] - d.site_xpos[b]))


def _alpha(s: Snapshot) -> float:
    """θ'' [rad/s²]: the crank's acceleration at this state (0 in steady state)."""
    return float(s.data.qacc[s.model.jnt_dofadr[s.model.joint("crank").id]])


def _reference(s: Snapshot) -> np.ndarray:
    """The course's frame force at the current θ, θ' and θ'', shared by pilon_ref and
    tamis_ref."""
    ref = s.cache.get("compressor_ref")
    if ref is None:
        ref = frame_force(_theta(s), s.joint_qvel("crank"), s.values, alpha=_alpha(s))
        s.cache["compressor_ref"] = ref
    return ref


def _motor_torque_ref(s: Snapshot) -> float:
    return motor_torque(_theta(s), s.joint_qvel("crank"), s.values, alpha=_alpha(s))


BEARINGS = (
    Bearing(
        "O", "Palier O", lambda s: bearings.pivot_action(s, "crank")[0],
        (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), ("x₀", "y₀"),
    ),
)  # fmt: skip
"""The crank's pivot on the frame at O, seen as a plain bearing (the course's planar
mechanism: its load is the pivot's resultant)."""

READOUTS = (
    SceneReadout("theta", "rad", "Crank angle θ from x0 to x1 (unwrapped).", _theta, label="Angle du vilebrequin θ", hint="Angle de x₀ à x₁ autour de z₀, qui continue de croître tour après tour."),
    SceneReadout("omega", "rad/s", "Crank speed θ'.", lambda s: s.joint_qvel("crank"), label="Vitesse mesurée du vilebrequin ω", hint="Vitesse de rotation θ' du vilebrequin par rapport au bâti."),
    SceneReadout("lambda", "m", "OB: position of the piston pin on y0.", lambda s: s.joint_qpos("piston"), label="Position du piston λ", hint="Distance OB de l'axe du vilebrequin à l'axe du piston, le long de y₀."),
    SceneReadout("pilon", "N", "Force of the moving parts on the frame along y0 (cylinder axis).", lambda s: float(_force(s)[1]), label="Effet de pilon", hint="Effort des pièces mobiles sur le bâti le long de l'axe du cylindre y₀."),
    SceneReadout("tamis", "N", "Force of the moving parts on the frame along x0 (across).", lambda s: float(_force(s)[0]), label="Effet de tamis", hint="Effort des pièces mobiles sur le bâti perpendiculairement à l'axe du cylindre, le long de x₀."),
    SceneReadout("motor_torque", "N·m", "Torque of the motor on the crank shaft (its rotor's own inertia excluded).", lambda s: float(joint_drive(s.model, s.data)[0]), label="Couple moteur Cₘₒₜ", hint="Couple que le moteur transmet au vilebrequin, sans J·θ'' qui accélère son propre rotor : le couple de l'actionneur vaut Cₘₒₜ + J·θ''.", imposed_label="Couple nécessaire Cₘₒₜ", imposed_hint="Couple que le moteur doit transmettre au vilebrequin pour lui imposer sa vitesse, donné par la dynamique inverse (sans celui qui accélère son propre rotor)."),
    SceneReadout("actuator_torque", "N·m", "Torque of the actuator: C_mot plus what accelerates the motor's own rotor, C_act = C_mot + J θ'' (P_ext = C_act ω).", lambda s: float(s.data.qfrc_actuator[0]), label="Couple de l'actionneur Cₘₒₜ + J·θ''", hint="Couple total produit par le moteur, celui qu'il transmet au vilebrequin (Cₘₒₜ) plus J·θ'' qui accélère son propre rotor : la puissance extérieure Pₑₓₜ vaut ce couple multiplié par ω.", imposed_label="Couple nécessaire de l'actionneur Cₘₒₜ + J·θ''", imposed_hint="Couple total que le moteur doit produire, Cₘₒₜ plus J·θ'' pour son propre rotor, donné par la dynamique inverse : la puissance extérieure Pₑₓₜ vaut ce couple multiplié par ω."),
    SceneReadout("closure_error", "m", "Distance between the rod's end and the crank pin A.", _closure, label="Écart de fermeture en A", hint="Distance entre l'extrémité de la bielle et le maneton A du vilebrequin, quasi nulle quand la chaîne reste fermée."),
    SceneReadout("pilon_h1", "N", "Order-1 amplitude of the pilon over a revolution (simulated ahead in steady state, on the loop at the current speed during a speed change).", lambda s: float(pilon_harmonics(s)[0, 1]), label="Pilon, ordre 1", hint="Amplitude de la composante du pilon à la fréquence de rotation, sur un tour de vilebrequin."),
    SceneReadout("pilon_h2", "N", "Order-2 amplitude of the pilon over a revolution (as pilon_h1).", lambda s: float(pilon_harmonics(s)[0, 2]), label="Pilon, ordre 2", hint="Amplitude de la composante du pilon à deux fois la fréquence de rotation, sur un tour."),
    SceneReadout("tamis_h1", "N", "Order-1 amplitude of the tamis over a revolution (as pilon_h1).", lambda s: float(pilon_harmonics(s)[1, 1]), label="Tamis, ordre 1", hint="Amplitude de la composante du tamis à la fréquence de rotation, sur un tour."),
    SceneReadout("pilon_ref", "N", "Course value of the pilon at the current θ, θ' and θ'' (exact slider-crank; θ'' terms during a speed change).", lambda s: float(_reference(s)[1]), label="Pilon selon le cours", hint="Pilon calculé par le cours pour le système bielle-manivelle exact, à l'angle, à la vitesse et à l'accélération actuels."),
    SceneReadout("tamis_ref", "N", "Course value of the tamis at the current θ, θ' and θ'' (as pilon_ref).", lambda s: float(_reference(s)[0]), label="Tamis selon le cours", hint="Tamis calculé par le cours pour le système bielle-manivelle exact, à l'angle, à la vitesse et à l'accélération actuels."),
    SceneReadout("motor_torque_ref", "N·m", "Course value of C_mot at the current θ, θ' and θ'' (virtual power; (dT/dt)/ω at constant speed).", _motor_torque_ref, label="Couple moteur selon le cours", hint="Couple Cₘₒₜ calculé par les puissances, égal à (dT/dt)/ω à vitesse constante."),
    *bearings.readouts(BEARINGS),
)  # fmt: skip

ARROW_SCALE = 2e-4
"""Metres of arrow per newton."""


def _at_o(vec: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(3), np.array([vec[0], vec[1], 0.0])


ARROWS = (
    Arrow("pilon", "Pilon", (220, 60, 60), lambda s: _at_o([0.0, _force(s)[1]]), ARROW_SCALE, unit="N", point="O", hint="Effet de pilon : effort des pièces mobiles sur le bâti le long de y₀ (rouge)."),
    Arrow("tamis", "Tamis", (60, 140, 220), lambda s: _at_o([_force(s)[0], 0.0]), ARROW_SCALE, unit="N", point="O", hint="Effet de tamis : effort des pièces mobiles sur le bâti le long de x₀ (bleu)."),
    Arrow("frame_force", "Pilon + tamis", (120, 60, 160), lambda s: _at_o(_force(s)), ARROW_SCALE, unit="N", point="O", hint="Effort total des pièces mobiles sur le bâti (violet)."),
)  # fmt: skip
