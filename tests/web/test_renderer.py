"""MJCF geoms to viser nodes: every drawn type, poses, static vs moving, rebuilds."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from sandbox.scenes import get_scene, resolve
from sandbox.web.view3d.geoms import capsule_mesh, geom_pose, geom_shapes, mat_to_wxyz
from sandbox.web.view3d.label_layout import Camera, label_size
from sandbox.web.view3d.renderer import READABLE_PX, SceneRenderer

ALL_TYPES = """
<mujoco>
  <asset>
    <mesh name="tetra" vertex="0 0 0  0.1 0 0  0 0.1 0  0 0 0.1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="1 2 0.1" rgba="0.3 0.3 0.3 1"/>
    <geom name="hidden" type="box" size="0.1 0.1 0.1" group="3"/>
    <geom name="invisible" type="box" size="0.1 0.1 0.1" rgba="1 0 0 0"/>
    <body name="b" pos="0 0 1" euler="0.3 0.2 0.1">
      <freejoint/>
      <geom name="box" type="box" size="0.1 0.2 0.3" rgba="1 0 0 0.5"/>
      <geom name="sphere" type="sphere" size="0.05" pos="0.3 0 0"/>
      <geom name="capsule" type="capsule" fromto="0 0 0 0 0.4 0" size="0.02"/>
      <geom name="cylinder" type="cylinder" size="0.05 0.1" pos="0 0 0.4"/>
      <geom name="ellipsoid" type="ellipsoid" size="0.1 0.05 0.02" pos="0 0 -0.4"/>
      <geom name="mesh" type="mesh" mesh="tetra" pos="0.2 0.2 0"/>
    </body>
  </worldbody>
