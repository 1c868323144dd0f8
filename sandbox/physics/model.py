"""Build an MjModel from a scene spec or an MJCF file, with only the scene's effects on.

Physics never imports the scenes: a scene spec reaches it as a :class:`SceneSpec` in a
:class:`Source`, and scene *names* are resolved through the registry that
:mod:`sandbox.scenes` passes down when it is imported (:func:`register_scenes`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import mujoco

from sandbox.data import data_dir
from sandbox.errors import BadModel, BadOption, UnknownScene, choices

INTEGRATORS: dict[str, int] = {
    "euler": int(mujoco.mjtIntegrator.mjINT_EULER),
    "implicit": int(mujoco.mjtIntegrator.mjINT_IMPLICIT),
    "implicitfast": int(mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
    "rk4": int(mujoco.mjtIntegrator.mjINT_RK4),
    "discrete": int(mujoco.mjtIntegrator.mjINT_DISCRETE),
}
"""Integrator names accepted by ``--integrator`` and the web app."""


def integrator_name(model: mujoco.MjModel) -> str:
    """Name of the integrator the model uses."""
    code = int(model.opt.integrator)
    for name, value in INTEGRATORS.items():
        if value == code:
            return name
    return "discrete"


def check_integrator(name: str) -> int:
    """MuJoCo code of an integrator name (BadOption naming the valid ones)."""
    if name not in INTEGRATORS:
        raise BadOption(f"unknown integrator {name!r}; choose one of: {choices(INTEGRATORS)}")
    return INTEGRATORS[name]


MIN_TIMESTEP = 1e-6
"""Smallest timestep accepted [s]: below it a second of motion costs over a million steps
(minutes of CPU) and rounding, not the integrator, limits the accuracy."""

MAX_TIMESTEP = 0.1
"""Largest timestep accepted [s] (a scene may set a smaller ``max_timestep``)."""


def check_timestep(value: float) -> float:
    """Validate a timestep [s]: finite, between :data:`MIN_TIMESTEP` and :data:`MAX_TIMESTEP`."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise BadOption(
            f"timestep must be a positive number of seconds, got {value!r}; try --timestep 0.001"
        )
    if value < MIN_TIMESTEP:
        raise BadOption(
            f"timestep {value!r} s is too small (min {MIN_TIMESTEP:g} s); try --timestep 0.001"
        )
    if value > MAX_TIMESTEP:
        raise BadOption(
            f"timestep {value!r} s is too large (max {MAX_TIMESTEP:g} s); try --timestep 0.001"
        )
    return float(value)


class SceneSpec(Protocol):
    """What physics reads from a scene spec (:class:`sandbox.scenes.base.Scene` is one).

    Callables take the parameter values by name (``Mapping[str, float]``)."""

    @property
    def name(self) -> str: ...
    @property
    def mjcf(self) -> str: ...  # file name under the scenes folder
    @property
    def effects(self) -> Any: ...  # has disable_flags() -> int
    @property
    def integrator(self) -> str: ...
    @property
    def timestep(self) -> float: ...
    @property
    def max_timestep(self) -> float: ...
    @property
    def timestep_for(self) -> Callable[..., float] | None: ...
    @property
    def readouts(self) -> Sequence[Any]: ...  # name, unit, doc, fn(snapshot) -> float
    @property
    def edit(self) -> Callable[[mujoco.MjSpec, Mapping[str, float]], None] | None: ...
    @property
    def drive(self) -> Callable[..., None] | None: ...  # (model, data, values)
    @property
    def initial_state(self) -> Callable[..., None] | None: ...  # (model, data, values)
    @property
    def reference(self) -> Callable[[Mapping[str, float]], dict[str, float]] | None: ...
    def defaults(self) -> dict[str, float]: ...
    def param(self, name: str) -> Any: ...  # has check(value) -> float and live
    def default_timestep(
        self, values: Mapping[str, float] | None = None, data: Any = None
    ) -> float: ...


