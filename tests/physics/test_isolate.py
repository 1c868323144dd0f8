"""Isolating a solid: the actions on it sum to its dynamic torsor (PFD per solid)."""

from __future__ import annotations

import numpy as np
import pytest

from sandbox.physics import isolate
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene, resolve


@pytest.mark.parametrize("target", ["compressor", "rotor"])
def test_actions_sum_to_the_dynamic_torsor_of_each_solid(target):
    sim = Simulation(resolve(target))
    sim.advance(0.003)
    sim.snapshot(["sup_R_x"])
    for solid in isolate.solids(sim.model):
        d = isolate.dynamic_torsor(sim.model, sim.data, solid)
        acts = isolate.actions(sim.model, sim.data, solid)
        r = sum(a.resultant for a in acts)
        m = sum(a.moment for a in acts)
        scale = max(np.abs(d.resultant).max(), 1.0)
        assert np.abs(r - d.resultant).max() < 1e-9 * scale
        assert np.abs(m - d.moment).max() < 1e-9 * scale


def test_piston_sees_the_frame_and_the_rod():
    """Course exercise: isolating the piston 3 shows the action of 0 (slide) and of 2."""
    sim = Simulation(get_scene("compressor"))
    sim.advance(0.002)
    sim.snapshot(["sup_R_x"])
    import mujoco

    piston = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, "piston")
    labels = [a.label for a in isolate.actions(sim.model, sim.data, piston)]
    assert labels == ["0 (bâti) → solide (glissière)", "rod → solide"]
    slide = isolate.actions(sim.model, sim.data, piston)[0]
    assert abs(slide.resultant[1]) < 1e-9 * np.abs(slide.resultant).max()  # no force along y0


def test_balance_reduces_everything_at_g_and_closes_the_pfd():
    """The panel's numbers: G, {D} and the actions moved to G (M_G = M_O + R ∧ OG), and
    the PFD's relative residual."""
    sim = Simulation(get_scene("compressor"))
    sim.advance(0.002)
    sim.snapshot(["sup_R_x"])
    for solid in isolate.solids(sim.model):
        b = isolate.balance(sim.model, sim.data, solid)
        members = isolate.members(sim.model, solid)
        mass = sim.model.body_mass[members]
        g = (mass[:, None] * sim.data.xipos[members]).sum(0) / mass.sum()
        assert np.allclose(b.centre, g)
        d = isolate.dynamic_torsor(sim.model, sim.data, solid)
        assert np.allclose(b.dynamic.moment, d.moment + np.cross(d.resultant, g))
        acts = isolate.actions(sim.model, sim.data, solid)
        assert [a.label for a in b.actions] == [a.label for a in acts]
        assert np.allclose(b.actions[0].moment, acts[0].moment + np.cross(acts[0].resultant, g))
        assert b.residual < 1e-9


def test_pfd_gap_by_hand_is_relative_to_the_largest_torsor():
    d = isolate.Action("{D}", np.array([3.0, 4.0, 0.0]), np.zeros(3))
    acts = [
        isolate.Action("a", np.array([1.0, 0.0, 0.0]), np.zeros(3)),
        isolate.Action("b", np.array([2.0, 4.0, 5.0]), np.zeros(3)),
    ]
    assert isolate.pfd_gap(d, acts) == pytest.approx((5.0, 0.0))  # |(0, 0, 5)|
    # over the largest resultant, |(2, 4, 5)| = √45, not over |{D}|
    assert isolate.pfd_residual(d, acts) == pytest.approx(5.0 / 45**0.5)
    assert isolate.pfd_residual(d, []) == pytest.approx(1.0)
    # a solid at constant speed: {D} = 0 and two opposite actions of round-off size
    still = isolate.Action("{D}", np.zeros(3), np.zeros(3))
    tiny = [
        isolate.Action("a", np.array([1e-300, 0.0, 0.0]), np.zeros(3)),
        isolate.Action("b", np.array([-1e-300, 0.0, 0.0]), np.zeros(3)),
    ]
    assert isolate.pfd_residual(still, tiny) == 0.0
    assert isolate.pfd_residual(still, []) == 0.0


