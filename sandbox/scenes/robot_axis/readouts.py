"""Readouts and arrows of the robot axis: the state of a snapshot (one instant: the torque
applied from it on, the speeds and accelerations there), the motor torque against the
course's, the reducer's loss, the
kinetic-energy theorem, the forces on the carriage and the generic powers of the course's
machine (the ``mechanism`` hook)."""

from __future__ import annotations

import math

import numpy as np

from sandbox.mechanics.robot_axis import equivalent_inertia, free_axis_frequency, motor_torque
from sandbox.physics.page import Arrow
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout
from sandbox.scenes.robot_axis.course import axis_of, flexible


def _state(s: Snapshot) -> dict[str, float]:
    """ω_m, ω̇_m, V_ch, a_ch, y, v, V_2, V̇_2 and C_m of the snapshot (cached per snapshot)."""
    cached = s.cache.get("robot_axis")
    if cached is not None:
        return cached
    m, d, v = s.model, s.data, s.values
    r = v["R_p"] * v["k"]
    v_ch, a_ch = float(d.qvel[0]), float(d.qacc[0])
    y = dy = ddy = 0.0
    if m.nv > 1:
        y, dy, ddy = float(d.qpos[1]), float(d.qvel[1]), float(d.qacc[1])
    out = {
        "omega_m": v_ch / r,
        "omega_m_dot": a_ch / r,
        "V_ch": v_ch,
        "a_ch": a_ch,
        "y": y,
        "v": dy,
        "V_2": v_ch + dy,
        "V_2_dot": a_ch + ddy,
        "C_m": float(d.actuator_force[0]),
    }
    s.cache["robot_axis"] = out
    return out


def _c_m(s: Snapshot) -> float:
    """C_m: the torque the motor applies from the snapshot's instant on (what MuJoCo
    applies in the step starting there), so that C_m ω_m is the row's P_motor."""
    return _state(s)["C_m"]


def _loss(s: Snapshot) -> float:
    """Power lost in the simulated reducer [W]: (1 − ρ) C_in ω_m, C_in = C_m − (J_m + J_r) ω̇_m
    − f_v ω_m the torque entering it (driving mode; negative while the load drives back)."""
    st, v = _state(s), s.values
    c_in = st["C_m"] - (v["J_m"] + v["J_r"]) * st["omega_m_dot"] - v["f_v"] * st["omega_m"]
    return (1.0 - v["eta"]) * c_in * st["omega_m"]


def _c_m_ref(s: Snapshot) -> float:
    """Course 6.3 (with 6.4's ρ): J_eq ω̇_m + f_v ω_m − R_p k (K_t y + μ_t v), from the
    simulated motion at the snapshot's instant (its acceleration that of the torque
    applied from it on, as C_m); ρ divides the reducer's output torque when driving and
    multiplies it when braking."""
    st, v = _state(s), s.values
    return float(
        motor_torque(
            axis_of(v), st["omega_m"], st["omega_m_dot"], y=st["y"], v=st["v"],
            flexible=flexible(v), rho=v["eta"],
        )
    )  # fmt: skip


def mechanism(s: Snapshot, out: dict[str, float]) -> None:
    """The generic T, P_acc, P_ext and P_int of the mechanism (course 6.4), from those of
    the simulated chain, which carries the motor's side scaled by ρ (ρ (J_m + J_r),
    ρ f_v, ρ C_m): T and dT/dt get back the (1 − ρ) (J_m + J_r) share of the motor and
    reducer, P_ext is C_m ω_m, and P_int gets the friction's (1 − ρ) f_v ω_m² share and
    the reducer's loss. dT/dt − P_ext − P_int is unchanged (the frame's power: 0 with
    perfect joints). Nothing changes for ρ = 1."""
    v = s.values
    lost = 1.0 - v["eta"]
    if lost == 0.0:
        return
    st = _state(s)
    w, j = st["omega_m"], v["J_m"] + v["J_r"]
    if "T" in out:
        out["T"] += 0.5 * lost * j * w * w
    if "P_acc" in out:
        out["P_acc"] += lost * j * w * st["omega_m_dot"]
    if "P_ext" in out:
        out["P_ext"] += lost * st["C_m"] * w
    if "P_int" in out:
        out["P_int"] -= lost * v["f_v"] * w * w + _loss(s)


def _kinetic(s: Snapshot) -> float:
    """E_c = ½ J_eq ω_m² + ½ M2 V_2² (rigid arm: ½ J_eq ω_m², M2 in J_eq) [J]."""
    st, v = _state(s), s.values
    flex = flexible(v)
    t = 0.5 * equivalent_inertia(axis_of(v), flexible=flex) * st["omega_m"] ** 2
    return t + 0.5 * v["M2"] * st["V_2"] ** 2 if flex else t


def _residual(s: Snapshot) -> float:
    """dE_c/dt − (C_m ω_m − f_v ω_m² − K_t y v − μ_t v² − P_loss) [W] (course 6.3)."""
    st, v = _state(s), s.values
    flex = flexible(v)
    rate = equivalent_inertia(axis_of(v), flexible=flex) * st["omega_m"] * st["omega_m_dot"]
    if flex:
        rate += v["M2"] * st["V_2"] * st["V_2_dot"]
    p = st["C_m"] * st["omega_m"] - v["f_v"] * st["omega_m"] ** 2
    p -= v["K_t"] * st["y"] * st["v"] + v["mu_t"] * st["v"] ** 2
    return rate - (p - _loss(s))


