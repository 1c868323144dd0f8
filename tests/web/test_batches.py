"""Geoms of one kind over several groups drawn as one batched node: unit meshes, which
groups are batched, colours, instance poses, and the messages a frame it saves."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from test_renderer import FakeScene

from sandbox.scenes import get_scene
from sandbox.web.view3d.batches import (
    batches,
    instance_poses,
    linear_colors,
    unit_box,
    unit_cylinder,
    unit_sphere,
)
from sandbox.web.view3d.geoms import geom_shapes
from sandbox.web.view3d.label_layout import Camera
from sandbox.web.view3d.renderer import SceneRenderer


def _volume(verts: np.ndarray, faces: np.ndarray) -> float:
    """The volume the faces enclose (divergence theorem): positive when they look out,
    short of the true one when a face is missing."""
    p = verts.astype(float)
    a, b, c = p[faces[:, 0]], p[faces[:, 1]], p[faces[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


@pytest.mark.parametrize(
    "make, volume, extent",
    [
        (unit_box, 1.0, (0.5, 0.5, 0.5)),
        (unit_cylinder, np.pi, (1.0, 1.0, 0.5)),
        (unit_sphere, 4 / 3 * np.pi, (1.0, 1.0, 1.0)),
    ],
)
def test_unit_meshes_have_the_size_the_scales_assume_and_face_out(make, volume, extent):
    verts, faces = make()
    assert verts.dtype == np.float32 and faces.dtype == np.uint32
    assert np.abs(verts).max(axis=0) == pytest.approx(extent, rel=1e-6)
    # a 32-sided polygon holds 99.4 % of its circle's area: volume within 2 %
    assert _volume(verts, faces) == pytest.approx(volume, rel=0.02)


def test_colours_are_sent_as_linear_light():
    """A batch's bytes are linear light, a single node's are sRGB: mid-grey (sRGB 0.5)
    is 21.4 % of full light, byte 55; sent as 128 it was drawn paler."""
    shape = geom_shapes(mujoco.MjModel.from_xml_string(FIVE_BOXES))[0]
    grey = type(shape)(**{**shape.__dict__, "rgba": (0.5, 0.0, 1.0, 1.0)})
    assert linear_colors([grey]).tolist() == [[55, 0, 255]]


FIVE_BOXES = """
<mujoco>
  <worldbody>
    <body name="a" pos="0 0 0"><joint type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.1 0.1" rgba="1 0 0 1"/></body>
    <body name="b" pos="0 1 0"><joint type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.2 0.1" rgba="0 1 0 1"/></body>
    <body name="c" pos="0 2 0" euler="0 0 30"><joint type="hinge" axis="0 0 1"/>
      <geom type="box" size="0.1 0.1 0.3" pos="0.2 0 0" euler="10 0 0" rgba="0 0 1 1"/></body>
    <body name="d" pos="0 5 0"><joint type="slide" axis="0 1 0"/>
      <geom type="box" size="0.2 0.1 0.1" rgba="1 1 0 1"/></body>
    <body name="e" pos="0 6 0"><joint type="slide" axis="0 0 1"/>
      <geom type="box" size="0.1 0.1 0.2" rgba="0 1 1 1"/></body>
    <body name="own" pos="0 3 0"><joint type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.1 0.1"/><geom type="sphere" size="0.1"/></body>
    <body name="glass" pos="0 4 0"><joint type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.1 0.1" rgba="1 1 1 0.3"/></body>
  </worldbody>
</mujoco>
"""


def _model_data(xml: str) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return model, data


def test_only_groups_whose_every_geom_is_shared_are_batched():
    """Boxes of any size over five groups are one batch; the group with a sphere of its
    own keeps its frame (its pose is sent anyway), and a translucent box is not batched
    (the instances of one node are drawn unsorted)."""
    model, _ = _model_data(FIVE_BOXES)
    from sandbox.physics.picture import body_groups

    roots, _ = body_groups(model)
    (batch,) = batches(geom_shapes(model), roots)
    names = {model.body(int(roots[k])).name for k in batch.groups}
    assert batch.key == ("box",) and names == {"a", "b", "c", "d", "e"}
    # two groups of two kinds each: two batch messages for two poses, nothing saved
    two, _ = _model_data(TWO_PAIRS)
    assert batches(geom_shapes(two), body_groups(two)[0]) == []
    # four groups of boxes: three messages saved, fewer than posing a batch costs
    body_e = FIVE_BOXES[FIVE_BOXES.index('<body name="e"') : FIVE_BOXES.index('<body name="own"')]
    four, _ = _model_data(FIVE_BOXES.replace(body_e, ""))
    assert batches(geom_shapes(four), body_groups(four)[0]) == []


TWO_PAIRS = """
<mujoco>
  <worldbody>
    <body><joint type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.1 0.1"/><geom type="cylinder" size="0.1 0.1"/></body>
    <body pos="0 1 0"><joint type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.1 0.1"/><geom type="cylinder" size="0.1 0.1"/></body>
  </worldbody>