</mujoco>
"""


class FakeNode:
    def __init__(self, kind: str, name: str, kwargs: dict) -> None:
        self.kind, self.name, self.kwargs = kind, name, kwargs
        self.position = np.asarray(kwargs.get("position", np.zeros(3)), float)
        self.wxyz = np.asarray(kwargs.get("wxyz", (1.0, 0, 0, 0)), float)
        self.removed = False
        self.visible = True

    def remove(self) -> None:
        self.removed = True


class FakeScene:
    """Records the nodes a renderer asks viser for."""

    def __init__(self) -> None:
        self.nodes: list[FakeNode] = []

    def __getattr__(self, attr: str):
        if not attr.startswith("add_"):
            raise AttributeError(attr)

        def add(name, *args, **kwargs):
            node = FakeNode(attr[4:], name, kwargs)
            self.nodes.append(node)
            return node

        return add


@pytest.fixture
def model_data():
    model = mujoco.MjModel.from_xml_string(ALL_TYPES)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def test_every_drawn_geom_type_gets_a_shape(model_data):
    model, _ = model_data
    shapes = {s.name.split("_", 1)[1]: s for s in geom_shapes(model)}
    assert set(shapes) == {"floor", "box", "sphere", "capsule", "cylinder", "ellipsoid", "mesh"}
    assert shapes["box"].size == pytest.approx((0.2, 0.4, 0.6))  # full edges
    assert shapes["box"].opacity == pytest.approx(0.5)
    assert shapes["cylinder"].size == pytest.approx((0.05, 0.2))  # radius, full height
    assert shapes["capsule"].size == pytest.approx((0.02, 0.2))  # radius, half length
    assert shapes["ellipsoid"].size == pytest.approx((0.1, 0.05, 0.02))
    assert shapes["floor"].size == pytest.approx((2.0, 4.0, 0.1))
    assert not shapes["floor"].moving and shapes["box"].moving
    assert shapes["mesh"].size[:2] == (4.0, 4.0)


def test_poses_are_mujoco_world_poses(model_data):
    model, data = model_data
    gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "sphere")
    pos, wxyz = geom_pose(data, gid)
    assert pos == pytest.approx(data.geom_xpos[gid])
    back = np.zeros(9)
    mujoco.mju_quat2Mat(back, wxyz)
    assert back == pytest.approx(data.geom_xmat[gid], abs=1e-12)
    assert np.linalg.norm(mat_to_wxyz(np.eye(3))) == pytest.approx(1.0)


def test_capsule_mesh_is_closed_and_has_the_right_extent():
    verts, faces = capsule_mesh(0.02, 0.1)
    assert verts[:, 2].min() == pytest.approx(-0.12) and verts[:, 2].max() == pytest.approx(0.12)
    assert np.hypot(verts[:, 0], verts[:, 1]).max() == pytest.approx(0.02, rel=1e-6)
    edges: dict[tuple[int, int], int] = {}
    for a, b, c in faces:
        for e in ((a, b), (b, c), (c, a)):
            edges[e] = edges.get(e, 0) + 1
    assert all(edges.get((b, a)) == 1 for a, b in edges)  # every edge shared, consistent


def test_renderer_poses_moving_nodes_and_keeps_unchanged_ones(model_data):
    model, data = model_data
    scene = FakeScene()
    renderer = SceneRenderer(scene)
    renderer.sync(model, data)
    kinds = sorted(n.kind for n in scene.nodes if n.kind != "frame")
    assert kinds == [
        "box",
        "cylinder",
        "grid",
        "icosphere",
        "icosphere",
        "mesh_simple",
        "mesh_simple",
    ]
    data.qpos[:3] = (1.0, 2.0, 3.0)
    mujoco.mj_forward(model, data)
    renderer.sync(model, data)
    moved = 0
    for gid, (shape, _) in renderer.nodes.items():
        pos, wxyz = renderer.world_pose(gid)
        assert pos == pytest.approx(data.geom_xpos[gid])
        mat = np.zeros(9)
        mujoco.mju_quat2Mat(mat, wxyz)
        assert mat == pytest.approx(data.geom_xmat[gid], abs=1e-9)
        moved += shape.moving
    assert moved >= 2 and len(renderer.bodies) == 1  # one pose a frame for the moving body
    # A recompiled model with one geom resized: only that node is replaced.
    spec = mujoco.MjSpec.from_string(ALL_TYPES)
    spec.geom("sphere").size[0] = 0.08
    model2 = spec.compile()
    data2 = mujoco.MjData(model2)
    mujoco.mj_forward(model2, data2)
    renderer.sync(model2, data2)
    removed = [n.name for n in scene.nodes if n.removed]
    assert len(removed) == 1 and removed[0].endswith("sphere")
    assert len(renderer.nodes) == 7


def test_the_mechanism_size_leaves_the_floor_out():
    from sandbox.physics.simulation import Simulation
    from sandbox.web.view3d.geoms import mechanism_size

    sim = Simulation(get_scene("rolling_cylinder"))
    assert float(sim.model.stat.extent) > 10.0  # the 12 m plane
    assert 0.2 < mechanism_size(sim.model, sim.data) < 1.0


def test_small_moving_spheres_are_drawn_large_enough_to_see():
    from sandbox.physics.simulation import Simulation
    from sandbox.web.view3d.geoms import MARKER, mechanism_size

    sim = Simulation(get_scene("rotor"), values={"mass1_g": 30.0})
    size = mechanism_size(sim.model)
    shapes = {s.name.rsplit("_", 1)[1]: s for s in geom_shapes(sim.model)}
    assert shapes["correction1"].size == (pytest.approx(MARKER * size),)
    assert shapes["correction1"].size[0] > 2 * 0.006  # the 6 mm sphere of the physics
    assert "correction2" not in shapes  # no mass: not drawn
    # the physics keeps its own size
    gid = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_GEOM, "correction1")
    assert sim.model.geom_size[gid][0] == pytest.approx(0.006)


class Handle:
    """A viser handle whose properties are plain attributes."""

    def __init__(self, **kwargs) -> None:
        self.visible = True
        self.points = np.zeros((1, 2, 3))
        self.position = np.zeros(3)
        self.__dict__.update(kwargs)


class HandleScene:
    def __init__(self) -> None:
        self.made: dict[str, Handle] = {}

    def add_arrows(self, name, **kwargs):
        self.made[name] = Handle(**kwargs)
        return self.made[name]

    def add_label(self, name, text, **kwargs):
        self.made[name] = Handle(text=text, **kwargs)
        return self.made[name]

    def add_frame(self, name, **kwargs):
        self.made[name] = Handle(**kwargs)
        return self.made[name]

    def add_line_segments(self, name, **kwargs):
        self.made[name] = Handle(**kwargs)
        return self.made[name]


@pytest.mark.parametrize(
    "scene, values",
    [
        ("rotor", {"speed_rpm": 6000.0}),
        ("rotor", {"speed_rpm": 300.0}),
        ("compressor", {}),
        ("rolling_cylinder", {}),
        ("gyroscope", {}),
        ("heavy_gyroscope", {}),
        ("engine", {"cylinders": 1.0}),
        ("robot_axis", {}),
        ("wheel_balancer", {}),
        ("inertia", {}),
    ],
)
def test_arrows_are_sized_to_the_mechanism_and_stay_in_view(scene, values):
    from sandbox.physics.simulation import Simulation
    from sandbox.physics.units import shown_scale
    from sandbox.web.view3d.arrow_scale import MAX_REACH, MIN_REACH, SHAFT
    from sandbox.web.view3d.arrows import ArrowLayer
    from sandbox.web.view3d.geoms import mechanism_size

    sim = Simulation(resolve(scene), values=values)
    sim.advance(0.05)
    spec = sim.scene
    assert spec is not None and spec.page.arrows
    fake = HandleScene()
    layer = ArrowLayer(fake, spec.page.arrows, extent=float(sim.model.stat.extent))
    for _ in range(5):
        layer.update(sim.snapshot(("sup_R_x", "dyn_R_x")))
        sim.advance(0.01)
    size = mechanism_size(sim.model, sim.data)
    assert layer.size == pytest.approx(size, rel=0.2)
    node = layer.node  # one node draws every arrow: one message a frame
    assert node.shaft_radius == pytest.approx(SHAFT * layer.size)
    assert node.head_length < 0.2 * size
    assert len(node.points) == sum(layer.shown) and node.visible == any(layer.shown)
    for shown, start, end in zip(layer.shown, layer.origins, layer.ends, strict=True):
        if shown:
            length = float(np.linalg.norm(end - start))
            assert length <= MAX_REACH * size + 1e-9
    by_unit: dict[str, float] = {}
    for k, shown in enumerate(layer.shown):
        if shown:
            length = float(np.linalg.norm(layer.ends[k] - layer.origins[k]))
            by_unit[layer.units[k]] = max(by_unit.get(layer.units[k], 0.0), length)
    assert all(v >= MIN_REACH * size * 0.99 for v in by_unit.values()), by_unit
    layer.relabel()
    for k, label in enumerate(layer.labels):
        if getattr(spec.page.arrows[k], "magnitude", True) and layer.units[k]:
            # in the unit every view writes it in (a speed in tr/min, as the tables)
            unit = shown_scale(spec.page.arrows[k].name, layer.units[k])[0]
            assert label.text.endswith(unit), label.text
            assert "." not in label.text.split(":")[-1], label.text  # decimal comma


def test_the_user_scale_multiplies_the_lengths():
    from sandbox.physics.simulation import Simulation
    from sandbox.web.view3d.arrows import ArrowLayer

    sim = Simulation(get_scene("rotor"))
    spec = sim.scene
    assert spec is not None
    layer = ArrowLayer(HandleScene(), spec.page.arrows, extent=1.0)
    snap = sim.snapshot(("sup_R_x",))
    layer.update(snap)
    before = np.linalg.norm(layer.ends[0] - layer.origins[0])
    layer.set_scale(2.0)
    layer.update(snap)
    assert np.linalg.norm(layer.ends[0] - layer.origins[0]) == pytest.approx(2 * before)
    layer.set_scale(100.0)
    assert layer.user_scale == 4.0


def test_a_round_off_force_draws_no_arrow():
    """The inline four's rocking moment is 0 to 4e-15 N·m: without the scene's round-off
    the automatic scale blew it up into a violet arrow as long as the force's."""
    from sandbox.physics.simulation import Simulation
    from sandbox.web.view3d.arrows import ArrowLayer

    sim = Simulation(
        get_scene("engine"), values={"cylinders": 4.0}, motion="free"
    )  # imposed: exactly 0
    sim.advance(0.05)
    spec = sim.scene
    assert spec is not None
    names = [a.name for a in spec.page.arrows]
    layer = ArrowLayer(HandleScene(), spec.page.arrows, extent=1.0, zero=spec.zero)
    layer.update(sim.snapshot(("sup_R_x", "dyn_R_x")))
    assert layer.shown[names.index("frame_force")]
    assert not layer.shown[names.index("shaking_moment")]
    layer.relabel()
    bare = ArrowLayer(HandleScene(), spec.page.arrows, extent=1.0)  # no round-off given
    bare.update(sim.snapshot(("sup_R_x", "dyn_R_x")))
    assert bare.shown[names.index("shaking_moment")]


