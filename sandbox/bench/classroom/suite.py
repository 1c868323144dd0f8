"""The classroom benchmark over several scenes: one table, a saved run, ratios to it.

``--save`` writes the runs to a JSON file (the runs of other scenes or sizes already in
it are kept); ``--compare`` prints, for each figure, the new value divided by the saved
one, and says whether it is better or worse. Nothing here is asserted: timings depend on
the machine.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from sandbox.bench.classroom.report import jsonable
from sandbox.bench.classroom.targets import split
from sandbox.bench.classroom.workers import fps_ratio
from sandbox.errors import BadOption

SCHEMA = 1
"""Version of the saved file."""

MAX_SAVED_BYTES = 20_000_000
"""Largest saved file read back (a run is ~10 kB; a crafted file must not fill memory)."""

FIGURES: tuple[tuple[str, str, str, str], ...] = (
    ("fps.median", "frames/s median", "higher", ".1f"),
    ("fps.min", "frames/s min", "higher", ".1f"),
    ("sim_rate.min", "sim/real min", "higher", ".3f"),
    ("server_cpu_ms_per_frame", "CPU ms/frame", "lower", ".2f"),
    ("server_cpu_cores", "server cores", "", ".2f"),
    ("split", "session split", "lower", ".0f"),
    ("worker_fps_ratio", "worker fps ratio", "higher", ".2f"),
    ("server_rss_bytes", "RSS MB", "lower", ".0f"),
    ("side.ratio_min", "flood ratio", "higher", ".2f"),
    ("machine_probe_ms", "machine probe ms", "", ".2f"),
    ("teacher.students", "students held", "higher", ".0f"),
)
"""(key, column, which way is better, format) of the figures a run is summed up by ("":
neither way: the cores a server uses grow with the frames it delivers)."""


def run_key(results: Mapping[str, Any]) -> str:
    """How a run is named in a saved file: ``rotor×30``, ``rotor --follow×120``,
    ``rotor --flood×30``."""
    mode = " --follow" if results.get("follow") else ""
    mode += " --busy-core" if results.get("busy_core") else ""
    side = results["main"].get("side")
    if isinstance(side, Mapping) and "students" in side:
        mode += f" --{side.get('work', 'studies')} {side['students']}"
    elif isinstance(side, Mapping):
        mode += " --flood"
    return f"{results['scene']}{mode}×{results['main']['clients']}"


def figure(results: Mapping[str, Any], key: str) -> float:
    """One figure of a run (NaN when missing); ``split`` counts sessions per worker,
    ``worker_fps_ratio`` compares the workers' frame rates (:func:`fps_ratio`)."""
    if key == "split":
        return split(dict(results))
    if key == "worker_fps_ratio":
        return fps_ratio(results["main"].get("workers", []))
    value: Any = results["main"]
    for part in key.split("."):
        if not isinstance(value, Mapping) or part not in value:
            return math.nan
        value = value[part]
    try:
        number = float(value)
    except (TypeError, ValueError):
        return math.nan
    return number / 1e6 if key == "server_rss_bytes" else number


def verdicts(results: Mapping[str, Any]) -> str:
    """``PASS`` or the failed targets, in a few words."""
    failed = [t["target"] for t in results.get("targets", ()) if t["verdict"] != "PASS"]
    return "PASS" if not failed else "FAIL: " + "; ".join(failed)


def _fmt(value: float, spec: str) -> str:
    return format(value, spec) if math.isfinite(value) else "—"


