"""What ``sandbox bench`` writes and prints: results.json, results.csv, the Markdown tables
(the sessions' costs, then every run of each scene) and one chart per scene.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

from sandbox.bench import plot
from sandbox.bench.cost import FRAME_RATE, GOAL, PANEL_RATE, TARGET
from sandbox.bench.results import SceneResult
from sandbox.bench.store import to_json
from sandbox.scenes import get_scene

CSV_COLUMNS = (
    "scene",
    "integrator",
    "timestep",
    "duration",
    "error",
    "drift",
    "constraint",
    "cpu_per_sim_s",
    "realtime_factor",
    "diverged",
    "pareto",
    "default",
)


def write_results(results: Sequence[SceneResult], out: Path, *, quick: bool) -> list[Path]:
    """results.json, results.csv, results.md and one PNG per scene in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(
        json.dumps(to_json(results, quick=quick), indent=1), encoding="utf-8"
    )
    with (out / "results.csv").open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(CSV_COLUMNS)
        for res in results:
            for r in res.runs:
                row = asdict(r)
                writer.writerow(["" if row[c] is None else row[c] for c in CSV_COLUMNS])
    (out / "results.md").write_text(markdown(results), encoding="utf-8")
    paths = [out / "results.json", out / "results.csv", out / "results.md"]
    for res in results:
        paths.append(plot.plot_scene(res, out / f"{res.scene}.png"))
    return paths


def _fmt(x: float | None, spec: str = ".2e") -> str:
    if x is None:
        return "—"
    return "∞" if math.isinf(x) else format(x, spec)


def session_markdown(results: Sequence[SceneResult]) -> str:
    """One row per scene: its default session's cost on one core, the 20× goal and the 60×
    target."""
    rows = [r for r in results if r.session is not None]
    if not rows:
        return ""
    lines = [
        f"### Sessions at the defaults — one core, goal ≥ {GOAL:g}× real time\n",
        f"A web session steps in real time, takes an arrows snapshot {FRAME_RATE:g} times "
        f"and a row of every readout {PANEL_RATE:g} times per simulated second. "
        "Default parameters (the grids below may use harder ones: the benchmark's "
        "default run is also given).\n",
        "| scene | default | stepping × real time | snapshot [ms] | row [ms] | "
        f"session × real time | ≥ {GOAL:g}× | ≥ {TARGET:g}× | benchmark case |",
        "|:--|:--|--:|--:|--:|--:|:--|:--|:--|",
    ]
    for res in rows:
        c = res.session
        assert c is not None
        d = res.default
        case = (
            f"{d.integrator} dt = {d.timestep:.3g} s: {_fmt(d.realtime_factor, '.1f')}×"
            if d is not None
            else "—"
        )
        lines.append(
            f"| {res.scene} | {c.integrator}, dt = {c.timestep:.3g} s | "
            f"{_fmt(c.step_factor, '.1f')} | {c.snapshot_s * 1e3:.3f} | {c.row_s * 1e3:.3f} | "
            f"{c.realtime_factor:.1f} | {'yes' if c.meets_goal else '**no**'} | "
            f"{'yes' if c.realtime_factor >= TARGET else 'no'} | {case} |"
        )
    return "\n".join(lines) + "\n\n"


def _angle_note(name: str) -> list[str]:
    """Why a default that is a crank angle per step is measured at the test's speed."""
    from sandbox.scenes import SCENES  # the registry (this module is below the scenes)

    scene = SCENES.get(name)
    acc = scene.accuracy if scene is not None else None
    if scene is None or acc is None or not acc.same_angle:
        return []
    test = scene.default_timestep(dict(acc.values))
    page = scene.default_timestep({})
    return [
        "",
        f"The default timestep is a crank angle per step: the errors depend on ω·dt alone, "
        f"so the default is the same angle at every speed, {test:.3g} s at the test's "
        f"speed and {page:.3g} s at the page's default speed, and « Précision et coût » "
        "measures a page's setting on this test at the same angle per step. A fixed "
        "timestep cannot do it: at the test's speed only about 1e-4 s is admissible.",
    ]


def markdown(results: Sequence[SceneResult]) -> str:
    """The sessions' table (:func:`session_markdown`), then one table per scene: every
    run, the Pareto front and the default marked."""
    parts = [session_markdown(results)] if any(r.session for r in results) else []
    for res in results:
        parts.append(
            f"### {res.scene} — key: `{res.key}`, invariant: {res.invariant}\n\n"
            "| integrator | dt [s] | error | drift | constraint [m] | CPU s / sim s | "
            "× real time | |\n|:--|--:|--:|--:|--:|--:|--:|:--|"
        )
        for r in res.runs:
            tags = []
            if r.default:
                tags.append("**default**")
            if r.pareto:
                tags.append("Pareto")
            if r.diverged:
                tags.append("diverged")
            parts.append(
                f"| {r.integrator} | {r.timestep:.3g} | {_fmt(r.error)} | {_fmt(r.drift)} | "
                f"{_fmt(r.constraint)} | {_fmt(r.cpu_per_sim_s, '.3g')} | "
                f"{_fmt(r.realtime_factor, '.1f')} | {', '.join(tags)} |"
            )
        exact = res.imposed
        if exact is not None:
            parts.append(
                f"| **imposed motion** (exact) | {exact.timestep:.3g} | {_fmt(exact.error)} | "
                f"{_fmt(exact.drift)} | {_fmt(exact.constraint)} | "
                f"{_fmt(exact.cpu_per_sim_s, '.3g')} | {_fmt(exact.realtime_factor, '.1f')} | "
                f"closure equations + inverse dynamics, {exact.evaluation_s * 1e6:.0f} µs "
                "per evaluation (one a web frame, whatever dt) |"
            )
        else:
            why = _not_imposed(res.scene)
            if why:
                dashes = " — |" * 6
                parts.append(f"| **imposed motion** |{dashes} not this case: {why} |")
        parts += _angle_note(res.scene)
        parts.append("")
    return "\n".join(parts)


def _not_imposed(name: str) -> str:
    """Why a scene that can impose its motion cannot on its benchmark case ("" when it
    has no imposed motion, or can)."""
    try:
        scene = get_scene(name)
    except Exception:  # a result file of a scene this version does not know
        return ""
    if scene.imposed is None or scene.accuracy is None:
        return ""
    refusal = scene.imposed.refusal({**scene.defaults(), **scene.accuracy.values})
    return "" if refusal is None else refusal[0]
