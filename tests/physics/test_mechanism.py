"""The shared pieces of the generic readouts: the mechanism's structure (bodies, joints by
type, gravity), the kinematics helpers, and the wrenches of joint forces and of MuJoCo's
com-based spatial forces reduced at O."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from sandbox.mechanics.vectors import cross
from sandbox.physics.kinematics import (
    Kinematics,
    cached_kinematics,
    ensure_kinematics,
    select_bodies,
)
from sandbox.physics.mechanism import (
    JointGroups,
    Structure,
    gravity_vector,
    joint_groups,
    structure,
)
from sandbox.physics.torsors import dof_wrenches, spatial_at_origin

TREE = """
<mujoco>
  <worldbody>
    <body name="fixed" pos="0 0 2"><geom type="sphere" size="0.05" mass="1"/></body>
    <body name="arm" pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1"/>
      <body name="slider" pos="0.3 0 0">
        <joint name="slide" type="slide" axis="1 0 0"/>
        <geom type="box" size="0.05 0.04 0.03" mass="0.5"/>
        <body name="ball" pos="0.1 0 0"><joint type="ball"/>
          <geom type="sphere" size="0.03" mass="0.2"/></body>
      </body>
    </body>
    <body name="free" pos="1 0 1"><freejoint/><geom type="sphere" size="0.05" mass="2"/></body>
  </worldbody>
</mujoco>
"""


def _model() -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(TREE)
    data = mujoco.MjData(model)
    data.qvel[:] = np.linspace(0.1, 0.9, model.nv)
    mujoco.mj_forward(model, data)
    return model, data


def _id(model: mujoco.MjModel, name: str) -> int:
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)


def test_structure_is_the_moving_bodies_and_those_hanging_from_the_frame_once_per_model():
    model, _ = _model()
    st = structure(model)
    assert isinstance(st, Structure) and structure(model) is st
    names = {model.body(int(b)).name for b in st.bodies}
    assert names == {"arm", "slider", "ball", "free"}  # not the world, not the welded body
    assert {model.body(int(b)).name for b in st.children} == {"arm", "free"}
    assert len(st.scalar_joints) == 2  # the hinge and the slide: those a spring may act in
    assert not st.bodies.flags.writeable


def test_joint_groups_sort_the_joints_of_some_bodies_by_type():
    model, _ = _model()
    bodies = np.array([_id(model, "arm"), _id(model, "ball")])
    g = joint_groups(model, bodies)
    assert isinstance(g, JointGroups) and joint_groups(model, bodies) is g
    assert g.hinge is not None and g.ball is not None
    assert g.slide is None and g.free is None
    assert g.ball_dofs.shape == (1, 3)


def test_gravity_vector_is_zero_when_weight_is_neglected():
    model, _ = _model()
    assert gravity_vector(model) == pytest.approx([0.0, 0.0, -9.81])
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_GRAVITY)
    assert gravity_vector(model) == pytest.approx([0.0, 0.0, 0.0])


def test_kinematics_helpers_share_one_computation_and_select_bodies():
    model, data = _model()
    k = Kinematics(model, data)
    assert ensure_kinematics(model, data, k) is k
    assert isinstance(ensure_kinematics(model, data, None), Kinematics)
    cache: dict = {}
    assert cached_kinematics(model, data, cache) is cached_kinematics(model, data, cache)
    assert cached_kinematics(model, data, None) is not cached_kinematics(model, data, None)
    assert list(select_bodies(k, None)) == list(k.bodies)
    assert list(select_bodies(k, [_id(model, "free")])) == [_id(model, "free")]


def test_dof_wrenches_turn_joint_forces_into_a_wrench_at_o():
    model, data = _model()
    force = np.zeros(model.nv)
    hinge = model.jnt_dofadr[model.joint("hinge").id]
    force[hinge] = 2.0
    r, m = dof_wrenches(model, data, force, np.array([_id(model, "arm")]))
    assert r == pytest.approx([0.0, 0.0, 0.0])
    assert m == pytest.approx(2.0 * data.xaxis[model.joint("hinge").id])
    slide = model.joint("slide").id
    force[:] = 0.0
    force[model.jnt_dofadr[slide]] = 3.0
    r, m = dof_wrenches(model, data, force, np.array([_id(model, "slider")]))
    f = 3.0 * data.xaxis[slide]
    assert r == pytest.approx(f)
    assert m == pytest.approx(cross(data.xanchor[slide], f))


def test_spatial_at_origin_moves_a_com_based_wrench_to_o():
    model, data = _model()
    b = _id(model, "free")
    wrench = np.array([0.1, 0.2, 0.3, 1.0, -2.0, 0.5])  # [torque at c; force]
    r, m = spatial_at_origin(model, data, b, wrench)
    c = data.subtree_com[model.body_rootid[b]]
    assert r == pytest.approx(wrench[3:])
    assert m == pytest.approx(wrench[:3] + np.cross(c, wrench[3:]))