def _arm_force(s: Snapshot) -> float:
    """Force of the arm on the carriage along y [N]: K_t y + μ_t v (0 for a rigid arm)."""
    st, v = _state(s), s.values
    return v["K_t"] * st["y"] + v["mu_t"] * st["v"] if s.model.nv > 1 else 0.0


def _belt_force(s: Snapshot) -> float:
    """Force of the belt on the carriage along y [N]: M1 a_ch minus the arm's and the end
    stops' forces (rigid arm: (M1 + M2) a_ch, the arm riding on the carriage)."""
    st, v = _state(s), s.values
    mass = v["M1"] if s.model.nv > 1 else v["M1"] + v["M2"]
    return mass * st["a_ch"] - _arm_force(s) - _stop_force(s)


def _stop_force(s: Snapshot) -> float:
    """Force of the end stops on the carriage along y [N] (0 away from them): the slide's
    limit force, the only constraint of the model."""
    return float(s.data.qfrc_constraint[0])


def _swing(s: Snapshot) -> float:
    """Amplitude [m] of the arm's oscillation against the free chain: √(y² + (v/ω)²) with
    ω = √(K_t (1/M2 + (R_p k)²/J_eq)) (the envelope of a free oscillation y = A cos ωt)."""
    st, v = _state(s), s.values
    if s.model.nv < 2:
        return 0.0
    omega = free_axis_frequency(axis_of(v))
    return math.hypot(st["y"], st["v"] / omega)


def _dissipated(s: Snapshot) -> float:
    """f_v ω_m² + μ_t v² + K_t y v [W]: minus the course's P_int (friction, arm)."""
    st, v = _state(s), s.values
    return v["f_v"] * st["omega_m"] ** 2 + v["mu_t"] * st["v"] ** 2 + v["K_t"] * st["y"] * st["v"]


def _j_eq(s: Snapshot) -> float:
    """Inertia the simulated chain presents to the motor shaft [kg·m²], read from the compiled
    model: (R_p k)² × (armature + M1, + M2 when the arm is welded to the carriage) / ρ. With
    ρ = 1 it is the course's J_eq; a lossy reducer makes the motor feel J_m + J_r + (the rest)/ρ."""
    m, v = s.model, s.values
    carriage = s.body_id("carriage")
    bodies = m.body_mass[carriage] if m.nv > 1 else m.body_subtreemass[carriage]
    return (v["R_p"] * v["k"]) ** 2 * float(m.dof_armature[0] + bodies) / v["eta"]


