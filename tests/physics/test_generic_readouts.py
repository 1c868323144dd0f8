"""Generic readouts on small inline MJCF models, against hand computations.

Tolerances: identities (PFD, energy theorem at an instant) close to 1e-9 of the
magnitudes; finite differences and integrated energy to 1e-4 relative.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from sandbox.physics import readouts as R
from sandbox.physics.energy import acceleration_power, kinetic_energy, potential_energy
from sandbox.physics.kinematics import body_accelerations, body_velocities
from sandbox.physics.torsors import (
    actuator_torsor,
    applied_torsor,
    dynamic_torsor,
    gravity_torsor,
    support_torsor,
)

CHAIN = """
<mujoco>
  <option timestep="0.0005" integrator="RK4"/>
  <worldbody>
    <geom type="plane" size="3 3 .1"/>
    <body name="a" pos="0 0 1">
      <joint name="j1" type="hinge" axis="0 1 0" {damping}/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0.1" size="0.03" mass="1.2"/>
      <body name="b" pos="0.3 0 0.1">
        <joint name="j2" type="slide" axis="1 0 0"/>
        <geom type="box" size="0.05 0.04 0.03" mass="0.7"/>
        <body name="c" pos="0.1 0 0">
          <joint name="j3" type="ball"/>
          <geom type="capsule" fromto="0 0 0 0 0.2 -0.1" size="0.02" mass="0.4"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="j1"/><motor joint="j2"/></actuator>
</mujoco>
"""

MIXED = """
<mujoco>
  <option timestep="0.001"/>
  <worldbody>
    <geom type="plane" size="2 2 .1" friction="0.6"/>
    <body name="box" pos="0.3 0 0.05"><freejoint/>
      <geom type="box" size="0.1 0.05 0.05" mass="2"/></body>
    <body name="hung" pos="1 0 1"><freejoint/>
      <geom type="sphere" size="0.05" mass="0.5"/></body>
    <body name="p"><joint name="k1" type="hinge" axis="0 1 0" damping="0.3"/>
      <geom type="capsule" fromto="0 0 1 0.3 0 1" size="0.02" mass="1"/>
      <body><joint name="k2" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0.3 0 1 0.6 0 1" size="0.02" mass="1"/></body></body>
  </worldbody>
  <equality><connect body1="hung" body2="world" anchor="0 0 0.2"/></equality>
  <actuator><motor joint="k1"/><motor joint="k2"/></actuator>
</mujoco>
"""

UNBALANCED = """
<mujoco>
  <option gravity="0 0 0"/>
  <worldbody><body><joint name="spin" type="hinge" axis="1 0 0"/>
    <geom type="cylinder" fromto="-0.1 0 0 0.1 0 0" size="0.02" mass="1"/>
    <geom type="sphere" pos="0 0.05 0" size="0.001" mass="0.01"/></body></worldbody>