SPINNER = """
<mujoco>
  <worldbody>
    <body name="disk">
      <joint name="spin" type="hinge" axis="0 1 0"/>
      <geom type="cylinder" size="0.2 0.02" euler="90 0 0"/>
      <geom name="mass" type="sphere" size="0.01" pos="0.15 0 0"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_a_label_riding_on_a_fast_turning_body_hides_and_shows_when_it_slows():
    """A mass's label on a disk at 3000 tr/min would be drawn anywhere on its circle at
    each frame: unreadable, and over the other labels. It hides while its body turns more
    than READABLE_PX between two layouts, and shows, with its exact box, once still."""
    model = mujoco.MjModel.from_xml_string(SPINNER)
    data = mujoco.MjData(model)
    renderer = SceneRenderer(FakeScene())
    renderer.sync(model, data)
    mass = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "mass")
    renderer.label_geoms({mass: "m₁ : 20 g"})
    camera = Camera((0.0, -1.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 1.3, 800, 720)
    ((text, label, _),) = renderer.labels.values()
    for angle in np.linspace(0.0, 2 * np.pi, 13)[1:]:  # 3000 tr/min at 50 frames a second
        data.qpos[0] = angle
        mujoco.mj_kinematics(model, data)
        renderer.sync(model, data)
    assert renderer.label_boxes(camera, 16.0) == [] and not label.visible
    mujoco.mj_kinematics(model, data)
    renderer.sync(model, data)  # paused: the same pose again
    (box,) = renderer.label_boxes(camera, 16.0)
    assert label.visible
    x, y, _ = camera.project(data.geom_xpos[mass])
    width, height = label_size(text, 16.0)
    assert box == pytest.approx((x - width / 2, y - height, x + width / 2, y), abs=1e-6)
    # turning slowly (a few pixels a layout): shown, its box grown by the slide
    data.qpos[0] += 0.5 * READABLE_PX / (0.15 * camera.focal)
    mujoco.mj_kinematics(model, data)
    renderer.sync(model, data)
    (grown,) = renderer.label_boxes(camera, 16.0)
    assert label.visible and grown[2] - grown[0] > width + READABLE_PX * 0.9


def test_a_rod_hangs_under_its_piston_and_sends_its_orientation_only():
    """A group turning about a point of another (:func:`carriers`) is drawn in that one's
    frame: the compressor's rod sends no position a frame, only its orientation; the
    engine's model rebuilt with other cylinders removes what hangs under a frame first
    (viser warned of nodes removed twice)."""
    import warnings

    import viser
    from conftest import free_port

    from sandbox.physics.picture import body_groups, carriers
    from sandbox.physics.simulation import Simulation

    sim = Simulation(get_scene("compressor"))
    roots, _ = body_groups(sim.model)
    carried = dict(zip(roots.tolist(), carriers(sim.model).tolist(), strict=True))
    rod, piston = sim.model.body("rod").id, sim.model.body("piston").id
    assert (
        carried[rod] == piston and carried[piston] == 0 and carried[sim.model.body("crank").id] == 0
    )
    scene = FakeScene()
    renderer = SceneRenderer(scene)
    renderer.sync(sim.model, sim.data)
    sent = renderer.messages
    sim.advance(0.003)
    renderer.sync(sim.model, sim.data)
    # crank: orientation; piston: position; rod: orientation (its position in the piston
    # is the same): 3 messages, not 4
    assert renderer.messages - sent == 3
    server = viser.ViserServer(port=free_port(), verbose=False)
    try:
        engine = Simulation(get_scene("engine"))
        live = SceneRenderer(server.scene)
        live.sync(engine.model, engine.data)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for n in (2.0, 1.0, 4.0):
                engine.set_value("cylinders", n)
                live.sync(engine.model, engine.data)
        assert not [w for w in caught if "removed" in str(w.message)]
    finally:
        server.stop()


@pytest.mark.parametrize("cylinders", [1.0, 2.0])
def test_a_rebuilt_model_poses_its_fixed_parts_where_they_are_now(cylinders):
    """The engine cut from four cylinders: a fixed part kept from the old model (the same
    shape, same geom id) is posed again where the new model holds it; it used to stay
    where the old one had it (a sleeve floating beside the block, its piston bare)."""
    from sandbox.physics.simulation import Simulation
    from sandbox.web.view3d.geoms import geom_pose

    sim = Simulation(get_scene("engine"))
    renderer = SceneRenderer(FakeScene())
    renderer.sync(sim.model, sim.data)
    sim.set_value("cylinders", cylinders)
    renderer.sync(sim.model, sim.data)
    data = mujoco.MjData(sim.model)
    mujoco.mj_kinematics(sim.model, data)
    fixed = [(gid, node) for gid, (shape, node) in renderer.nodes.items() if not shape.moving]
    assert fixed
    for gid, node in fixed:
        assert not node.removed
        pos, wxyz = geom_pose(data, gid)
        assert np.allclose(node.position, pos), sim.model.geom(gid).name
        assert np.allclose(np.abs(node.wxyz @ wxyz), 1.0), sim.model.geom(gid).name
