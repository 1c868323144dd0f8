"""One frame's 3D part, drawn the same way for one browser and for the class's broadcast:
the mechanism's poses and its arrows, or the arrows hidden once the motion diverged."""

from __future__ import annotations

from sandbox.physics.picture import Picture
from sandbox.web.view3d.arrows import ArrowLayer
from sandbox.web.view3d.renderer import SceneRenderer


def draw_scene(
    renderer: SceneRenderer | None,
    arrows: ArrowLayer | None,
    picture: Picture | None,
    diverged: bool,
) -> bool:
    """Draw ``picture`` (poses, then arrows) when it is given and the view draws
    (``renderer``); hide the arrows of a diverged motion, whose forces mean nothing.

    Returns:
        True when the picture was drawn.
    """
    if diverged:
        if arrows is not None:
            arrows.hide()
        return False
    if picture is None or renderer is None:
        return False
    renderer.draw(picture)
    if arrows is not None:
        arrows.draw(picture.arrows, picture.magnitudes)
    return True
