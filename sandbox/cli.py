"""Command line: ``sandbox list | describe | run | serve`` (bare ``sandbox`` serves).

Every user error prints one line ``sandbox: error: ...`` and exits with code 2; a
diverging simulation exits with code 3 after writing what was computed so far.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from sandbox.errors import BadOption, BadParameter, Diverged, SandboxError
from sandbox.physics.model import INTEGRATORS, resolve
from sandbox.physics.simulation import Simulation


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit code 2, no usage dump)."""

    def error(self, message: str) -> NoReturn:
        raise BadOption(
            f"{message}; see 'sandbox {self.prog.split()[-1]} --help'"
            if " " in self.prog
            else f"{message}; see 'sandbox --help'"
        )


def _positive_float(kind: str, *, allow_zero: bool = False):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise BadOption(f"{kind} must be a number, got {text!r}") from None
        if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
            need = "zero or positive" if allow_zero else "positive"
            raise BadOption(f"{kind} must be {need}, got {text!r}")
        return value

    return parse


def _pairs(items: Sequence[str]) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise BadParameter(f"--set expects NAME=VALUE, got {item!r}; e.g. --set speed_rpm=3000")
        out[name.strip()] = value.strip()
    return out


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (exposed for tests and docs)."""
    p = _Parser(prog="sandbox", description="Rigid-body dynamics teaching sandbox.")
    sub = p.add_subparsers(dest="command", parser_class=_Parser)
    sub.add_parser("list", help="list scenes and lessons")
    d = sub.add_parser("describe", help="parameters, effects and readouts of a scene or file")
    d.add_argument("target", help="scene name or MJCF file")
    d.add_argument("--json", action="store_true", help="machine-readable output")
    r = sub.add_parser("run", help="simulate without a browser and write readouts")
    r.add_argument("target", help="scene name or MJCF file")
    r.add_argument(
        "--duration",
        type=_positive_float("--duration", allow_zero=True),
        default=1.0,
        help="simulated time [s] (default 1)",
    )
    r.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a parameter (repeatable)",
    )
    r.add_argument("--integrator", choices=sorted(INTEGRATORS), help="override the integrator")
    r.add_argument("--timestep", type=_positive_float("--timestep"), help="override dt [s]")
    r.add_argument(
        "--rate",
        type=_positive_float("--rate"),
        default=100.0,
        help="readout rows per simulated second (default 100)",
    )
    r.add_argument("--out", type=Path, help="FILE.csv or FILE.json")
    s = sub.add_parser("serve", help="start the web sandbox")
    s.add_argument("target", nargs="?", default=None, help="scene name or MJCF file")
    s.add_argument("--host", default="127.0.0.1")
    s.add_argument("--port", type=int, default=8080)
    s.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    return p


def cmd_list() -> int:
    """Print the scenes (and lessons) available."""
    from sandbox.scenes import DEFAULT_SCENE, SCENES

    print("Scenes:")
    for scene in SCENES.values():
        mark = " (default)" if scene.name == DEFAULT_SCENE else ""
        print(f"  {scene.name:<18} {scene.title}{mark}")
    return 0


def describe(target: str) -> dict:
    """JSON-able description of a scene or MJCF file."""
    sim = Simulation(resolve(target))
    scene = sim.scene
    params = [
        {
            "name": p.name,
            "value": sim.values[p.name],
            "unit": p.unit,
            "min": p.min,
            "max": p.max,
            "doc": p.doc,
        }
        for p in (scene.params if scene else ())
    ]
    return {
        "name": sim.label,
        "title": scene.title if scene else sim.label,
        "effects": list(scene.effects.simulated()) if scene else ["file options"],
        "hypotheses": list(scene.effects.hypotheses()) if scene else [],
        "integrator": sim.integrator,
        "timestep": sim.timestep,
        "params": params,
        "readouts": [{"name": r.name, "unit": r.unit, "doc": r.doc} for r in sim.readout_infos()],
    }


def cmd_describe(target: str, as_json: bool) -> int:
    """Print :func:`describe` as JSON or text."""
    info = describe(target)
    if as_json:
        print(json.dumps(info, indent=2, ensure_ascii=False))
        return 0
    print(f"{info['name']}: {info['title']}")
    effects = ", ".join(info["effects"])
    print(f"  effects: {effects}; {info['integrator']}, dt = {info['timestep']:g} s")
    if info["params"]:
        print("  parameters:")
        for p in info["params"]:
            print(
                f"    {p['name']:<16} = {p['value']:<8g} {p['unit']:<6} "
                f"[{p['min']:g}, {p['max']:g}]  {p['doc']}"
            )
    print("  readouts:")
    for r in info["readouts"]:
        print(f"    {r['name']:<18} [{r['unit']}]  {r['doc']}")
    return 0


def _check_out(out: Path | None) -> None:
    if out is None:
        return
    if out.suffix.lower() not in (".csv", ".json"):
        raise BadOption(f"--out {str(out)!r} must end in .csv or .json")
    if out.is_dir():
        raise BadOption(f"--out {str(out)!r} is a directory; give a file name such as run.csv")
    if not out.parent.exists():
        raise BadOption(f"folder {str(out.parent)!r} of --out does not exist; create it first")


def simulate(sim: Simulation, duration: float, rate: float, progress: bool = True):
    """Run ``duration`` seconds, sampling every readout ``rate`` times per second.

    Returns:
        (columns, rows, error) where error is a :class:`Diverged` or None; rows computed
        before a divergence are kept.
    """
    columns = sim.readout_names()
    dt = sim.timestep
    per_row = max(1, round(1.0 / (rate * dt)))
    total = int(round(duration / dt))
    rows = [list(sim.readouts(columns).values())]
    done, start, shown = 0, time.perf_counter(), time.perf_counter()
    try:
        while done < total:
            n = min(per_row, total - done)
            sim.step(n)
            done += n
            rows.append(list(sim.readouts(columns).values()))
            now = time.perf_counter()
            if progress and now - shown > 2.0:
                shown = now
                pct = 100.0 * done / total
                rtf = sim.data.time / (now - start)
                print(
                    f"  {pct:5.1f}%  t = {sim.data.time:.3f} s  ({rtf:.1f}x real time)",
                    file=sys.stderr,
                    flush=True,
                )
    except Diverged as exc:
        return columns, rows, exc
    return columns, rows, None


def write_rows(out: Path, sim: Simulation, columns: list[str], rows: list[list[float]]) -> None:
    """Write readout rows to CSV (header = column names) or JSON (with units and metadata)."""
    if out.suffix.lower() == ".csv":
        with out.open("w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(columns)
            writer.writerows([[f"{v:.10g}" for v in row] for row in rows])
        return
    units = {r.name: r.unit for r in sim.readout_infos()}
    doc = {
        "scene": sim.label,
        "params": sim.values,
        "integrator": sim.integrator,
        "timestep": sim.timestep,
        "columns": columns,
        "units": units,
        "rows": [[v if math.isfinite(v) else None for v in row] for row in rows],
    }
    out.write_text(json.dumps(doc))


def cmd_run(args: argparse.Namespace) -> int:
    """``sandbox run``: simulate, write readouts, summarise."""
    _check_out(args.out)
    sim = Simulation(
        resolve(args.target),
        values=_pairs(args.set),
        integrator=args.integrator,
        timestep=args.timestep,
    )
    columns, rows, error = simulate(sim, args.duration, args.rate)
    if args.out is not None:
        write_rows(args.out, sim, columns, rows)
    if error is not None:
        print(f"sandbox: error: {error}", file=sys.stderr)
        return error.exit_code
    ref = sim.reference()
    units = {r.name: r.unit for r in sim.readout_infos()}
    print(
        f"{sim.label}: {args.duration:g} s simulated ({sim.integrator}, dt = {sim.timestep:g} s)"
        + (f", {len(rows)} rows written to {args.out}" if args.out else "")
    )
    scene_names = [r.name for r in sim.scene.readouts] if sim.scene else ["T", "V", "P_acc"]
    for name in scene_names:
        value = rows[-1][columns.index(name)]
        extra = f"   (course: {ref[name]:.6g})" if name in ref else ""
        print(f"  {name:<18} {value:>14.6g} {units[name]}{extra}")
    return 0


def cmd_serve(target: str | None, host: str, port: int, sets: Sequence[str]) -> int:
    """``sandbox serve``: start the web app (blocks until Ctrl-C)."""
    from sandbox.scenes import DEFAULT_SCENE
    from sandbox.web.app import serve

    if not 0 <= port <= 65535:
        raise BadOption(f"--port must be between 0 and 65535, got {port!r}")
    serve(target or DEFAULT_SCENE, host=host, port=port, values=_pairs(sets))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``sandbox`` console script; returns the exit code."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = build_parser().parse_args(argv)
        if args.command in (None, "serve"):
            return cmd_serve(
                getattr(args, "target", None),
                getattr(args, "host", "127.0.0.1"),
                getattr(args, "port", 8080),
                getattr(args, "set", []),
            )
        if args.command == "list":
            return cmd_list()
        if args.command == "describe":
            return cmd_describe(args.target, args.json)
        return cmd_run(args)
    except SandboxError as exc:
        print(f"sandbox: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
