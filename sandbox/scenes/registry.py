"""Registry of the course's scenes (frozen :class:`~sandbox.physics.spec.Scene` specs).

Physics never imports the scenes (tests/test_layers.py) and keeps no registry: it takes a
scene's spec (``Simulation(get_scene("rotor"))``), and a name typed by a user (the CLI's
``X``, a link, a study) is turned into a source here, by :func:`resolve`, which passes this
registry to :func:`sandbox.physics.model.resolve`.
"""

from __future__ import annotations

from pathlib import Path

from sandbox.errors import UnknownScene, choices
from sandbox.physics import model
from sandbox.physics.limits import MAX_MODEL_BYTES
from sandbox.physics.model import Source
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
from sandbox.scenes.wind_turbine import SCENE as WIND_TURBINE

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
        WIND_TURBINE,
    )
}
"""Every registered scene by name."""

DEFAULT_SCENE = "rotor"


def resolve(target: str | Path, *, max_bytes: float = MAX_MODEL_BYTES) -> Source:
    """A scene of the registry by name, or an MJCF file by path (UnknownScene listing the
    scenes, BadModel for a directory or a device); ``max_bytes``: what the file may take to
    compile (the command line's own: :func:`~sandbox.physics.limits.machine_bytes`)."""
    return model.resolve(target, SCENES, max_bytes=max_bytes)


def get_scene(name: str) -> Scene:
    """The scene called ``name`` (UnknownScene listing the valid names)."""
    try:
        return SCENES[name]
    except KeyError:
        raise UnknownScene(f"unknown scene {name!r}; choose one of: {choices(SCENES)}") from None
