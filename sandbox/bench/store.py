"""results.json, the saved benchmark: written from the runs (:func:`to_json`), read back
scene by scene (:func:`load_results`), merged with a new run of a few scenes
(:func:`merge_results`). Schema in docs/reference.md.
"""

from __future__ import annotations

import json
import math
import os
import platform
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, fields
from pathlib import Path
from typing import Any

import mujoco

from sandbox.bench.cost import FRAME_RATE, GOAL, PANEL_RATE, SessionCost
from sandbox.bench.pareto import mark_pareto
from sandbox.bench.results import Run, SceneResult
from sandbox.data import data_dir
from sandbox.physics.spec import Accuracy
from sandbox.scenes import SCENES

SCHEMA = 1
"""Version of results.json (documented in docs/reference.md)."""


def machine() -> dict[str, object]:
    """Where the numbers were measured."""
    return {
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "platform": platform.platform(),
        "cpus": os.cpu_count(),
        "date": time.strftime("%Y-%m-%d"),
    }


def _json_number(x: float | None) -> float | str | None:
    if x is None:
        return None
    return x if math.isfinite(x) else ("inf" if x > 0 else "nan" if math.isnan(x) else "-inf")


def to_json(results: Sequence[SceneResult], *, quick: bool) -> dict[str, object]:
    """The results.json document (schema in docs/reference.md)."""
    scenes = {}
    for res in results:
        scenes[res.scene] = {
            "key": res.key,
            "invariant": res.invariant,
            "default": {"integrator": res.default_integrator, "timestep": res.default_timestep},
            "drift_tol": _json_number(res.drift_tol),
            "constraint_tol": _json_number(res.constraint_tol),
            "runs": [_run_json(r) for r in res.runs],
        }
        if res.imposed is not None:
            scenes[res.scene]["imposed"] = _run_json(res.imposed)
        if res.session is not None:
            c = res.session
            scenes[res.scene]["session"] = {
                "integrator": c.integrator,
                "timestep": c.timestep,
                "step_cpu_per_sim_s": c.step_s,
                "snapshot_cpu_s": c.snapshot_s,
                "row_cpu_s": c.row_s,
                "frame_rate": FRAME_RATE,
                "panel_rate": PANEL_RATE,
                "cpu_per_sim_s": c.per_sim_s,
                "step_realtime_factor": _json_number(c.step_factor),
                "realtime_factor": c.realtime_factor,
                "goal": GOAL,
                "meets_goal": c.meets_goal,
            }
    return {"schema": SCHEMA, "quick": quick, "machine": machine(), "scenes": scenes}


def _run_json(run: Run) -> dict[str, Any]:
    """One run as results.json writes it (the grid's simulated runs without ``motion``)."""
    d = asdict(run)
    for k in ("error", "drift", "constraint", "cpu_per_sim_s", "realtime_factor", "evaluation_s"):
        d[k] = _json_number(d[k])
    if d["motion"] == "free":
        del d["motion"], d["evaluation_s"]
    return d


def _from_json_number(x: object) -> float:
    """Inverse of :func:`_json_number` for a number that is there.

    Raises:
        TypeError, ValueError: ``x`` is neither a number nor "inf", "-inf" or "nan".
    """
    if isinstance(x, bool) or not isinstance(x, (int, float, str)):
        raise TypeError(f"expected a number, got {x!r}")
    if isinstance(x, str) and x not in ("inf", "-inf", "nan"):
        raise ValueError(f"expected a number, got {x!r}")
    return float(x)


