"""Registry of the course's scenes (frozen :class:`~sandbox.physics.spec.Scene` specs).

Importing it passes the registry down to physics (:func:`sandbox.physics.model.register_scenes`),
so that ``Simulation("rotor")`` and :func:`~sandbox.physics.model.resolve` know the scene
names. That injection is the seam between the two layers: physics never imports the
scenes (tests/test_layers.py), it only looks names up in the mapping it was given here.
A scene that needs a simulation of its own builds it from its spec
(``Simulation(Source.of_scene(SCENE))``) and so does not depend on this registry.
"""

from __future__ import annotations

from sandbox.errors import UnknownScene, choices
from sandbox.physics.model import register_scenes
from sandbox.physics.spec import Scene
from sandbox.scenes.compressor import SCENE as COMPRESSOR
from sandbox.scenes.engine import SCENE as ENGINE
from sandbox.scenes.gyroscope import SCENE as GYROSCOPE
from sandbox.scenes.heavy_gyroscope import SCENE as HEAVY_GYROSCOPE
from sandbox.scenes.inertia import SCENE as INERTIA
from sandbox.scenes.robot_axis import SCENE as ROBOT_AXIS
from sandbox.scenes.rolling_cylinder import SCENE as ROLLING_CYLINDER
from sandbox.scenes.rotor import SCENE as ROTOR
from sandbox.scenes.wheel_balancer import SCENE as WHEEL_BALANCER

SCENES: dict[str, Scene] = {
    s.name: s
    for s in (
        ROTOR,
        COMPRESSOR,
        ROLLING_CYLINDER,
        GYROSCOPE,
        HEAVY_GYROSCOPE,
        ENGINE,
        ROBOT_AXIS,
        INERTIA,
        WHEEL_BALANCER,
    )
}
"""Every registered scene by name."""

DEFAULT_SCENE = "rotor"

register_scenes(SCENES)


def get_scene(name: str) -> Scene:
    """The scene called ``name`` (UnknownScene listing the valid names)."""
    try:
        return SCENES[name]
    except KeyError:
        raise UnknownScene(f"unknown scene {name!r}; choose one of: {choices(SCENES)}") from None