</mujoco>
"""


def test_instances_are_drawn_where_mujoco_holds_the_geoms():
    model, data = _model_data(FIVE_BOXES)
    scene = FakeScene()
    renderer = SceneRenderer(scene)
    data.qpos[:] = (0.3, -0.2, 0.7, 0.25, -0.15, 0.1, 0.4)
    mujoco.mj_kinematics(model, data)
    renderer.sync(model, data)
    (node,) = [n for n in scene.nodes if n.kind == "batched_meshes_simple"]
    batch = renderer._batches[0][0]
    for k, shape in enumerate(batch.shapes):
        g = shape.geom_id
        assert node.batched_positions[k] == pytest.approx(data.geom_xpos[g], abs=1e-6)
        mat = np.zeros(9)
        mujoco.mju_quat2Mat(mat, node.batched_wxyzs[k].astype(float))
        assert mat == pytest.approx(data.geom_xmat[g], abs=1e-6)
        pos, wxyz = renderer.world_pose(g)  # what labels and tests ask of a batched geom
        assert pos == pytest.approx(data.geom_xpos[g], abs=1e-12)
    assert node.kwargs["batched_scales"][1] == pytest.approx((0.2, 0.4, 0.2))
    # a poses helper on its own: the groups' world poses give the same instances
    roots = renderer._roots
    poses = np.concatenate([data.xpos[roots], data.xquat[roots]], axis=1)
    positions, _ = instance_poses(batch, poses)
    assert positions == pytest.approx(node.batched_positions, abs=1e-6)


def test_the_engine_sends_three_messages_a_frame_and_a_label_brings_its_frame_back():
    """The inline four sent nine poses a frame (crankshaft, four pistons, four rods); its
    pistons and its rods are now two batches: three messages. A label riding on a piston
    needs the piston's frame posed again: one more message while it is shown."""
    from sandbox.physics.simulation import Simulation

    sim = Simulation(get_scene("engine"))
    renderer = SceneRenderer(FakeScene())
    renderer.sync(sim.model, sim.data)
    counts = []
    for _ in range(4):
        sent = renderer.messages
        sim.advance(0.007)
        renderer.sync(sim.model, sim.data)
        counts.append(renderer.messages - sent)
    assert counts == [3, 3, 3, 3]
    assert sorted(b.key[0] for b, _ in renderer._batches) == ["capsule", "cylinder"]
    piston = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_GEOM, "piston_1")
    assert piston in renderer.batched
    renderer.label_geoms({piston: "piston 1"})
    sim.advance(0.007)
    sent = renderer.messages
    renderer.sync(sim.model, sim.data)
    assert renderer.messages - sent == 5  # the piston's frame: its first whole pose
    sim.advance(0.007)
    sent = renderer.messages
    renderer.sync(sim.model, sim.data)
    assert renderer.messages - sent == 4  # then its position only (it slides)
    camera = Camera((0.4, -0.4, 0.3), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 1.0, 800, 720)
    assert len(renderer.label_boxes(camera, 16.0)) == 1
    (label,) = renderer.labels.values()
    frame = renderer.bodies[label[2]]
    assert frame.position == pytest.approx(sim.data.xpos[label[2]])
    # one cylinder left: nothing shared, every geom back under its group's frame
    sim.set_value("cylinders", 1.0)
    renderer.sync(sim.model, sim.data)
    assert renderer._batches == [] and renderer.batched == {}
    drawn = {s.geom_id for s, _ in renderer.nodes.values()}
    assert drawn == {s.geom_id for s in geom_shapes(sim.model)}
    sim.set_value("cylinders", 4.0)
    renderer.sync(sim.model, sim.data)
    assert len(renderer._batches) == 2
