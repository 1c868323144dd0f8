"""Build an MjModel from a scene spec or an MJCF file, with only the scene's effects on."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import mujoco

from sandbox.data import data_dir
from sandbox.errors import BadModel, BadOption, UnknownScene, choices
from sandbox.scenes.base import Scene

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


def check_timestep(value: float) -> float:
    """Validate a timestep [s]: finite, > 0 and at most 0.1 s."""
    if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise BadOption(
            f"timestep must be a positive number of seconds, got {value!r}; try --timestep 0.001"
        )
    if value > 0.1:
        raise BadOption(f"timestep {value!r} s is too large (max 0.1 s); try --timestep 0.001")
    return float(value)


@dataclass(frozen=True)
class Source:
    """Where a model comes from: a registered scene or a user's MJCF file."""

    scene: Scene | None
    path: Path

    @property
    def label(self) -> str:
        """Scene name, or the file name for a user's MJCF."""
        return self.scene.name if self.scene else self.path.name


def resolve(target: str | Path) -> Source:
    """Turn ``X`` of the CLI into a source: a registered scene name or an MJCF path.

    Raises:
        UnknownScene: neither a scene nor an existing file (lists the scenes).
        BadModel: a directory was given instead of a file.
    """
    from sandbox.scenes import SCENES

    text = str(target)
    if text in SCENES:
        scene = SCENES[text]
        return Source(scene, data_dir("scenes") / scene.mjcf)
    path = Path(text)
    if path.is_dir():
        raise BadModel(
            f"{text!r} is a directory; give an MJCF file (.xml) or a scene name: {choices(SCENES)}"
        )
    if path.is_file():
        return Source(None, path)
    raise UnknownScene(
        f"unknown scene or file {text!r}; scenes: {choices(SCENES)}, "
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