def test_the_heavy_tops_weight_reads_minus_m_g_along_z0():
    """Issue 21: the planar table read "poids | 0 | 0 | 0 | 0" for the heavy top."""
    import mujoco

    sim = Simulation(get_scene("heavy_gyroscope"))
    sim.advance(0.2)
    sim.snapshot(["sup_R_x"])
    rotor = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, "rotor")
    b = isolate.balance(sim.model, sim.data, rotor)
    (weight,) = [a for a in b.actions if a.label == "poids"]
    m, g = float(sim.model.body_subtreemass[rotor]), 9.81
    assert weight.resultant == pytest.approx([0.0, 0.0, -m * g], abs=1e-12)
    assert np.linalg.norm(weight.moment) < 1e-12  # at G, the weight has no moment
    assert b.residual < 1e-9


def test_the_rotors_rotating_bearing_force_is_m_e_omega_squared_and_fixed_in_the_rotor():
    """A static unbalance m e at ω: the frame's action on the rotor is m e ω², in the
    plane of the disc, turning with it (constant in B1)."""
    import math

    import mujoco

    sim = Simulation(get_scene("rotor"), values={"mass1_g": 0.0, "mass2_g": 0.0})
    sim.advance(0.2)
    rotor = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, "rotor")
    seen = []
    for _ in range(3):
        sim.advance(0.013)
        sim.snapshot(["sup_R_x"])
        b = isolate.balance(sim.model, sim.data, rotor)
        frame = b.actions[0]
        omega = abs(float(sim.data.qvel[0]))
        m = float(sim.model.body_subtreemass[rotor])
        e = math.hypot(*b.centre[1:])  # G off the axis x0
        assert np.linalg.norm(frame.resultant) == pytest.approx(m * e * omega**2, rel=1e-6)
        assert abs(frame.resultant[0]) < 1e-9 * np.linalg.norm(frame.resultant)
        seen.append(b.axes.T @ frame.resultant)
        assert b.residual < 1e-9
    assert np.ptp(np.array(seen), axis=0).max() < 1e-6 * np.linalg.norm(seen[0])


def test_the_engines_pfd_gap_is_round_off_of_its_largest_action():
    """Issue 21: divided by {D} (0 for the crank at constant speed), the engine's relative
    gap read 3×10²⁸⁶."""
    sim = Simulation(get_scene("engine"))
    sim.advance(0.1)
    sim.snapshot(["sup_R_x"])
    for solid in isolate.solids(sim.model):
        b = isolate.balance(sim.model, sim.data, solid)
        assert b.residual <= 1e-9, (solid, b.residual)
        at_o = isolate.balance(sim.model, sim.data, solid, np.zeros(3))
        assert at_o.residual <= 1e-9 and np.allclose(at_o.point, 0.0)


@pytest.mark.parametrize("motion", ["free", "imposed"])
def test_a_frictionless_joint_has_no_moment_about_its_own_axis(motion):
    """The compressor's crank at 6000 tr/min, free (its speed ripples: θ'' ≠ 0): the
    motor's rotor (J = 0,02 kg·m², a joint armature) takes J·θ'' of the actuator's torque,
    and the crank receives the rest, C_mot = C_act − J·θ''. The pivot only reacts: its
    moment about its own axis is 0 (it read −J·θ'', 1 N·m, when the motor's action was
    the actuator's torque)."""
    from sandbox.physics.torsors import joint_drive

    sim = Simulation(get_scene("compressor"), values={"speed_rpm": 6000.0}, motion=motion)
    sim.advance(0.0371)
    sim.snapshot(["sup_R_x"])
    model, data = sim.model, sim.data
    crank = model.body("crank").id
    joint = int(model.body_jntadr[crank])
    dof = int(model.jnt_dofadr[joint])
    acts = {a.label: a for a in isolate.actions(model, data, crank)}
    pivot = acts["0 (bâti) → solide (pivot)"]
    motor = acts["moteur"]
    axis, anchor = data.xaxis[joint], data.xanchor[joint]
    about = lambda a: float((a.moment + np.cross(a.resultant, anchor)) @ axis)  # noqa: E731
    actuator = float(data.qfrc_actuator[dof])
    inertia = float(model.dof_armature[dof] * data.qacc[dof])
    assert abs(about(pivot)) <= 1e-9 * abs(actuator)
    assert about(motor) == pytest.approx(float(joint_drive(model, data)[dof]), rel=1e-12)
    assert about(motor) == pytest.approx(actuator - inertia, rel=1e-12)
    if motion == "free":  # the difference the page must name: J·θ'' of the torque
        assert abs(inertia) > 1e-3 * abs(actuator)
    d = isolate.dynamic_torsor(model, data, crank)
    total = sum(a.moment for a in acts.values())
    assert np.abs(total - d.moment).max() < 1e-9 * max(np.abs(d.moment).max(), 1.0)
