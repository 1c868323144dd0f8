"""Where a video's camera stands (:mod:`sandbox.web.video.framing`): the page's framing
kept when the moving parts stay in it, else every moving part of every sampled instant
in the picture and clear of the readouts' box; a turning disc outlined by its rim, not by
its box. Checked on the scenes whose page framing cut a part or hid it under the box."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, load
from sandbox.replay import open_simulation
from sandbox.scenes import get_scene
from sandbox.web.video.framing import (
    Picture,
    _basis,
    _bounds,
    clip_points,
    fits,
    frame_clip,
    outline,
    sample_clip,
)
from sandbox.web.view3d.camera import page_pose, scene_view

PICTURE = Picture(aspect=16 / 9, fovy=45.0, box=(0.3, 0.3))
"""A 16:9 video whose readouts' box takes the top-left 30 % by 30 %."""


def _recording(name: str, path: Path, seconds: float) -> Path:
    sim = Simulation(get_scene(name))
    rec = Recorder(path, sim)
    rec.frame(sim.readouts())
    steps = max(1, round(seconds / sim.timestep / 20))
    for _ in range(20):
        sim.step(steps)
        rec.frame(sim.readouts())
    rec.close()
    return path


def _page_camera(sim: Simulation) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    position, look_at = page_pose(sim)
    return position, look_at, np.asarray(scene_view(sim)[1], float)


@pytest.mark.parametrize(
    ("name", "seconds"),
    [("rolling_cylinder", 1.0), ("wheel_balancer", 0.5), ("heavy_gyroscope", 1.0)],
)
def test_every_moving_part_is_whole_and_clear_of_the_box(name, seconds, tmp_path):
    """The page's framing cut these (the rolling cylinder under the box at the top of
    its plane, the wheel and the top's disc above the picture); the video's framing
    holds every moving part of the whole clip."""
    rec = load(_recording(name, tmp_path / f"{name}.sbx", seconds))
    sim = open_simulation(rec)
    points = clip_points(rec, sim, np.linspace(0.0, rec.timeline[-1], 24))
    position, look_at, up = _page_camera(sim)
    assert not fits(_bounds(points, position, _basis(position, look_at, up), PICTURE), PICTURE)
    position, look_at = frame_clip(points, position, look_at, up, PICTURE)
    bounds = _bounds(points, position, _basis(position, look_at, up), PICTURE)
    assert fits(bounds, PICTURE)
    left, right, bottom, top = bounds  # and it fills the picture: not a speck
    assert max(right - left, top - bottom) > 0.9


def test_a_framing_that_holds_everything_is_the_pages():
    points = np.array([[0.1, 0.0, 0.0], [-0.1, 0.0, -0.1]])
    position, look_at, up = np.array([0.0, -1.0, 0.0]), np.zeros(3), np.array([0.0, 0.0, 1.0])
    got = frame_clip(points, position, look_at, up, PICTURE)
    assert np.array_equal(got[0], position) and np.array_equal(got[1], look_at)


def test_a_part_under_the_box_moves_the_camera_not_the_part():
    """A part at the top-left, where the box is: the camera aims again, the part ends
    below the box, whole."""
    position, look_at, up = np.array([0.0, -1.0, 0.0]), np.zeros(3), np.array([0.0, 0.0, 1.0])
    points = np.array([[-0.5, 0.0, 0.3], [-0.4, 0.0, 0.25]])
    basis = _basis(position, look_at, up)
    assert not fits(_bounds(points, position, basis, PICTURE), PICTURE)
    position, look_at = frame_clip(points, position, look_at, up, PICTURE)
    assert fits(_bounds(points, position, _basis(position, look_at, up), PICTURE), PICTURE)


def test_a_turning_disc_is_outlined_by_its_rim():
    """A disc's box corners turn on a circle 1.41 times the disc's: its rim's points do
    not (the wheel balancer was framed far too small)."""
    model = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><joint type='hinge'/>"
        "<geom type='cylinder' size='0.3 0.02'/></body></worldbody></mujoco>"
    )
    points = outline(model, 0)
    assert np.allclose(np.hypot(points[:, 0], points[:, 1]), 0.3)
    assert np.allclose(np.abs(points[:, 2]), 0.02)


def test_a_cylinder_rolling_far_is_followed_and_a_short_roll_is_not(tmp_path):
    """Framed still, 4 s down the plane made the
    cylinder a dot: a clip whose parts travel 4 times their size or more is followed,
    the camera around their centre of mass, which the parts' outline fills."""
    far = load(_recording("rolling_cylinder", tmp_path / "far.sbx", 4.0))
    clip = sample_clip(far, open_simulation(far), np.linspace(0.0, far.timeline[-1], 24))
    assert clip.follows
    position, look_at, up = _page_camera(open_simulation(far))
    position, look_at = frame_clip(clip.shape(), position - look_at, np.zeros(3), up, PICTURE)
    bounds = _bounds(clip.shape(), position, _basis(position, look_at, up), PICTURE)
    assert fits(bounds, PICTURE)
    near = load(_recording("rolling_cylinder", tmp_path / "near.sbx", 0.2))
    assert not sample_clip(near, open_simulation(near), np.linspace(0.0, 0.2, 8)).follows


def test_the_videos_labels_are_placed_as_the_pages(monkeypatch):
    """Four labels: two at one point, one 6 px from it near the right edge, one near the
    left edge: every label whole in the picture, none over another nor over the box (the
    video stacked labels on a 40 px grid, over one another and past the right edge)."""
    from PIL import Image, ImageDraw

    from sandbox.physics.page import Arrow
    from sandbox.web.video import frame

    text = frame.Text(360)
    boxes: list[tuple[float, float, float, float]] = []
    real = text.box

    def measured(draw, xy, lines, font, color=(0, 0, 0)):
        x0, y0, x1, y1 = draw.multiline_textbbox(xy, "\n".join(lines), font=font, spacing=4)
        boxes.append((x0, y0, x1, y1))
        real(draw, xy, lines, font, color)

    monkeypatch.setattr(text, "box", measured)
    pixels = {0.0: (630.0, 200.0), 1.0: (636.0, 204.0), 2.0: (8.0, 300.0)}
    monkeypatch.setattr(
        frame, "project", lambda scene, pts, w, h: np.array([pixels[float(pts[0][0])]])
    )

    def arrow(name: str) -> Arrow:
        return Arrow(
            name, f"Effort {name}", (40, 110, 230), lambda s: (np.zeros(3), np.zeros(3)), unit="N"
        )

    drawn = [
        (arrow("A"), np.array([0.0, 0, 0]), 54.4, "N"),
        (arrow("B"), np.array([0.0, 0, 0]), 14.9, "N"),
        (arrow("C"), np.array([1.0, 0, 0]), 3.0, "N"),
        (arrow("D"), np.array([2.0, 0, 0]), 7.0, "N"),
    ]
    image = Image.new("RGB", (640, 360), (255, 255, 255))
    readouts_box = (0.0, 0.0, 200.0, 90.0)
    frame.ArrowLabels(text).draw(
        ImageDraw.Draw(image, "RGBA"), None, drawn, (640, 360), {}, avoid=(readouts_box,)
    )
    assert len(boxes) == 4
    for k, (x0, y0, x1, y1) in enumerate(boxes):
        assert 0 <= x0 and x1 <= 640 and 0 <= y0 and y1 <= 360, boxes[k]
        assert not (x0 < readouts_box[2] and y0 < readouts_box[3]), boxes[k]
        for other in boxes[k + 1 :]:
            assert x1 <= other[0] or other[2] <= x0 or y1 <= other[1] or other[3] <= y0