def _run_from_json(r: object) -> Run:
    """One run of a results.json document, each field checked against its type.

    Raises:
        KeyError: a required field is missing.
        TypeError, ValueError: ``r`` is not an object, or a field is unknown or of the
            wrong type.
    """
    if not isinstance(r, Mapping):
        raise TypeError(f"a run must be a JSON object, got {r!r}")
    unknown = set(r) - {f.name for f in fields(Run)}
    if unknown:
        raise TypeError(f"unknown run fields {sorted(unknown)!r}")

    def text(key: str, default: str | None = None) -> str:
        value = r[key] if default is None else r.get(key, default)
        if not isinstance(value, str):
            raise TypeError(f"run field {key!r} must be a string, got {value!r}")
        return value

    def flag(key: str) -> bool:
        value = r.get(key, False)
        if not isinstance(value, bool):
            raise TypeError(f"run field {key!r} must be true or false, got {value!r}")
        return value

    def number(key: str, default: float) -> float:
        return _from_json_number(r.get(key, default))

    constraint = r.get("constraint")
    return Run(
        scene=text("scene"),
        integrator=text("integrator"),
        timestep=_from_json_number(r["timestep"]),
        duration=_from_json_number(r["duration"]),
        error=number("error", math.inf),
        drift=number("drift", math.inf),
        constraint=None if constraint is None else _from_json_number(constraint),
        cpu_per_sim_s=number("cpu_per_sim_s", math.nan),
        realtime_factor=number("realtime_factor", math.nan),
        diverged=flag("diverged"),
        detail=text("detail", ""),
        pareto=flag("pareto"),
        default=flag("default"),
        motion=text("motion", "free"),
        evaluation_s=number("evaluation_s", math.nan),
    )


def scene_from_json(
    scene: str, entry: Mapping[str, Any], acc: Accuracy | None = None
) -> SceneResult:
    """One scene of a results.json document (:func:`to_json`) back as a
    :class:`SceneResult`, its Pareto front marked again with ``acc``'s limits, with its
    session cost when the document has one.

    Raises:
        KeyError, TypeError, ValueError: the entry lacks a field or has one of the wrong
            type (an older or foreign document).
    """
    runs = [_run_from_json(r) for r in entry["runs"]]
    res = SceneResult(
        scene,
        entry["key"],
        entry["invariant"],
        entry["default"]["integrator"],
        entry["default"]["timestep"],
        runs,
        drift_tol=float(entry.get("drift_tol", math.inf)),
        constraint_tol=float(entry.get("constraint_tol", math.inf)),
        session=_session_from_json(scene, entry.get("session")),
        imposed=None if entry.get("imposed") is None else _run_from_json(entry["imposed"]),
    )
    mark_pareto(res.runs, acc)
    return res


def _session_from_json(scene: str, entry: object) -> SessionCost | None:
    """The ``session`` object of a results.json scene back as a :class:`SessionCost`
    (None when absent).

    Raises:
        KeyError, TypeError, ValueError: a field is missing or of the wrong type.
    """
    if entry is None:
        return None
    if not isinstance(entry, Mapping) or not isinstance(entry["integrator"], str):
        raise TypeError(f"a session must be a JSON object with an integrator, got {entry!r}")
    return SessionCost(
        scene,
        entry["integrator"],
        _from_json_number(entry["timestep"]),
        _from_json_number(entry["step_cpu_per_sim_s"]),
        _from_json_number(entry["snapshot_cpu_s"]),
        _from_json_number(entry["row_cpu_s"]),
    )


def merge_results(new: Sequence[SceneResult], path: Path) -> list[SceneResult]:
    """``new`` plus every other registered scene already benchmarked in ``path`` (a
    results.json), in the registry's order: refreshing a few scenes keeps the rest.

    A scene that cannot be read back (missing, foreign or older document) is left out.
    """
    fresh = {r.scene: r for r in new}
    merged = []
    for name in SCENES:
        if name in fresh:
            merged.append(fresh[name])
        else:
            kept = load_results(name, path)
            if kept is not None:
                merged.append(kept)
    merged += [r for r in new if r.scene not in SCENES]
    return merged


def load_results(scene: str, path: Path | None = None) -> SceneResult | None:
    """The benchmark of ``scene`` in ``path`` (default: the shipped bench/results.json),
    or None when the file, the scene or a field is missing."""
    path = data_dir("bench") / "results.json" if path is None else path
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        entry = doc["scenes"][scene]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    spec = SCENES.get(scene)
    try:
        return scene_from_json(scene, entry, spec.accuracy if spec else None)
    except (KeyError, TypeError, ValueError):
        return None