def table(runs: Sequence[Mapping[str, Any]]) -> str:
    """One Markdown row per run: the figures of :data:`FIGURES` and the targets' verdict."""
    head = ["run", *(label for _, label, _, _ in FIGURES), "clients per process", "targets"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in runs:
        cells = [run_key(r)]
        cells += [_fmt(figure(r, key), spec) for key, _, _, spec in FIGURES]
        cells.append("/".join(str(n) for n in r["main"]["clients_per_process"]) or "—")
        cells.append(verdicts(r))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def load(path: Path) -> dict[str, dict[str, Any]]:
    """The runs of a saved file, by :func:`run_key`.

    Raises:
        BadOption: the file is missing, too large, not JSON or not a saved run.
    """
    try:
        size = path.stat().st_size
        if size > MAX_SAVED_BYTES:
            raise BadOption(
                f"{str(path)!r} is {size} bytes, more than a saved classroom run can be "
                f"({MAX_SAVED_BYTES}); give the file --save wrote"
            )
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise BadOption(
            f"no saved classroom run at {str(path)!r}; make one with --save {path}"
        ) from None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise BadOption(
            f"cannot read {str(path)!r} as a saved classroom run ({type(exc).__name__}); "
            "give the file --save wrote"
        ) from None
    runs = data.get("runs") if isinstance(data, dict) else None
    if not isinstance(runs, dict) or data.get("schema") != SCHEMA:
        raise BadOption(
            f"{str(path)!r} is not a saved classroom run (schema {SCHEMA}); "
            "give the file --save wrote"
        )
    good = {}
    for key, run in runs.items():
        if isinstance(run, dict) and isinstance(run.get("main"), dict) and "scene" in run:
            good[str(key)] = run
    return good


def save(path: Path, runs: Sequence[Mapping[str, Any]]) -> None:
    """Write ``runs`` to ``path``, keeping the saved runs of other scenes and sizes."""
    kept: dict[str, Any] = {}
    if path.exists():
        try:
            kept = load(path)
        except BadOption:
            kept = {}
    for r in runs:
        kept[run_key(r)] = jsonable(dict(r))
    out = {"schema": SCHEMA, "saved": time.strftime("%Y-%m-%d %H:%M:%S %Z"), "runs": kept}
    path.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")


def compare(runs: Sequence[Mapping[str, Any]], saved: Mapping[str, Mapping[str, Any]]) -> str:
    """For each run with a saved counterpart, each figure: new, saved, new / saved."""
    lines = []
    for r in runs:
        key = run_key(r)
        old = saved.get(key)
        if old is None:
            lines.append(f"{key}: no saved run to compare with")
            continue
        lines.append(f"{key} (saved {old.get('date', '?')}):")
        for fkey, label, better, spec in FIGURES:
            new_v, old_v = figure(r, fkey), figure(old, fkey)
            if not (math.isfinite(new_v) and math.isfinite(old_v)):
                continue
            if old_v == 0:
                ratio = "same" if new_v == 0 else "new"
                word = ""
            else:
                q = new_v / old_v
                ratio = f"×{q:.2f}"
                up = q > 1.0
                word = (
                    ""
                    if abs(q - 1.0) < 0.05 or not better
                    else ("better" if up == (better == "higher") else "WORSE")
                )
            lines.append(
                f"  {label:<16} {_fmt(new_v, spec):>8}  saved {_fmt(old_v, spec):>8}  "
                f"{ratio:>7} {word}".rstrip()
            )
        lines += _at_saved_speed(r, old)
    return "\n".join(lines)


def _at_saved_speed(new: Mapping[str, Any], old: Mapping[str, Any]) -> list[str]:
    """The CPU per frame the new run would have taken at the saved run's machine speed
    (its probe timing scaled back), when both runs timed the machine; else nothing."""
    new_probe, old_probe = figure(new, "machine_probe_ms"), figure(old, "machine_probe_ms")
    cpu_new, cpu_old = (
        figure(new, "server_cpu_ms_per_frame"),
        figure(old, "server_cpu_ms_per_frame"),
    )
    if not all(math.isfinite(v) and v > 0 for v in (new_probe, old_probe, cpu_new, cpu_old)):
        return []
    speed = new_probe / old_probe  # > 1: this machine ran slower than at the saved run
    adjusted = cpu_new / speed
    q = adjusted / cpu_old
    word = "" if abs(q - 1.0) < 0.05 else ("better" if q < 1.0 else "WORSE")
    return [
        f"  machine ran ×{speed:.2f} the saved run's time for the same work; CPU ms/frame "
        f"at the saved speed {adjusted:.2f}  saved {cpu_old:.2f}  ×{q:.2f} {word}".rstrip()
    ]
