"""3D labels: beside their point, never over one another, written at the panels' refresh
with the overlay's values of that instant, and as large as the page's text.

viser draws labels in WebGL (no DOM element to measure): the browser test reads the
camera the browser reports and the labels' places the server sent, measures each text
with the browser's own fonts (the stack viser's glyph atlas uses), and builds each box as
viser's ``layoutLabel`` does.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import free_port, wait_for

from sandbox.physics.simulation import Simulation
from sandbox.scenes import resolve
from sandbox.web.loop.requests import Pause, Reset
from sandbox.web.view3d import label_layout
from sandbox.web.view3d.arrows import ArrowLayer, read_camera
from sandbox.web.view3d.label_layout import (
    DIRECTIONS,
    REACH,
    Block,
    Camera,
    distance,
    label_size,
    overlaps,
    place,
    preferred_sides,
    text_width,
)

SCENES = (
    "rotor",
    "compressor",
    "rolling_cylinder",
    "gyroscope",
    "heavy_gyroscope",
    "engine",
    "robot_axis",
    "inertia",
    "wheel_balancer",
)

CAMERA = Camera((0.0, -1.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), math.radians(75), 800, 720)


# -- pure layout ---------------------------------------------------------------------------
def test_a_pixel_offset_lands_where_asked():
    point = np.array([0.1, 0.2, -0.05])
    x, y, depth = CAMERA.project(point)
    moved = CAMERA.project(point + CAMERA.offset(37.0, -12.0, depth))
    assert moved[0] == pytest.approx(x + 37.0) and moved[1] == pytest.approx(y - 12.0)
    assert CAMERA.project(np.array([0.0, 0.0, 0.0]))[:2] == pytest.approx((400, 360))
    assert math.isnan(CAMERA.project(np.array([0.0, -2.0, 0.0]))[0])  # behind the eye


def test_blocks_sharing_a_crowded_spot_never_overlap():
    rng = np.random.default_rng(3)
    view = (4.0, 4.0, 796.0, 716.0)
    for _ in range(50):
        blocks = [
            Block(
                (float(x), float(y)),
                tuple(label_size("Palier A : -54,4 N", 12.8) for _ in range(int(n))),
            )
            for x, y, n in zip(
                rng.uniform(250, 550, 5),
                rng.uniform(200, 500, 5),
                rng.integers(1, 4, 5),
                strict=True,
            )
        ]
        avoid = [(0.0, 560.0, 480.0, 720.0)]
        spots = place(blocks, view=view, centre=(400, 360), avoid=avoid)
        boxes = [s.box for s in spots if s is not None and s.free]
        for i, a in enumerate(boxes):
            assert not overlaps(a, avoid[0])
            assert all(not overlaps(a, b) for b in boxes[i + 1 :])
        for block, spot in zip(blocks, spots, strict=True):
            assert spot is not None and distance(block.point, spot.box) <= REACH


def test_a_block_keeps_its_place_while_it_is_free():
    block = Block((400.0, 360.0), (label_size("Tamis : 143 N", 12.8),))
    first = place([block], view=(0, 0, 800, 720), centre=(300, 300))[0]
    assert first is not None and first.reach == label_layout.DISTANCES[0]
    assert DIRECTIONS[first.side][0] > 0 and DIRECTIONS[first.side][1] > 0  # away from centre
    other = next(s for s in range(8) if s != first.side)
    old = label_layout.Placement(other, 30.0, block.box(other, 30.0))
    again = place([block], view=(0, 0, 800, 720), centre=(300, 300), before=[old])[0]
    assert again is not None and (again.side, again.reach) == (other, 30.0)
    assert preferred_sides((500, 360), (400, 360))[0] == 0  # east of the centre: east


def test_the_width_bound_covers_long_values():
    assert text_width("Pilon : -387 N", 10) > text_width("Pilon : 42 N", 10)
    assert text_width("m", 10) > text_width("i", 10)


# -- the arrows' layer -----------------------------------------------------------------------
class Handle:
    def __init__(self, **kwargs) -> None:
        self.visible = True
        self.position = np.zeros(3)
        self.__dict__.update(kwargs)


class Recorder:
    """A scene whose handles record every text written."""

    def __init__(self) -> None:
        self.texts: list[tuple[str, str]] = []

    def add_arrows(self, name, **kwargs):
        return Handle(**kwargs)

    def add_frame(self, name, **kwargs):
        return Handle(**kwargs)

    def add_line_segments(self, name, **kwargs):
        return Handle(**kwargs)

    def add_label(self, name, text, **kwargs):
        scene = self

        class Label(Handle):
            def __setattr__(self, key, value):
                if key == "text" and "text" in self.__dict__ and value != self.text:
                    scene.texts.append((name, value))
                super().__setattr__(key, value)

        return Label(text=text, **kwargs)


def _layer(scene, name: str = "compressor") -> tuple[Simulation, ArrowLayer]:
    sim = Simulation(resolve(name))
    spec = sim.scene
    assert spec is not None
    return sim, ArrowLayer(scene, spec.page.arrows, extent=1.0, zero=spec.zero)


def test_labels_write_the_instant_the_overlay_shows_and_send_nothing_between():
    """Issue 36: the compressor at 3000 tr/min, its shaking forces changing every frame
    (60 a second, the panels refresh 10 times a second). The labels read « Tamis : 47,6 N »
    beside the overlay's « −47,6 N », « Pilon : 302 N » beside « −42,7 N »: written at 4 Hz
    from the arrows' magnitudes. Now at each panel refresh every label writes the value the
    overlay writes at that instant (the readout of its name, signed, with its digits); the
    arrows move every frame and the labels, riding on the frame's point O, send nothing
    between refreshes."""
    from sandbox.web.panels.projector import overlay_lines

    scene = Recorder()
    sim, layer = _layer(scene)
    layer.watch(CAMERA)
    spec = sim.scene
    assert spec is not None
    units = {i.name: i.unit for i in sim.readout_infos()}
    sim.advance(0.05)
    layer.update(sim.snapshot((), forces=True))  # the first drawing places every label
    layer.relabel(sim.readouts(["pilon", "tamis"]))
    frames, messages, checked = 0, [], 0
    while frames < 120:
        sim.advance(1 / 60)
        snap = sim.snapshot((), forces=True)
        before = layer.messages
        layer.update(snap)
        frames += 1
        if frames % 6 == 0:  # the panels' refresh: the frame's readouts, one instant
            values = sim.readouts(["pilon", "tamis"], snapshot=snap)
            layer.relabel(values)
            for name in ("pilon", "tamis"):
                k = [a.name for a in layer.arrows].index(name)
                zeros = {name: spec.zero_for(units[name])}  # the scene's round-off
                (line,) = overlay_lines([name], values, {name: "x"}, units, zeros)
                assert layer.labels[k].text.endswith(line.removeprefix("x = ")), name
                checked += 1
        else:
            messages.append(layer.messages - before)
    assert checked == 40
    assert max(messages) <= 1  # the arrows' node only: nothing for the labels


def test_every_relabel_writes():
    """A replay's export writes every frame's values."""
    scene = Recorder()
    sim, layer = _layer(scene)
    for _ in range(5):
        sim.advance(0.0037)
        layer.update(sim.snapshot((), forces=True))
        layer.relabel()
    assert len(scene.texts) >= 8


def test_labels_follow_the_page_text_size():
    scene = Recorder()
    sim, layer = _layer(scene)
    font = [16]
    layer.watch(CAMERA, font=lambda: font[0])
    layer.update(sim.snapshot((), forces=True))
    layer.relabel()
    small = layer.labels[0].font_screen_scale
    font[0] = 24
    layer.relabel()
    assert layer.labels[0].font_screen_scale == pytest.approx(1.5 * small)
    assert 12 * layer.labels[0].font_screen_scale >= 18  # 24 px text: labels of 18 px or more


# -- in the browser ---------------------------------------------------------------------------
MEASURE = """(items) => {
  const ctx = document.createElement('canvas').getContext('2d');
  return items.map(([text, px]) => {
    ctx.font = px + 'px -apple-system, BlinkMacSystemFont, "Segoe UI", "Roboto", ' +
               '"Helvetica Neue", Arial, sans-serif';
    const m = ctx.measureText(text);
    return [m.width, m.fontBoundingBoxAscent + m.fontBoundingBoxDescent];
  });
}"""


def _quat_rotate(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    w, x, y, z = wxyz
    u = np.array([x, y, z])
    return v + 2 * np.cross(u, np.cross(u, v) + w * v)


def _box(x: float, y: float, anchor: str, width: float, line: float) -> tuple:
    """A label's background [px] as viser's layoutLabel lays it out."""
    pad = 0.2 * line
    w, h = width + pad, line + pad
    vertical, horizontal = anchor.split("-")
    left = x if horizontal == "left" else x - w if horizontal == "right" else x - w / 2
    top = y if vertical == "top" else y - h if vertical == "bottom" else y - h / 2
    return (left, top, left + w, top + h)


def _labels(session, page) -> tuple[list[tuple], Camera]:
    """(name, box, point of its arrow or None) of every visible label, in canvas px, in
    the camera the labels were last laid out for, once the browser's is that one (a
    camera the browser changed is laid out for within a quarter of a second)."""
    view = session.view
    layer, renderer = view.arrows, view.renderer
    assert wait_for(lambda: read_camera(view.client.camera) == layer.laid_out, timeout=10)
    camera = layer.laid_out
    assert camera is not None
    found = []  # (name, text, world anchor, viser anchor, scale, arrow point)
    for k, label in enumerate(layer.labels):
        if label.visible:
            frame = layer.frames[layer.group_of[k]]
            # copies, read together: a handle's position is an array the loop thread
            # rewrites in place (a view read after the browser measured the texts found
            # the robot's travelling point 140 px past its label)
            at = np.array(frame.position, dtype=float)
            world = at + np.array(label.position, dtype=float)
            found.append((layer.arrows[k].label, label.text, world, label.anchor,
                          label.font_screen_scale, at))  # fmt: skip
    for text, label, root in renderer.labels.values():
        if not label.visible:  # turning too fast to be read: not drawn
            continue
        frame = renderer.bodies[root]
        world = np.array(frame.position, dtype=float) + _quat_rotate(
            np.array(frame.wxyz, dtype=float), np.array(label.position, dtype=float)
        )
        found.append((text, text, world, label.anchor, label.font_screen_scale, None))
    sizes = page.evaluate(MEASURE, [[text, 12 * scale] for _, text, _, _, scale, _ in found])
    out = []
    for (name, _, world, anchor, _, point), (width, line) in zip(found, sizes, strict=True):
        x, y, _ = camera.project(world)
        at = None if point is None else camera.project(point)[:2]
        out.append((name, _box(x, y, anchor, width, line), at))
    return out, camera


TRAVELLING = ("rolling_cylinder",)
"""Scenes whose mechanism leaves the view (the cylinder rolls out of it a second into its
run): their labels are checked on the opening view, held."""


@pytest.mark.browser
@pytest.mark.slow  # a server and a Chromium page per scene: ~8 s each
@pytest.mark.parametrize("scene", SCENES)
def test_labels_sit_by_their_point_and_never_overlap(browser, scene):
    from sandbox.web.serving.app import start

    app = start(scene, port=free_port(), open_message=False)
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    try:
        page = context.new_page()
        page.goto(app.url)
        assert wait_for(lambda: len(app.sessions) == 1, timeout=30)
        (session,) = app.sessions.values()
        if scene in TRAVELLING:  # their opening view, held
            session.controller.submit(Pause())
            session.controller.submit(Reset())
        layer = session.view.arrows
        assert layer is not None
        assert wait_for(lambda: any(p is not None for p in layer._placed), timeout=30)
        canvas = page.evaluate(
            "() => { const c = [...document.querySelectorAll('canvas')].sort((a, b) =>"
            " b.width * b.height - a.width * a.height)[0].getBoundingClientRect();"
            " return [c.left, c.top]; }"
        )
        overlay = page.evaluate(
            "() => { const o = document.getElementById('sandbox-overlay');"
            " if (!o || !o.textContent) return null; const r = o.getBoundingClientRect();"
            " return [r.left, r.top, r.right, r.bottom]; }"
        )
        checked = 0

        def read() -> tuple[int, list[tuple]]:
            """(labels of arrows found, what is wrong) in one reading of the page."""
            found, wrong = 0, []
            labels, camera = _labels(session, page)
            if not labels:  # only while no arrow shows (an axis at rest between moves)...
                # ...or until the next layout labels an arrow just shown (after a reset)
                assert wait_for(
                    lambda: not any(layer.shown) or any(lb.visible for lb in layer.labels),
                    timeout=5,
                ), scene
                labels, camera = _labels(session, page)
                if not labels:
                    return 0, []
            for i, (name, box, point) in enumerate(labels):
                inside = 0 <= box[0] and box[2] <= camera.width
                if not (inside and 0 <= box[1] and box[3] <= camera.height):
                    wrong.append((scene, name, box))
                for other, box2, _ in labels[i + 1 :]:
                    if overlaps(box, box2):
                        wrong.append((scene, name, other, box, box2))
                if overlay is not None:
                    ox = [overlay[0] - canvas[0], overlay[1] - canvas[1]]
                    shown = (ox[0], ox[1], overlay[2] - canvas[0], overlay[3] - canvas[1])
                    if overlaps(box, shown):
                        wrong.append((scene, name, "readouts", box, shown))
                if point is not None:  # an arrow's label: by its point of application
                    if distance(point, box) > REACH:
                        wrong.append((scene, name, point, box))
                    found += 1
            return found, wrong

        def check() -> int:
            """One reading without a fault, within a few layouts: a reading that caught a
            label's handle between two writes of the loop thread (once in five full runs,
            the gyroscope's label read 1,200 px above the view) is read again; a label
            that stays wrong fails."""
            seen: dict[str, tuple[int, list[tuple]]] = {}

            def clean() -> bool:
                seen["last"] = read()
                return not seen["last"][1]

            wait_for(clean, timeout=3, poll=0.3)
            found, wrong = seen["last"]
            assert not wrong, wrong[0]
            return found

        for _ in range(1 if scene in TRAVELLING else 6):  # a rotor's masses turn: instants
            if scene not in TRAVELLING:  # held: the one instant
                drawn = session.controller.drawn_time
                assert wait_for(lambda drawn=drawn: session.controller.drawn_time > drawn + 0.05)
            checked += check()
        marks = session.view.renderer.labels
        if marks and scene not in TRAVELLING:  # paused, the masses' labels show again
            session.controller.submit(Pause())
            assert wait_for(lambda: all(m[1].visible for m in marks.values()), timeout=5)
            checked += check()
        assert checked
        # each label rides on its arrow's point of application
        for k, shown in enumerate(layer.shown):
            if shown:
                frame = layer.frames[layer.group_of[k]]
                gap = np.linalg.norm(np.asarray(frame.position) - layer.origins[k])
                assert gap <= 0.05 * layer.size, (scene, layer.arrows[k].name)
    finally:
        context.close()
        app.stop()
