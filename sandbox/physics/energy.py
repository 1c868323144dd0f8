"""Energies and powers of the mechanism, and the kinetic-energy theorem they check.

T (with the motor rotors' armature), V (weight and joint springs), P_ext, P_int and
P_acc [J, W] are pure functions of (model, data) in R0 (Galilean).

The kinetic-energy theorem checked on the generic readouts:
dT/dt = P_ext + P_int + P_frame: the power of the accelerations ``P_acc`` (= dT/dt)
equals the powers of the outside actions and of the inter-efforts plus the power of the
frame's reactions, which is 0 for perfect fixed joints. What is left over is shown by
the readout panel as a check of the model's hypotheses.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import mujoco

from sandbox.physics.kinematics import Kinematics, ensure_kinematics, select_bodies
from sandbox.physics.mechanism import gravity_vector, structure


def frame_power(values: Mapping[str, float]) -> float:
    """Power of the frame's reactions P_frame = P_acc − P_ext − P_int [W].

    Args:
        values: Readouts by name, including ``P_acc``, ``P_ext`` and ``P_int`` (a missing
            one gives nan).
    """
    p_acc = values.get("P_acc", math.nan)
    return p_acc - values.get("P_ext", math.nan) - values.get("P_int", math.nan)


def kinetic_energy(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    bodies: Iterable[int] | None = None,
    *,
    kin: Kinematics | None = None,
) -> float:
    """T = Σ ½ m v_G² + ½ ω·I_G ω, plus ½ Σ armature q̇² (motor rotors, whole mechanism)."""
    k = ensure_kinematics(model, data, kin)
    if bodies is None:
        v, m, i_omega, omega = k.v_g_b, k.mass_b, k.i_omega_b, k.omega_b
    else:
        b = select_bodies(k, bodies)
        v, m, i_omega, omega = k.v_g[b], model.body_mass[b], k.i_omega[b], k.omega[b]
    t = 0.5 * (m * (v * v).sum(1)).sum() + 0.5 * (i_omega * omega).sum()
    if bodies is None:
        t += 0.5 * float(model.dof_armature @ (data.qvel * data.qvel))
    return float(t)


def potential_energy(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Weight (−Σ m g·OG) plus hinge and slide joint springs ½ k (q − q_ref)²."""
    st = structure(model)
    b = st.bodies
    v = -float((model.body_mass[b] * (data.xipos[b] @ gravity_vector(model))).sum())
    if not model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_SPRING:
        k = model.jnt_stiffness[st.scalar_joints]
        if k.any():
            a = st.scalar_qpos
            stretch = data.qpos[a] - model.qpos_spring[a]
            v += 0.5 * float(k @ (stretch * stretch))
    return v


def powers(
    model: mujoco.MjModel, data: mujoco.MjData, *, kin: Kinematics | None = None
) -> dict[str, float]:
    """P_ext and P_int [W] (see the module and docs/reference.md for the split)."""
    k = ensure_kinematics(model, data, kin)
    qv = data.qvel
    p_grav = float((k.mass_b * (k.v_g_b @ k.gravity)).sum())
    p_xfrc = 0.0
    if data.xfrc_applied.any():
        xf = data.xfrc_applied[k.bodies]
        p_xfrc = float((xf[:, :3] * k.v_g_b).sum() + (xf[:, 3:] * k.omega_b).sum())
    p_ext = (
        p_grav + p_xfrc + float(qv @ (data.qfrc_actuator + data.qfrc_applied + data.qfrc_gravcomp))
    )
    p_int = float(qv @ (data.qfrc_passive - data.qfrc_gravcomp + data.qfrc_constraint))
    return {"P_ext": p_ext, "P_int": p_int}


def acceleration_power(
    model: mujoco.MjModel, data: mujoco.MjData, *, kin: Kinematics | None = None
) -> float:
    """P_acc = Σ {D_i}⊗{V_i} = Σ m a_G·v_G + (I_G α + ω ∧ I_G ω)·ω, plus the motor
    rotors' Σ armature q̇ q̈ (so that P_acc = dT/dt with T as above)."""
    k = ensure_kinematics(model, data, kin)
    return float(
        (k.mass_b * (k.a_g_b * k.v_g_b).sum(1)).sum()
        + (k.delta_g_b * k.omega_b).sum()
        + model.dof_armature @ (data.qvel * data.qacc)
    )
