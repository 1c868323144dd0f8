"""The 3D part of a frame, drawn by one function for a browser and for the broadcast."""

from __future__ import annotations

from types import SimpleNamespace

from sandbox.web.view3d.stage import draw_scene


class Calls(list):
    """A renderer and an arrow layer in one: what was asked of them, in order."""

    def draw(self, *args: object) -> None:
        self.append(("draw", len(args)))

    def hide(self) -> None:
        self.append(("hide", 0))


PICTURE = SimpleNamespace(arrows={"R": None}, magnitudes={"R": 1.0})


def test_a_picture_is_drawn_poses_then_arrows():
    renderer, arrows = Calls(), Calls()
    assert draw_scene(renderer, arrows, PICTURE, diverged=False)  # type: ignore[arg-type]
    assert renderer == [("draw", 1)] and arrows == [("draw", 2)]


def test_a_diverged_motion_hides_its_arrows_and_draws_nothing():
    renderer, arrows = Calls(), Calls()
    assert not draw_scene(renderer, arrows, PICTURE, diverged=True)  # type: ignore[arg-type]
    assert renderer == [] and arrows == [("hide", 0)]


def test_a_view_that_does_not_draw_leaves_the_shared_arrows_alone():
    """A teacher's panels in follow mode: no renderer, the broadcast's arrows untouched
    unless the motion diverged."""
    arrows = Calls()
    assert not draw_scene(None, arrows, PICTURE, diverged=False)  # type: ignore[arg-type]
    assert not draw_scene(Calls(), arrows, None, diverged=False)  # type: ignore[arg-type]
    assert arrows == []