_SCENES: Mapping[str, SceneSpec] = {}
"""The registry :func:`resolve` looks names up in (empty until one is registered)."""


def register_scenes(scenes: Mapping[str, SceneSpec]) -> None:
    """Let :func:`resolve` (and ``Simulation(name)``) find scenes by name.

    :mod:`sandbox.scenes` passes its registry down when it is imported, so that physics
    never imports the layer above it; the entry points (cli, bench, replay, the web
    package) import it.
    """
    global _SCENES
    _SCENES = scenes


@dataclass(frozen=True)
class Source:
    """Where a model comes from: a registered scene or a user's MJCF file."""

    scene: SceneSpec | None
    path: Path

    @classmethod
    def of_scene(cls, scene: SceneSpec) -> Source:
        """The source of a scene spec: its MJCF file in the scenes folder."""
        return cls(scene, data_dir("scenes") / scene.mjcf)

    @property
    def label(self) -> str:
        """Scene name, or the file name for a user's MJCF."""
        return self.scene.name if self.scene else self.path.name


def resolve(target: str | Path) -> Source:
    """Turn ``X`` of the CLI into a source: a registered scene name or an MJCF path.

    Scene names are those of the registry passed to :func:`register_scenes` (importing
    :mod:`sandbox.scenes` does it).

    Raises:
        UnknownScene: neither a scene nor an existing file (lists the scenes).
        BadModel: a directory was given instead of a file.
    """
    scenes = _SCENES
    text = str(target)
    if text in scenes:
        return Source.of_scene(scenes[text])
    path = Path(text)
    if path.is_dir():
        raise BadModel(
            f"{text!r} is a directory; give an MJCF file (.xml) or a scene name: {choices(scenes)}"
        )
    if path.is_file():
        return Source(None, path)
    if not scenes:
        raise UnknownScene(
            f"unknown scene or file {text!r}: no scene registry is loaded (import "
            "sandbox.scenes first), or give the path of an MJCF file"
        )
    raise UnknownScene(
        f"unknown scene or file {text!r}; scenes: {choices(scenes)}, "
        "or give the path of an MJCF file"
    )


def model_xml(source: Source, values: Mapping[str, float]) -> str:
    """MJCF text of the model: a file's own text, or the scene's file with the edits."""
    if source.scene is None or source.scene.edit is None:
        return source.path.read_text()
    spec = mujoco.MjSpec.from_file(str(source.path))
    source.scene.edit(spec, values)
    spec.compile()
    return spec.to_xml()


def build(source: Source, values: Mapping[str, float]) -> mujoco.MjModel:
    """Compile the model with the parameter values applied and the scene's effects only.

    A user's file keeps its own options; autoreset is always disabled so that a
    divergence stays visible (MuJoCo would otherwise reset silently).

    Raises:
        BadModel: the file cannot be parsed or compiled (MuJoCo's message included).
    """
    try:
        spec = mujoco.MjSpec.from_file(str(source.path))
        if source.scene is not None and source.scene.edit is not None:
            source.scene.edit(spec, values)
        model = spec.compile()
    except (ValueError, mujoco.FatalError) as exc:  # MuJoCo reports XML/compile errors so
        text = " ".join(line.strip() for line in str(exc).splitlines() if line.strip())
        raise BadModel(
            f"cannot load MJCF {str(source.path)!r}: {text or type(exc).__name__}; "
            "fix the file (see MuJoCo's XML reference)"
        ) from None
    except UnicodeDecodeError:
        raise BadModel(f"{str(source.path)!r} is not a text MJCF file; give an .xml file") from None
    if source.scene is not None:
        model.opt.disableflags = source.scene.effects.disable_flags()
        model.opt.integrator = check_integrator(source.scene.integrator)
        model.opt.timestep = source.scene.default_timestep(values)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
    return model
