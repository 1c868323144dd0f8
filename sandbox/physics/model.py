"""Build an MjModel from a scene spec or an MJCF file, with only the scene's effects on.

Physics never imports the scenes: a scene's record (:class:`~sandbox.physics.spec.Scene`,
a plain dataclass of physics) reaches it in a :class:`Source`, and a scene *name* is
resolved against the registry its caller passes (:func:`resolve`; :mod:`sandbox.scenes`
gives its own).
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import mujoco

from sandbox.data import data_dir
from sandbox.errors import BadModel, BadOption, UnknownScene, choices, one_line, shown
from sandbox.french import shown_value
from sandbox.physics.imposed import ANCHOR_SLOTS
from sandbox.physics.limits import (
    MAX_MODEL_BYTES,
    check_spec,
    prescan,
    read_mjcf,
)
from sandbox.physics.spec import Scene

INTEGRATORS: dict[str, int] = {
    "euler": int(mujoco.mjtIntegrator.mjINT_EULER),
    "implicit": int(mujoco.mjtIntegrator.mjINT_IMPLICIT),
    "implicitfast": int(mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
    "rk4": int(mujoco.mjtIntegrator.mjINT_RK4),
    "discrete": int(mujoco.mjtIntegrator.mjINT_DISCRETE),
}
"""Integrator names accepted by ``--integrator`` and the web app."""

INTEGRATOR_WORDS: dict[str, str] = {
    "euler": "Euler semi-implicite",
    "implicit": "Implicite",
    "implicitfast": "Implicite rapide",
    "rk4": "Runge-Kutta 4",
    "discrete": "Discret",
}
"""The integrators in words, as the web page and its charts name them."""


def integrator_words(name: str) -> str:
    """An integrator in the words of the page, the charts and the lessons ("Runge-Kutta
    4"); an unknown one as it is (its CLI name is a contract, not a word for the page)."""
    return INTEGRATOR_WORDS.get(name, name)


def integrator_name(model: mujoco.MjModel) -> str:
    """Name of the integrator the model uses."""
    code = int(model.opt.integrator)
    for name, value in INTEGRATORS.items():
        if value == code:
            return name
    return "discrete"


def check_integrator(name: object) -> int:
    """MuJoCo code of an integrator name (BadOption naming the valid ones, in English and
    in the page's words)."""
    if not isinstance(name, str) or name not in INTEGRATORS:
        raise BadOption(
            f"unknown integrator {shown(name)}; choose one of: {choices(INTEGRATORS)}",
            french=f"Intégrateur « {shown_value(name)} » inconnu : choisissez parmi "
            f"{', '.join(INTEGRATORS)}.",
        )
    return INTEGRATORS[name]


NO_SCENES: Mapping[str, Scene] = MappingProxyType({})
"""No registry: :func:`resolve` then takes only MJCF paths."""


@dataclass(frozen=True)
class Source:
    """Where a model comes from: a registered scene or a user's MJCF file, and what that
    file may take to compile [bytes] (:data:`~sandbox.physics.limits.MAX_MODEL_BYTES`
    for one from outside; a file named on the command line gets more, ``--max-memory``)."""

    scene: Scene | None
    path: Path
    max_bytes: float = MAX_MODEL_BYTES

    @classmethod
    def of_scene(cls, scene: Scene) -> Source:
        """The source of a scene spec: its MJCF file in the scenes folder."""
        return cls(scene, data_dir("scenes") / scene.mjcf)

    @property
    def label(self) -> str:
        """Scene name, or the file name for a user's MJCF."""
        return self.scene.name if self.scene else self.path.name


def resolve(
    target: str | Path,
    scenes: Mapping[str, Scene] = NO_SCENES,
    *,
    max_bytes: float = MAX_MODEL_BYTES,
) -> Source:
    """Turn ``X`` of the CLI into a source: a scene name of ``scenes`` or an MJCF path.

    Args:
        target: A scene name or the path of an MJCF file.
        scenes: The registry names are looked up in (:func:`sandbox.scenes.resolve` passes
            the course's); without one, only a file is accepted.
        max_bytes: What a file may take to compile (the command line's own file gets
            :func:`~sandbox.physics.limits.machine_bytes`).

    Raises:
        UnknownScene: neither a scene nor an existing file (lists the scenes).
        BadModel: a directory was given instead of a file.
    """
    text = str(target)
    if text in scenes:
        return Source.of_scene(scenes[text])
    name = shown(text)
    if not scenes:
        unknown = (
            f"unknown file {name}: give the path of an MJCF file (a scene's name is "
            "resolved by sandbox.scenes.resolve)"
        )
    else:
        unknown = (
            f"unknown scene or file {name}; scenes: {choices(scenes)}, "
            "or give the path of an MJCF file"
        )
    if not text or "\x00" in text:
        raise UnknownScene(unknown)
    try:
        mode = os.stat(text).st_mode
    except OSError as exc:
        if exc.errno == errno.ENAMETOOLONG:
            raise UnknownScene(
                f"{name} is too long for a file name; give a scene name ({choices(scenes)}) "
                "or the path of an MJCF file"
            ) from None
        if exc.errno in (errno.EACCES, errno.EPERM):
            raise BadModel(
                f"cannot read {name}: permission denied; check its permissions"
            ) from None
        raise UnknownScene(unknown) from None
    if stat.S_ISDIR(mode):
        raise BadModel(
            f"{name} is a directory; give an MJCF file (.xml) or a scene name: {choices(scenes)}"
        )
    if not stat.S_ISREG(mode):
        raise BadModel(
            f"{name} is not a regular file (a device or a pipe?); give an MJCF file (.xml)"
        )
    return Source(None, Path(text), max_bytes)


def model_xml(source: Source, values: Mapping[str, float]) -> str:
    """MJCF text of the model: a file's own text, or the scene's file with the edits."""
    if source.scene is None or (source.scene.edit is None and source.scene.imposed is None):
        return read_mjcf(source.path)
    spec = mujoco.MjSpec.from_file(str(source.path))
    _edit(spec, source.scene, values)
    spec.compile()
    return spec.to_xml()


def _edit(spec: mujoco.MjSpec, scene: Scene, values: Mapping[str, float]) -> None:
    """The scene's edits of its MJCF, and the ``userdata`` an imposed law's anchor takes
    (:mod:`sandbox.physics.imposed`: it travels with the state)."""
    if scene.edit is not None:
        scene.edit(spec, values)
    if scene.imposed is not None:
        spec.nuserdata = max(spec.nuserdata, scene.imposed.slot + ANCHOR_SLOTS)


def build(
    source: Source, values: Mapping[str, float], *, own_timestep: bool = True
) -> mujoco.MjModel:
    """Compile the model with the parameter values applied and the scene's effects only.

    A user's file keeps its own options; autoreset is always disabled so that a
    divergence stays visible (MuJoCo would otherwise reset silently). A user's file is
    read at most ``MAX_MJCF_BYTES``, its expansion counted and its parsed spec bounded
    (:func:`check_spec`) before MuJoCo compiles it.

    Args:
        source: Scene or file.
        values: Parameter values of a scene.
        own_timestep: A user's file will run at its own timestep, which must then lie
            within [:data:`MIN_TIMESTEP`, :data:`MAX_TIMESTEP`] (False: the caller sets
            another one).

    Raises:
        BadModel: the file cannot be read, parsed or compiled (MuJoCo's message
            included), or it exceeds a limit.
    """
    try:
        if source.scene is None:
            prescan(source.path, source.max_bytes)
        spec = mujoco.MjSpec.from_file(str(source.path))
        if source.scene is None:
            check_spec(spec, source.path, timestep=own_timestep, limit=source.max_bytes)
        if source.scene is not None:
            _edit(spec, source.scene, values)
        model = spec.compile()
    except (ValueError, RuntimeError, mujoco.FatalError) as exc:  # MuJoCo's XML/compile
        text = one_line(str(exc))
        text = text if len(text) <= 300 else text[:297] + "..."
        raise BadModel(
            f"cannot load MJCF {shown(str(source.path))}: {text or type(exc).__name__}; "
            "fix the file (see MuJoCo's XML reference)",
            french="Le modèle ne se construit pas avec ces valeurs : rien n'a changé.",
        ) from None
    except UnicodeDecodeError:
        raise BadModel(
            f"{shown(str(source.path))} is not a text MJCF file; give an .xml file"
        ) from None
    if source.scene is not None:
        model.opt.disableflags = source.scene.effects_at(values).disable_flags()
        model.opt.integrator = check_integrator(source.scene.integrator)
        model.opt.timestep = source.scene.default_timestep(values)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
    return model