READOUTS = (
    SceneReadout("J_eq", "kg·m²", "Equivalent inertia the simulated chain presents to the motor (course 6.3; M2 included for a rigid arm; the reducer's share divided by its efficiency).", _j_eq, label="Inertie équivalente Jₑq", hint="Inertie d'un volant sur l'arbre moteur qui aurait la même énergie cinétique que la chaîne rigide (bras exclu s'il est souple)."),
    SceneReadout("omega_m", "rad/s", "Motor speed ω_m = V_ch / (R_p k).", lambda s: _state(s)["omega_m"], label="Vitesse du moteur ωₘ", hint="Vitesse de rotation de l'arbre moteur, liée à celle du chariot par Vch = Rₚ·k·ωₘ."),
    SceneReadout("V_ch", "m/s", "Speed of the carriage along y.", lambda s: _state(s)["V_ch"], label="Vitesse du chariot Vch", hint="Vitesse du chariot le long de l'axe y, entraîné par la courroie."),
    SceneReadout("V_2", "m/s", "Speed of the arm's mass M2 along y.", lambda s: _state(s)["V_2"], label="Vitesse des parties flexibles V₂", hint="Vitesse de la masse M₂ du bras, qui oscille autour de celle du chariot si le bras est souple."),
    SceneReadout("deflection", "m", "Deflection of the arm y_2 - y_ch.", lambda s: _state(s)["y"], label="Déformation du bras y₂ − ych", hint="Écart entre la position de la masse M₂ du bras et celle du chariot, nul pour un bras rigide."),
    SceneReadout("arm_swing", "m", "Amplitude of the arm's oscillation: √(y² + (v/ω)²), ω the arm's frequency against the free chain.", _swing, label="Amplitude d'oscillation du bras", hint="Enveloppe de la déformation du bras, calculée à partir de sa déformation et de sa vitesse par rapport au chariot."),
    SceneReadout("C_m", "N·m", "Torque the motor applies to its shaft from this instant on (what the simulation applies in the step starting there): C_m ω_m is P_motor on the same row. A speed servo's torque held over a step depends on the timestep (its peak on the default move: 4.98 N·m at 1 ms, 4.80 at 0.1 ms).", _c_m, label="Couple moteur appliqué Cₘ", hint="Couple que le moteur applique à son arbre à cet instant : multiplié par ωₘ, il donne la puissance du moteur.", imposed_label="Couple nécessaire Cₘ", imposed_hint="Couple que le moteur doit appliquer à son arbre pour imposer le mouvement du chariot, donné par la dynamique inverse à cet instant."),
    SceneReadout("C_m_ref", "N·m", "Course value J_eq ω̇_m + f_v ω_m − R_p k (K_t y + μ_t v) from the simulated motion (efficiency ρ on the reducer's output torque).", _c_m_ref, label="Couple moteur selon le cours", hint="Couple Jₑq·ω̇ₘ + fᵥ·ωₘ − Rₚ·k·(Kₜ·y + μₜ·v) calculé avec l'accélération et la déformation simulées, rendement compris."),
    SceneReadout("C_m_gap", "N·m", "C_m minus C_m_ref, both at the same instant: non-zero where the simulated mechanism leaves the course's model (an end stop, the load driving the motor back through a lossy reducer).", lambda s: _c_m(s) - _c_m_ref(s), label="Écart au couple du cours", hint="Différence entre le couple appliqué et celui du cours, qui révèle un modèle différent."),
    SceneReadout("P_motor", "W", "Power of the motor C_m ω_m at the snapshot (the torque applied from it on).", lambda s: _state(s)["C_m"] * _state(s)["omega_m"], label="Puissance du moteur", hint="Puissance que le moteur fournit à son arbre à cet instant : le couple qu'il applique à cet instant multiplié par sa vitesse."),
    SceneReadout("P_loss", "W", "Power lost in the reducer (1 − ρ) × the power entering it (motor driving).", _loss, label="Puissance perdue dans le réducteur", hint="Puissance dissipée par le réducteur, une part 1 − ρ de la puissance qui y entre."),
    SceneReadout("E_c", "J", "Kinetic energy of the course: ½ J_eq ω_m² + ½ M2 V_2², J_eq the course's (6.3, efficiency aside: the kinetic energy does not depend on it; the generic T equals it).", _kinetic, label="Énergie cinétique de la chaîne Ec", hint="Énergie cinétique ½·Jₑq·ωₘ² + ½·M₂·V₂² de toute la chaîne, écrite avec l'inertie équivalente."),
    SceneReadout("energy_residual", "W", "Kinetic-energy theorem residual dE_c/dt − (C_m ω_m + P_int − P_loss) (course 6.3).", _residual, label="Écart au théorème de l'énergie cinétique", hint="Différence entre la dérivée de Ec et la somme des puissances du cours, nulle si le modèle simulé est celui du cours."),
    SceneReadout("F_belt", "N", "Force of the belt on the carriage along y.", _belt_force, label="Effort de la courroie sur le chariot", hint="Effort de la courroie sur le chariot le long de y, qui l'accélère et retient le bras."),
    SceneReadout("F_arm", "N", "Force of the arm on the carriage along y: K_t y + μ_t v.", _arm_force, label="Effort du bras sur le chariot", hint="Effort du ressort et de l'amortisseur du bras sur le chariot le long de y."),
    SceneReadout("P_diss", "W", "f_v ω_m² + μ_t v² + K_t y v: minus the course's inter-effort power.", _dissipated, label="Puissance des frottements et du bras", hint="Puissance fᵥ·ωₘ² + μₜ·v² + Kₜ·y·v, l'opposé de la puissance des inter-efforts du cours."),
    SceneReadout("y_ch", "m", "Position of the carriage's centre along the rail (end stops at -0.05 and 2.05 m).", lambda s: float(s.data.qpos[0]), label="Position du chariot ych", hint="Position du centre du chariot le long du rail, dont les butées sont à −0,05 m et 2,05 m."),
    SceneReadout("F_stop", "N", "Force of the end stops on the carriage along y (0 away from them; outside the course's model).", _stop_force, label="Effort des butées sur le chariot", hint="Effort qu'une butée de fin de rail exerce sur le chariot quand il l'atteint, absent du modèle du cours."),
)  # fmt: skip

ARROW_SCALE = 1e-3
"""Metres of arrow per newton."""


def _carriage_point(s: Snapshot, offset: tuple[float, float, float]) -> np.ndarray:
    """A point of the carriage [m]: C on its top (0, 0, 0.07), B the arm's attachment
    (0.14, 0, 0), offsets from the carriage's centre."""
    return np.asarray(s.data.xpos[s.body_id("carriage")]) + np.array(offset)


ARROWS = (
    Arrow("F_belt", "Courroie sur chariot", (220, 120, 30), lambda s: (_carriage_point(s, (0.0, 0.0, 0.07)), np.array([0.0, _belt_force(s), 0.0])), ARROW_SCALE, unit="N", point="C", hint="Effort de la courroie sur le chariot, au point C (orange)."),
    Arrow("F_arm", "Bras sur chariot", (60, 160, 80), lambda s: (_carriage_point(s, (0.14, 0.0, 0.0)), np.array([0.0, _arm_force(s), 0.0])), ARROW_SCALE, unit="N", point="B", hint="Effort du bras sur le chariot, à son attache B (vert)."),
)  # fmt: skip