</mujoco>
"""


def _state(
    xml: str, seed: int = 0, steps: int = 200, **fmt
) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(xml.format(**fmt) if fmt else xml)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    data.qvel[:] = rng.normal(size=model.nv)
    data.ctrl[:] = rng.normal(size=model.nu)
    mujoco.mj_step(model, data, steps)
    R.prepare(model, data, ["dyn_R_x"])
    return model, data


def test_body_motion_matches_mujoco_object_functions():
    model, data = _state(CHAIN, damping="")
    v_g, omega = body_velocities(model, data)
    a_g, alpha = body_accelerations(model, data)
    res = np.zeros(6)
    for b in range(1, model.nbody):
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, res, 0)
        np.testing.assert_allclose(res[3:], v_g[b], atol=1e-10)
        np.testing.assert_allclose(res[:3], omega[b], atol=1e-10)
        mujoco.mj_objectAcceleration(model, data, mujoco.mjtObj.mjOBJ_BODY, b, res, 0)
        np.testing.assert_allclose(res[3:] + model.opt.gravity, a_g[b], atol=1e-9)
        np.testing.assert_allclose(res[:3], alpha[b], atol=1e-9)


def test_kinetic_energy_is_half_qdot_m_qdot():
    model, data = _state(CHAIN, damping="")
    mass = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass)
    assert kinetic_energy(model, data) == pytest.approx(
        0.5 * data.qvel @ mass @ data.qvel, rel=1e-12
    )


def test_p_acc_is_dT_dt_by_finite_difference():
    model, data = _state(CHAIN, damping="")
    h = 1e-6
    p_acc = acceleration_power(model, data)
    saved = (data.qpos.copy(), data.qvel.copy())

    def energy_at(dt: float) -> float:
        data.qpos[:], data.qvel[:] = saved
        mujoco.mj_forward(model, data)
        v = data.qvel + dt * data.qacc
        q = data.qpos.copy()
        mujoco.mj_integratePos(model, q, data.qvel + 0.5 * dt * data.qacc, dt)
        data.qpos[:], data.qvel[:] = q, v
        mujoco.mj_forward(model, data)
        return kinetic_energy(model, data)

    dTdt = (energy_at(h) - energy_at(-h)) / (2 * h)
    assert dTdt == pytest.approx(p_acc, rel=1e-4, abs=1e-6)


@pytest.mark.parametrize("xml, fmt", [(CHAIN, {"damping": 'damping="0.5"'}), (MIXED, {})])
def test_energy_theorem_at_every_instant(xml, fmt):
    """P_acc = P_ext + P_int (course 6.2), with motors, damping, contact, equality."""
    model = mujoco.MjModel.from_xml_string(xml.format(**fmt) if fmt else xml)
    data = mujoco.MjData(model)
    data.ctrl[:] = 0.5
    data.qvel[:] = 0.3
    for _ in range(20):
        mujoco.mj_step(model, data, 25)
        R.prepare(model, data, ["P_acc"])
        out = R.compute(model, data, ["P_acc", "P_ext", "P_int"])
        scale = 1.0 + abs(out["P_ext"]) + abs(out["P_int"])
        assert out["P_acc"] == pytest.approx(out["P_ext"] + out["P_int"], abs=1e-9 * scale)
        if model.dof_damping.any() and model.neq == 0:  # only viscous damping: dissipates
            assert out["P_int"] <= 1e-12


def test_perfect_double_pendulum_conserves_T_plus_V():
    model = mujoco.MjModel.from_xml_string(CHAIN.format(damping=""))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    data = mujoco.MjData(model)
    data.qvel[:] = [2.0, 0.5, 1.0, -1.0, 0.5]
    mujoco.mj_forward(model, data)
    e0 = kinetic_energy(model, data) + potential_energy(model, data)
    mujoco.mj_step(model, data, 4000)
    R.prepare(model, data, ["P_int"])
    e1 = kinetic_energy(model, data) + potential_energy(model, data)
    assert e1 == pytest.approx(e0, rel=1e-4)
    assert R.compute(model, data, ["P_int"])["P_int"] == 0.0


@pytest.mark.parametrize("gravity", [True, False])
def test_pfd_closes(gravity):
    """{D} = {frame} + {weight} + {motors} + {applied}, each computed separately."""
    model = mujoco.MjModel.from_xml_string(MIXED)
    if not gravity:
        model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_GRAVITY
    data = mujoco.MjData(model)
    data.ctrl[:] = [0.7, -0.4]
    data.qvel[:6] = [0.0, 0.5, 0.0, 1.0, 2.0, 3.0]
    data.xfrc_applied[1] = [1, 2, 3, 0.1, 0.2, 0.3]
    for _ in range(10):
        mujoco.mj_step(model, data, 50)
        R.prepare(model, data, ["dyn_R_x"])
        d_r, d_m = dynamic_torsor(model, data)
        parts = [
            support_torsor(model, data),
            gravity_torsor(model, data),
            actuator_torsor(model, data),
            applied_torsor(model, data),
        ]
        scale = 1.0 + np.abs(d_r).max() + np.abs(d_m).max()
        np.testing.assert_allclose(d_r, sum(p[0] for p in parts), atol=1e-9 * scale)
        np.testing.assert_allclose(d_m, sum(p[1] for p in parts), atol=1e-9 * scale)
    assert (
        data.ncon > 0 or not gravity
    )  # the box rests on the plane: contact is in the frame's action


def test_unbalanced_rotor_bearing_force_is_m_omega2_r():
    """Course 7.2: the frame pulls the rotor with m ω² Y (weight neglected)."""
    model = mujoco.MjModel.from_xml_string(UNBALANCED)
    data = mujoco.MjData(model)
    data.qvel[0] = 100.0
    mujoco.mj_step(model, data, 37)
    R.prepare(model, data, ["sup_R_x"])
    r, _ = support_torsor(model, data)
    com_radius = 0.01 * 0.05 / 1.01  # G of the whole rotor
    assert np.linalg.norm(r) == pytest.approx(1.01 * 100.0**2 * com_radius, rel=1e-6)


def test_hanging_pendulum_at_rest_is_held_by_its_weight():
    model = mujoco.MjModel.from_xml_string(CHAIN.format(damping=""))
    data = mujoco.MjData(model)
    data.qpos[:] = [np.pi / 2 - np.arctan2(0.1, 0.3), 0, 1, 0, 0, 0][: model.nq]
    R.prepare(model, data, forces=True)
    total = model.body_subtreemass[1]
    r, _ = support_torsor(model, data)
    d_r, _ = dynamic_torsor(model, data)
    np.testing.assert_allclose(r, d_r - total * model.opt.gravity, atol=1e-9)


def test_compute_asks_only_what_is_needed_and_names_valid_ones(monkeypatch):
    model, data = _state(CHAIN, damping="")
    calls = []
    monkeypatch.setattr(R.mujoco, "mj_rnePostConstraint", lambda m, d: calls.append(1))
    R.prepare(model, data, ["T", "kin_R_x"])
    assert calls == []
    R.prepare(model, data, ["sup_M_z"])
    assert calls == [1]
    R.prepare(model, data, forces=True)  # asked by intent (arrows, scene readouts)
    assert calls == [1, 1]
    with pytest.raises(KeyError, match="valid: time, T"):
        R.compute(model, data, ["energy"])
    assert list(R.compute(model, data, ["T", "time"])) == ["T", "time"]


def test_joint_springs_count_in_v_and_t_plus_v_is_conserved(tmp_path):
    """A mass on a slide spring (k = 100 N/m, x0 = 0.1 m): V(0) = ½ k x0² = 0.5 J and
    T + V stays 0.5 J (RK4, dt = 1e-4) within 1e-6 J."""
    from sandbox.physics.simulation import Simulation

    xml = tmp_path / "spring.xml"
    xml.write_text(
        '<mujoco><option timestep="1e-4" integrator="RK4"/><worldbody><body>'
        '<joint type="slide" axis="1 0 0" stiffness="100"/>'
        '<geom type="sphere" size="0.05" mass="1"/></body></worldbody>'
        '<keyframe><key qpos="0.1"/></keyframe></mujoco>'
    )
    sim = Simulation(xml)
    assert sim.readouts(["V"])["V"] == pytest.approx(0.5, rel=1e-12)
    sim.advance(0.37)
    r = sim.readouts(["T", "V"])
    assert r["T"] > 0.1 and r["T"] + r["V"] == pytest.approx(0.5, abs=1e-6)


def test_armature_counts_as_motor_rotor_energy(tmp_path):
    """A motor with rotor inertia (armature) spinning up an arm: T includes ½ J q̇²,
    P_acc = P_ext + P_int = dT/dt, and the PFD still closes on the bodies."""
    import mujoco

    from sandbox.physics.simulation import Simulation

    xml = tmp_path / "motor.xml"
    xml.write_text(
        '<mujoco><option timestep="1e-4" integrator="RK4" gravity="0 0 0"/><worldbody>'
        '<body><joint name="j" type="hinge" axis="0 0 1" armature="0.05"/>'
        '<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1"/></body>'
        '</worldbody><actuator><motor joint="j" gear="1"/></actuator></mujoco>'
    )
    sim = Simulation(xml)
    sim.data.ctrl[0] = 0.7
    sim.advance(0.2)
    names = ["T", "P_acc", "P_ext", "P_int", "dyn_M_z", "sup_M_z"]
    r = sim.readouts(names)
    qv = float(sim.data.qvel[0])
    full = np.zeros((1, 1))
    mujoco.mj_fullM(sim.model, sim.data, full)  # joint-space inertia, armature included
    assert r["T"] == pytest.approx(0.5 * full[0, 0] * qv * qv, rel=1e-9)
    assert full[0, 0] > 0.05
    assert r["P_acc"] == pytest.approx(r["P_ext"] + r["P_int"], rel=1e-9)
    assert r["P_ext"] == pytest.approx(0.7 * qv, rel=1e-9)
    t0, p0 = r["T"], r["P_acc"]
    sim.advance(1e-3)
    r1 = sim.readouts(["T", "P_acc"])
    assert (r1["T"] - t0) / 1e-3 == pytest.approx(0.5 * (p0 + r1["P_acc"]), rel=1e-6)
    # the body receives the motor torque minus the rotor's own inertial torque
    drive = 0.7 - 0.05 * float(sim.data.qacc[0])
    r = sim.readouts(names)
    assert r["dyn_M_z"] == pytest.approx(r["sup_M_z"] + drive, rel=1e-6)


def test_forces_are_asked_for_by_intent_never_by_a_dummy_readout_name():
    """Issue 37: callers once passed ``("sup_R_x", "dyn_R_x")`` to get the forces
    prepared; they say ``forces=True``. No call to snapshot, prepare, data or drawn in
    the package names a torsor component it does not read."""
    import ast
    from pathlib import Path

    package = Path(R.__file__).resolve().parents[1]
    found = []
    for path in package.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
                continue
            if node.func.attr not in {"snapshot", "prepare", "data", "drawn"}:
                continue
            for arg in node.args:
                for leaf in ast.walk(arg):
                    text = leaf.value if isinstance(leaf, ast.Constant) else None
                    if isinstance(text, str) and text.startswith(("sup_", "dyn_")):
                        found.append(f"{path.relative_to(package)}:{node.lineno}")
    assert not found, found
