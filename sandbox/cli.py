"""Command line: ``sandbox list | describe | run | serve | replay`` (bare ``sandbox`` serves).

Every user error prints one line ``sandbox: error: ...`` and exits with code 2; a
diverging simulation exits with code 3 after writing what was computed so far. Any other
exception (a bug) prints one line ``sandbox: error: internal error: <type>: <message> —
please report it (...)`` and exits with code 1; set the environment variable
``SANDBOX_DEBUG=1`` to get the traceback instead. Ctrl-C exits with code 130, quietly.

``sandbox run`` validates everything before simulating: the output file is created (under
a temporary name, renamed at the end) before the first step, and a run is bounded by
:data:`sandbox.runner.MAX_STEPS` steps and :data:`sandbox.runner.MAX_ROWS` rows; MJCF
files are bounded by the limits of :mod:`sandbox.physics.model`.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import json
import math
import os
import shlex
import shutil
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import NoReturn

import mujoco

from sandbox.errors import BadOption, BadParameter, SandboxError, choices, one_line, shown
from sandbox.launch import INTERRUPTED
from sandbox.physics.model import INTEGRATORS
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, Recording, load, write_csv
from sandbox.runner import RowWriter, check_out, check_run, simulate, special_file
from sandbox.scenes import resolve
from sandbox.scenes.base import Scene

DEBUG_ENV = "SANDBOX_DEBUG"
"""Environment variable: ``1`` re-raises unexpected exceptions (a traceback for developers)."""

MAX_WORKERS = 64
"""Most server processes ``--workers`` may start."""

LESSON_PREFIX = "lesson:"
"""``sandbox serve lesson:NAME`` opens the lesson NAME even when a scene has that name."""

MAX_NAME_CHARS = 200
"""Longest ``--set`` name or value accepted."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit code 2, no usage dump)."""

    def error(self, message: str) -> NoReturn:
        raise BadOption(
            f"{message}; see 'sandbox {self.prog.split()[-1]} --help'"
            if " " in self.prog
            else f"{message}; see 'sandbox --help'"
        )


def _positive_float(kind: str, *, allow_zero: bool = False) -> Callable[[str], float]:
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise BadOption(f"{kind} must be a number, got {shown(text)}") from None
        if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
            need = "zero or positive" if allow_zero else "positive"
            raise BadOption(f"{kind} must be a finite {need} number, got {shown(text)}")
        return value

    return parse


def _pairs(items: Sequence[str]) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise BadParameter(
                f"--set expects NAME=VALUE, got {shown(item)}; e.g. --set speed_rpm=3000"
            )
        if len(name) > MAX_NAME_CHARS or len(value) > MAX_NAME_CHARS or "\x00" in item:
            raise BadParameter(
                f"--set {shown(item)} is not a parameter name and a number; "
                "see 'sandbox describe SCENE' for the names"
            )
        out[name.strip()] = value.strip()
    return out


def version_text() -> str:
    """ "sandbox 0.1.0 (MuJoCo 3.3.0, viser 1.0.0, Python 3.11.2)": what a bug report needs."""
    from importlib import metadata

    def of(dist: str) -> str:
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            return "?"

    python = ".".join(str(n) for n in sys.version_info[:3])
    return f"sandbox {of('sandbox')} (MuJoCo {of('mujoco')}, viser {of('viser')}, Python {python})"


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (exposed for tests and docs)."""
    p = _Parser(prog="sandbox", description="Rigid-body dynamics teaching sandbox.")
    p.add_argument(
        "--version",
        action="version",
        version=version_text(),
        help="print the version of sandbox, MuJoCo and Python, then exit",
    )
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="interface to serve on (0.0.0.0: reachable by the students' machines)",
    )
    p.add_argument("--port", type=int, default=8080, help="port to serve on")
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help=(
            "server processes sharing the port (default: one per core, at most 4; "
            "1: a single process)"
        ),
    )
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
        "--tolerance",
        type=_positive_float("--tolerance"),
        help="relative error wanted on the scene's key quantity (e.g. 1e-4): the cheapest "
        "integrator and timestep of bench/results.json that reach it",
    )
    r.add_argument(
        "--rate",
        type=_positive_float("--rate"),
        default=100.0,
        help="readout rows per simulated second (default 100)",
    )
    r.add_argument("--out", type=Path, help="FILE.csv or FILE.json")
    r.add_argument(
        "--record", type=Path, metavar="FILE", help="also write a recording for 'sandbox replay'"
    )
    w = sub.add_parser(
        "sweep", help="parameter study: one readout over a grid of values, beside the course"
    )
    w.add_argument("target", help="scene name or MJCF file")
    w.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="NAME=START:STOP:COUNT",
        help="a varied parameter (give it twice for a family of curves)",
    )
    w.add_argument(
        "--measure",
        required=True,
        metavar="READOUT[:STAT]",
        help="the readout and what to take of it after --settle: final (default), mean, "
        "max, amplitude, order1, order2 (over the last revolution), period (of its "
        "oscillations), onset (the time it leaves its starting value: a slip, a lift-off)",
    )
    w.add_argument(
        "--duration",
        type=_positive_float("--duration"),
        default=1.0,
        help="simulated time of each run [s] (default 1)",
    )
    w.add_argument(
        "--settle",
        type=_positive_float("--settle", allow_zero=True),
        default=0.0,
        help="simulated time before the samples are taken [s] (default 0)",
    )
    w.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    w.add_argument("--integrator", choices=sorted(INTEGRATORS), help="override the integrator")
    w.add_argument("--timestep", type=_positive_float("--timestep"), help="override dt [s]")
    w.add_argument(
        "--jobs", type=int, default=None, help="processes running the study (default: cores)"
    )
    w.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask distributed cluster (tcp://HOST:8786; the cluster extra)",
    )
    w.add_argument("--out", type=Path, help="FILE.csv or FILE.json")
    w.add_argument("--plot", type=Path, help="FILE.png: the study as a chart, in French")
    s = sub.add_parser("serve", help="start the web sandbox")
    s.add_argument(
        "target",
        nargs="?",
        default=None,
        help="scene, lesson, lesson:NAME (a lesson named like a scene, e.g. "
        "lesson:gyroscope), lesson file (FILE.md) or MJCF file",
    )
    _server_options(s)
    s.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    s.add_argument(
        "--follow",
        action="store_true",
        help="one shared simulation driven by the teacher (secret link printed at start), "
        "watched by every other browser",
    )
    s.add_argument(
        "--public-url",
        metavar="URL",
        help="address students type when they come through a proxy (shown in 'Rejoindre')",
    )
    rp = sub.add_parser("replay", help="replay a recording in the browser, verify or export it")
    rp.add_argument(
        "file",
        type=Path,
        nargs="+",
        help="recording file (sandbox run --record, web app); several with --export",
    )
    _server_options(rp, workers=False)
    rp.add_argument(
        "--verify", action="store_true", help="re-simulate and print the largest deviation"
    )
    rp.add_argument("--export", type=Path, metavar="DIR", help="write a static replay folder")
    rp.add_argument("--csv", type=Path, metavar="OUT.csv", help="write the readouts as CSV")
    rp.add_argument(
        "--salvage", action="store_true", help="accept a recording that was never closed"
    )
    rp.add_argument(
        "--video",
        type=Path,
        metavar="OUT.mp4|OUT.gif",
        help="a video for slides: the mechanism, arrows, key readouts, time (the video extra)",
    )
    rp.add_argument("--size", default="1280x720", metavar="WxH", help="--video: frame size")
    rp.add_argument("--fps", type=int, default=30, metavar="N", help="--video: frames a second")
    rp.add_argument(
        "--from", dest="start", type=float, default=0.0, metavar="S", help="--video: start [s]"
    )
    rp.add_argument("--to", dest="stop", type=float, metavar="S", help="--video: end [s]")
    rp.add_argument(
        "--speed", type=float, default=1.0, metavar="X", help="--video: 0.1 = slow motion ×10"
    )
    rp.add_argument(
        "--plot",
        default="",
        metavar="NAME[,NAME...]",
        help="--video: a strip of these readouts against time, with a moving cursor",
    )
    rp.add_argument(
        "--camera",
        default="scene",
        metavar="PRESET",
        help="--video: scene (the page's view), front, side or top",
    )
    b = sub.add_parser("bench", help="what accuracy costs in time: integrators × timesteps")
    b.add_argument("scenes", nargs="*", metavar="SCENE", help="scenes (default: all)")
    b.add_argument("--quick", action="store_true", help="shorter runs (under 2 minutes)")
    b.add_argument("--out", type=Path, default=Path("bench-results"), metavar="DIR")
    b.add_argument(
        "--merge",
        action="store_true",
        help="keep the other scenes already in DIR/results.json (refresh only SCENE ...)",
    )
    b.add_argument("--effects", action="store_true", help="declared effects vs everything on")
    b.add_argument("--overhead", action="store_true", help="sandbox run vs a bare mj_step loop")
    b.add_argument(
        "--sweep",
        action="store_true",
        help="a study of 50 runs of 2 s (rotor, or SCENE): one process vs every core",
    )
    b.add_argument(
        "--video",
        action="store_true",
        help="30 s of the rotor (or SCENE) recorded, then made a 1280x720 video at 30 fps: "
        "the time it takes and its ratio to the video's length",
    )
    b.add_argument(
        "--classroom",
        type=int,
        metavar="N",
        help="N headless browsers on one server of SCENE (default rotor): frames/s, "
        "sim time rate, CPU, RSS, slider delay (--out FILE.json saves them)",
    )
    b.add_argument("--follow", action="store_true", help="--classroom: serve with --follow")
    b.add_argument(
        "--all", action="store_true", help="--classroom: every scene in turn, then one table"
    )
    b.add_argument(
        "--flood",
        action="store_true",
        help='--classroom: one more student floods "Pas" at dt = 1e-6 s halfway through '
        "(the others' frame rate before and during it)",
    )
    b.add_argument(
        "--studies",
        type=int,
        metavar="K",
        help="--classroom: K of the N browsers run the scene's parameter study again and "
        "again; the other N - K are measured",
    )
    b.add_argument(
        "--videos",
        type=int,
        metavar="K",
        help="--classroom: K of the N browsers click « Exporter une vidéo » again and again; "
        "the other N - K are measured",
    )
    b.add_argument(
        "--save",
        type=Path,
        metavar="FILE.json",
        help="--classroom: keep these runs in FILE.json (other saved runs stay)",
    )
    b.add_argument(
        "--compare",
        type=Path,
        metavar="FILE.json",
        help="--classroom: print each figure's ratio to the run saved in FILE.json",
    )
    b.add_argument(
        "--seconds",
        type=_positive_float("--seconds"),
        metavar="S",
        help="--classroom: measured seconds (default 15)",
    )
    return p


def _server_options(sp: argparse.ArgumentParser, *, workers: bool = True) -> None:
    """--host, --port (and --workers) of a serving command; given before the command
    (``sandbox --host H serve``) they count just the same."""
    sp.add_argument("--host", default=argparse.SUPPRESS, help="interface (default 127.0.0.1)")
    sp.add_argument("--port", type=int, default=argparse.SUPPRESS, help="port (default 8080)")
    if workers:
        sp.add_argument(
            "--workers",
            type=int,
            default=argparse.SUPPRESS,
            help="server processes sharing the port (default: one per core, at most 4)",
        )


def cmd_list() -> int:
    """Print the scenes (and lessons) available."""
    from sandbox.lessons import lessons
    from sandbox.scenes import DEFAULT_SCENE, SCENES

    found = lessons()
    width = max(len(n) for n in (*SCENES, *found))  # one column for every name
    print("Scenes:")
    for scene in SCENES.values():
        mark = " (default)" if scene.name == DEFAULT_SCENE else ""
        print(f"  {scene.name:<{width}} {scene.title}{mark}")
    print("Lessons (sandbox serve LESSON; lesson:LESSON when a scene has its name; or FILE.md):")
    for name, lesson in found.items():
        print(f"  {name:<{width}} {lesson.title} [{lesson.scene}, {len(lesson.steps)} steps]")
    return 0


def describe(target: str) -> dict:
    """JSON-able description of a scene or MJCF file."""
    sim = Simulation(resolve(target))
    scene = sim.scene if isinstance(sim.scene, Scene) else None
    params = [
        {
            "name": p.name,
            "value": sim.values[p.name],
            "unit": p.unit,
            "min": p.min,
            "max": p.max,
            "doc": p.doc,
            # What the French web page shows (added keys; the ones above are contracts).
            "label": p.label,
            "hint": p.hint,
            "display_unit": p.display_unit,
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
        "readouts": [
            {
                "name": r.name,
                "unit": r.unit,
                "doc": r.doc,
                "label": r.label,
                "hint": r.hint,
                "display_unit": r.display_unit,
            }
            for r in sim.readout_infos()
        ],
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
                f"    {p['name']:<16} = {p['value']:<8g} {p['display_unit']:<6} "
                f"[{p['min']:g}, {p['max']:g}]  {p['doc']}"
            )
    print("  readouts:")
    for r in info["readouts"]:
        print(f"    {r['name']:<18} [{r['unit']}]  {r['doc']}")
    return 0


class _Sinks:
    """Every row to the output file and the recording (both opened before the run)."""

    def __init__(self, *sinks: RowWriter | Recorder | None) -> None:
        self.sinks = [s for s in sinks if s is not None]

    def frame(self, values: Mapping[str, float]) -> None:
        for sink in self.sinks:
            sink.frame(values)


def _for_tolerance(args: argparse.Namespace) -> tuple[str, float]:
    """The cheapest (integrator, timestep) of the saved benchmark that reaches
    ``--tolerance`` on the scene's key quantity; says on stderr what it chose and costs.

    Raises:
        BadOption: with --integrator or --timestep, outside (0, 1), for a scene (or file)
            without a benchmark, or out of reach (the best one is named).
    """
    from sandbox.accuracy import cheapest, most_accurate
    from sandbox.bench import load_results

    tol = args.tolerance
    if args.integrator is not None or args.timestep is not None:
        raise BadOption("give --tolerance or --integrator/--timestep, not both")
    if not 0 < tol < 1:
        raise BadOption(f"--tolerance is a relative error in (0, 1), got {tol:g}; e.g. 1e-4")
    result = load_results(str(args.target))
    if result is None:
        raise BadOption(
            f"no benchmark of {shown(str(args.target))} in bench/results.json to choose from; "
            "give --integrator and --timestep"
        )
    run = cheapest(result, tol)
    if run is None:
        best = most_accurate(result)
        hint = (
            f" (the best measured: {best.error:.2g} with {best.integrator} at dt = "
            f"{best.timestep:g} s)"
            if best is not None
            else ""
        )
        raise BadOption(
            f"no measured setting of {args.target} reaches --tolerance {tol:g}{hint}; "
            "ask for a larger tolerance"
        )
    print(
        f"sandbox: --tolerance {tol:g}: {run.integrator} at dt = {run.timestep:g} s "
        f"(error {run.error:.2g} on {result.key} against the course, "
        f"{run.realtime_factor:.3g}x real time on the benchmark's machine)",
        file=sys.stderr,
    )
    return run.integrator, run.timestep


def cmd_run(args: argparse.Namespace) -> int:
    """``sandbox run``: simulate, write readouts, summarise.

    Everything is checked (target, parameters, timestep, duration and rate within the
    step budget, output and recording paths) and the output file created before the
    first step: a refusal costs no simulation and leaves no file behind.
    """
    if args.out is not None:
        check_out(args.out)
    if args.record is not None:
        _check_record(args.record)
        if args.out is not None and args.out.absolute() == args.record.absolute():
            raise BadOption(
                f"--out and --record name the same file {shown(str(args.out))}; give two names"
            )
    integrator, timestep = args.integrator, args.timestep
    if args.tolerance is not None:
        integrator, timestep = _for_tolerance(args)
    sim = Simulation(
        resolve(args.target),
        values=_pairs(args.set),
        integrator=integrator,
        timestep=timestep,
    )
    check_run(args.duration, args.rate, sim.timestep)
    columns = sim.readout_names()
    writer = None if args.out is None else RowWriter(args.out, sim, columns)
    recorder = None
    try:
        if args.record is not None:
            try:
                recorder = Recorder(args.record, sim)
            except OSError as exc:
                raise BadOption(
                    f"cannot create --record {shown(str(args.record))}: {exc.strerror}; "
                    "give another path"
                ) from None
        try:
            columns, rows, error = simulate(
                sim, args.duration, args.rate, recorder=_Sinks(writer, recorder), keep=False
            )
        finally:
            if recorder is not None:
                recorder.close()
        if writer is not None:
            writer.close()
    except BaseException as exc:
        if writer is not None:
            writer.discard()
        if isinstance(exc, OSError) and exc.errno in DISK_FULL:
            where = args.record if recorder is not None else args.out
            if recorder is not None:
                _drop_if_empty(recorder)
            raise BadOption(_disk_full(where)) from None
        raise
    if recorder is not None and recorder.full:
        print(
            f"sandbox: warning: --record {shown(str(args.record))} stopped at "
            f"t = {recorder.stopped_at:g} s, the most one recording holds; lower --rate or "
            "--duration to record the whole run",
            file=sys.stderr,
        )
    if error is not None:
        print(f"sandbox: error: {error}", file=sys.stderr)
        return error.exit_code
    ref = sim.reference()
    units = {r.name: r.unit for r in sim.readout_infos()}
    print(
        f"{sim.label}: {args.duration:g} s simulated ({sim.integrator}, dt = {sim.timestep:g} s)"
        + (f", {writer.count} rows written to {args.out}" if writer is not None else "")
    )
    scene_names = [r.name for r in sim.scene.readouts] if sim.scene else ["T", "V", "P_acc"]
    for name in scene_names:
        value = rows[-1][columns.index(name)]
        extra = f"   (course: {ref[name]:.6g})" if name in ref else ""
        print(f"  {name:<18} {value:>14.6g} {units[name]}{extra}")
    if recorder is not None:
        print(
            f"recording: {recorder.frames} frames written to {recorder.path.absolute()}; "
            f"replay it with: sandbox replay {shlex.quote(str(recorder.path))}"
        )
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    """``sandbox sweep``: a parameter study, checked whole before its first run; a
    progress bar on a terminal; exit 3 when a run diverged (its row is kept)."""
    from tqdm import tqdm  # type: ignore[import-untyped]  # (viser needs it; no stubs)

    from sandbox import sweep
    from sandbox.cores import default_workers

    if args.out is not None:
        check_out(args.out)
    if args.plot is not None:
        check_out(args.plot, "--plot", (".png",))
    study = sweep.Study(
        target=args.target,
        varies=tuple(sweep.parse_vary(v) for v in args.vary),
        measure=sweep.parse_measure(args.measure),
        duration=args.duration,
        settle=args.settle,
        fixed=tuple(_pairs(args.set).items()),
        integrator=args.integrator,
        timestep=args.timestep,
    )
    steps = sweep.check(study)
    runs = len(study.points())
    # a small study runs here: starting processes (about a second each) would cost more
    small = steps * runs < sweep.SMALL_STEPS
    jobs = (1 if small else default_workers()) if args.jobs is None else args.jobs
    if not 1 <= jobs <= MAX_WORKERS:
        raise BadOption(f"--jobs must be 1 to {MAX_WORKERS}, got {args.jobs}")
    with tqdm(
        total=runs, unit="run", file=sys.stderr, disable=not sys.stderr.isatty(), leave=False
    ) as bar:
        rows = sweep.run_study(
            study,
            jobs,
            progress=lambda done: bar.update(done - bar.n),
            scheduler=args.scheduler,
        )
    if args.out is not None:
        sweep.write(args.out, study, rows)
    if args.plot is not None:
        sweep.plot(args.plot, study, rows)
    for line in sweep.table(study, rows):
        print(line)
    diverged = sum(1 for r in rows if r["status"] != "ok")
    print(
        f"{runs} runs of {study.duration:g} s, {study.measure.label}"
        + (f", written to {args.out}" if args.out is not None else "")
    )
    if diverged:
        print(f"sandbox: error: {diverged} of {runs} runs diverged (rows kept)", file=sys.stderr)
        return 3
    return 0


def _bench_sweep(target: str) -> int:
    """``sandbox bench --sweep``: the same study in one process, then on every core."""
    from sandbox import sweep
    from sandbox.cores import default_workers

    study = sweep.bench_study(target)
    cores = default_workers()
    v = study.varies[0]
    print(
        f"{target}: {v.count} runs of {study.duration:g} s, {study.measure.label} over "
        f"{v.name} from {v.start:g} to {v.stop:g}"
    )
    times = {}
    for jobs in dict.fromkeys((1, cores)):
        start = time.perf_counter()
        rows = sweep.run_study(study, jobs)
        times[jobs] = time.perf_counter() - start
        word = "process" if jobs == 1 else "processes"
        print(f"  {jobs} {word:<9} {times[jobs]:6.2f} s  ({len(rows)} rows)")
    if cores > 1:
        ratio = times[1] / times[cores]
        print(
            f"  time in one process / time on {cores}: ×{ratio:.2f}"
            + (" (starting the processes costs more than the runs)" if ratio < 1 else "")
        )
    return 0


def _bench_video(target: str, seconds: float = 30.0) -> int:
    """``sandbox bench --video``: record ``seconds`` of the scene as the page does (a
    frame every 10 ms), then time the video of it at 1280x720 and 30 fps."""
    import tempfile
    import time

    from sandbox.web.video import VideoOptions, render_video

    sim = Simulation(target)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bench.sbx"
        recorder = Recorder(path, sim)
        recorder.frame(sim.readouts())
        while sim.data.time < seconds - 1e-9:
            sim.advance(0.01)
            recorder.frame(sim.readouts())
        recorder.close()
        rec = load(path)
        options = VideoOptions(Path(folder) / "bench.mp4", plots=())
        start = time.perf_counter()
        frames = render_video(rec, options)
        took = time.perf_counter() - start
    length = frames / options.fps
    print(
        f"{target}: {length:.0f} s of video, {frames} frames of 1280x720, made in {took:.1f} s: "
        f"{took / length:.2f} × its length ({took / frames * 1000:.0f} ms a frame)"
    )
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """``sandbox bench``: work-precision grid, or the effects / overhead comparisons."""
    if args.classroom is not None:
        from sandbox.classroom_suite import cli_classroom

        return cli_classroom(args)
    if args.sweep:
        return _bench_sweep(args.scenes[0] if args.scenes else "rotor")
    if args.video:
        return _bench_video(args.scenes[0] if args.scenes else "rotor")
    from sandbox import bench
    from sandbox.scenes import SCENES, get_scene

    names = args.scenes or [n for n, s in SCENES.items() if s.accuracy is not None]
    scenes = [get_scene(n) for n in names]
    for scene in scenes:
        if scene.accuracy is None:
            raise BadOption(f"scene {scene.name!r} has no accuracy measure to benchmark")

    def say(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    if args.effects:
        print(f"{'scene':<18} {'speed ratio':>12} {'error declared':>15} {'error all on':>13}")
        for scene in scenes:
            res = bench.bench_effects(scene, quick=args.quick)
            print(
                f"{scene.name:<18} {res.speed_ratio:>11.2f}x {res.declared.error:>15.2e} "
                f"{res.all_on.error:>13.2e}   drift {res.declared.drift:.1e} -> "
                f"{res.all_on.drift:.1e} ({scene.accuracy.invariant})"  # type: ignore[union-attr]
            )
        print("speed ratio = CPU cost with every effect on / with the scene's effects only")
    if args.overhead:
        print(f"{'scene':<18} {'run / bare':>10} {'x real time':>12}")
        for scene in scenes:
            o = bench.bench_overhead(scene)
            print(f"{scene.name:<18} {o.ratio:>10.2f} {o.realtime_factor:>12.1f}")
        print("goals: run / bare <= 1.25 (readouts at 60 Hz), >= 20x real time at the defaults")
    if args.effects or args.overhead:
        return 0
    _check_folder(args.out, "--out")
    start = time.perf_counter()
    results = []
    for scene in scenes:
        say(f"{scene.name}: {scene.accuracy.key} vs the course ...")  # type: ignore[union-attr]
        results.append(bench.bench_scene(scene, quick=args.quick, progress=say))
    if args.merge:
        results = bench.merge_results(results, args.out / "results.json")
    paths = bench.write_results(results, args.out, quick=args.quick)
    print(bench.markdown(results))
    for result in results:
        d = result.default
        if d is not None:
            mark = "on" if d.pareto else "NOT on"
            print(
                f"{result.scene}: default {d.integrator} dt = {d.timestep:g} s, error "
                f"{d.error:.2e}, {mark} the Pareto front"
            )
    print(f"written: {', '.join(str(p) for p in paths)} ({time.perf_counter() - start:.0f} s)")
    return 0


def _check_folder(path: Path, option: str) -> None:
    """A folder a command writes into (it may not exist yet): refuse a file or a bad name."""
    _no_nul(path, option)
    try:
        if path.exists() and not path.is_dir():
            raise BadOption(f"{option} {shown(str(path))} is a file; give a folder")
    except OSError as exc:
        raise BadOption(f"{option} {shown(str(path))}: {exc.strerror}; give another path") from None


def _no_nul(path: Path, option: str) -> None:
    if "\x00" in str(path):
        raise BadOption(f"{option} {shown(str(path))} contains a NUL character; give another path")


DISK_FULL = frozenset(
    getattr(errno, name) for name in ("ENOSPC", "EDQUOT", "EFBIG") if hasattr(errno, name)
)
"""Write errors that mean "no room left" (disk, quota, file size), not a bug."""


def _disk_full(path: Path | None) -> str:
    """One line: which file could not be written for want of room, and the room left."""
    folder = (path or Path(".")).absolute().parent
    try:
        free = f"{shutil.disk_usage(folder).free / 1e6:.1f} MB free on its disk"
    except OSError:
        free = "free space unknown"
    return (
        f"no space left to write {shown(str(path), limit=300)} ({free}); "
        "free some space or write to another disk"
    )


def _drop_if_empty(recorder: Recorder) -> None:
    """After a failed write, remove a recording that holds no frame (a partial one with
    frames stays: 'sandbox replay --salvage' reads what it holds)."""
    with contextlib.suppress(Exception):
        recorder.close()
    if recorder.frames == 0:
        with contextlib.suppress(OSError):
            recorder.path.unlink()


def _check_record(path: Path) -> None:
    name = shown(str(path))
    _no_nul(path, "--record")
    try:
        if path.is_dir():
            raise BadOption(f"--record {name} is a directory; give a file name such as r.sbx")
        special = special_file(path)
        if special is not None:
            raise BadOption(f"--record {name} is {special}, not a file; give a file name")
        if not path.parent.exists():
            raise BadOption(
                f"folder {shown(str(path.parent))} of --record does not exist; create it first"
            )
        if not path.parent.is_dir():
            raise BadOption(
                f"--record {name}: {shown(str(path.parent))} is a file, not a folder; "
                "give a path in an existing folder"
            )
    except OSError as exc:
        raise BadOption(f"--record {name}: {exc.strerror}; give another path") from None
    if not os.access(path.parent, os.W_OK | os.X_OK):
        raise BadOption(f"--record {name} cannot be written (permission denied); give another path")


def _video(rec: Recording, args: argparse.Namespace) -> None:
    """``replay --video``: checked before any frame, a progress bar on a terminal."""
    from tqdm import tqdm

    from sandbox.web.video import VideoOptions, check, render_video
    from sandbox.web.video_options import parse_size

    options = VideoOptions(
        args.video,
        size=parse_size(args.size),
        fps=args.fps,
        start=args.start,
        stop=args.stop,
        speed=args.speed,
        plots=tuple(n.strip() for n in str(args.plot).split(",") if n.strip()),
        camera=args.camera,
    )
    check(options, rec)
    total = len(options.times(rec))
    with tqdm(total=total, unit="image", disable=not sys.stderr.isatty(), leave=False) as bar:
        frames = render_video(rec, options, lambda done, _: bar.update(done - bar.n))
    seconds = frames / options.fps
    print(f"video written to {args.video}: {frames} frames, {seconds:.1f} s at {options.fps} fps")


def cmd_replay(args: argparse.Namespace) -> int:
    """``sandbox replay``: serve a recording, or verify / export / convert it."""
    files: list[Path] = list(args.file)
    others = args.verify or args.csv is not None or args.video is not None
    if len(files) > 1 and (args.export is None or others):
        raise BadOption("give one recording (several go together only with --export DIR)")
    recs = [load(f, salvage=args.salvage) for f in files]
    for path, one in zip(files, recs, strict=True):
        if not one.complete:
            print(
                f"sandbox: warning: {path} was not closed; replaying its {one.duration:.2f} s",
                file=sys.stderr,
            )
    rec = recs[0]
    offline = (
        args.verify or args.export is not None or args.csv is not None or args.video is not None
    )
    if args.video is not None:
        _video(rec, args)
    if args.csv is not None:
        try:
            usable = not args.csv.is_dir() and args.csv.parent.is_dir()
        except (OSError, ValueError):  # a name too long, a NUL
            usable = False
        if not usable:
            raise BadOption(f"--csv {shown(str(args.csv))}: give a file in an existing folder")
        n = write_csv(rec, args.csv)
        print(f"{n} rows of {len(rec.names)} readouts written to {args.csv}")
    if args.export is not None:
        _check_folder(args.export, "--export")
        from sandbox.web.pack import export_pack

        index = export_pack(recs, args.export)
        print(
            f"lesson pack written to {index}: {len(recs)} recording(s), each a video with "
            "its plots and lesson steps, and a 3D view (open it in a browser; no Python needed)"
        )
    if args.verify:
        from sandbox.replay import verify

        result = verify(rec)
        if result.model.warning:
            print(f"sandbox: warning: {result.model.warning}", file=sys.stderr)
        worst, frames = result.deviation, result.frames
        print(
            f"verify: {frames} frames re-simulated with {result.model.description}, "
            f"maximum deviation {worst:.3g}"
        )
        if worst != 0.0:
            print(
                "sandbox: warning: the re-simulation differs from the recording (another "
                "MuJoCo version or platform?)",
                file=sys.stderr,
            )
    if offline:
        return 0
    from sandbox.web.player import serve_replay

    _check_port_range(args.port)
    serve_replay(rec, host=args.host, port=args.port)
    return 0


def _check_port_range(port: int) -> None:
    if not 0 <= port <= 65535:
        raise BadOption(f"--port must be between 0 and 65535, got {port!r}")


def cmd_serve(
    target: str | None,
    host: str,
    port: int,
    sets: Sequence[str],
    workers: int | None = None,
    follow: bool = False,
    public_url: str | None = None,
) -> int:
    """``sandbox serve``: start the web app (blocks until Ctrl-C).

    ``target`` is a scene name, a lesson name (a scene of the same name wins: write
    ``lesson:NAME`` for the lesson), the path of a lesson file (``*.md``, parsed and
    validated here: its errors are one line) or the path of an MJCF file."""
    from sandbox.lessons import (
        ANY_SCENE,
        UnknownLesson,
        catalogue,
        is_lesson_file,
        open_lesson_file,
    )
    from sandbox.scenes import DEFAULT_SCENE, SCENES
    from sandbox.web.app import serve

    _check_port_range(port)
    target = target or DEFAULT_SCENE
    named = target.startswith(LESSON_PREFIX)  # a lesson, even one named like a scene
    name = target.removeprefix(LESSON_PREFIX)
    lesson = None
    scene = None
    if is_lesson_file(name):
        path = Path(name)
        scene = open_lesson_file(path).scene
        lesson = str(path.resolve())  # opened again by each worker process
    # One broken lesson file does not stop the good ones: it is named once here (and listed
    # in the web "Leçon" folder); serving the broken lesson itself is refused with its error.
    good, refused = catalogue()
    for error in refused:
        if lesson is None and (named or name not in SCENES):
            if f"{os.sep}{name}.md:" in f"{os.sep}{error}":
                raise error
        print(f"sandbox: warning: lesson skipped: {error}", file=sys.stderr)
    if lesson is None and named and name not in good:
        raise UnknownLesson(
            f"unknown lesson {shown(name)}; lessons: {choices(good) or 'none'} "
            "(or the path of a lesson file, FILE.md)"
        )
    if lesson is None and (named or name not in SCENES) and name in good:
        lesson = name
        scene = good[name].scene
    if scene is not None:
        target = DEFAULT_SCENE if scene == ANY_SCENE else scene
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise BadOption(f"--workers must be between 1 and {MAX_WORKERS}, got {workers!r}")
    options: dict[str, object] = {"follow": True} if follow else {}
    if public_url:
        if not public_url.startswith(("http://", "https://")) or len(public_url) > 200:
            raise BadOption(
                f"--public-url must be an http:// or https:// address, got {public_url[:80]!r}; "
                "e.g. --public-url http://sandbox.lycee.fr"
            )
        options["public_url"] = public_url
    serve(
        target,
        host=host,
        port=port,
        values=_pairs(sets),
        lesson=lesson,
        workers=workers,
        **options,
    )
    return 0


MAX_HELD_WARNINGS = 10
"""MuJoCo warnings kept for the end of a command (the rest are dropped)."""


@contextlib.contextmanager
def _held_mujoco_warnings(held: list[str]) -> Iterator[None]:
    """Collect MuJoCo's warnings (printed on stderr by default) instead of printing them."""

    def keep(text: object) -> None:
        if len(held) < MAX_HELD_WARNINGS:
            held.append(one_line(str(text)))

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(keep)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``sandbox`` console script; returns the exit code.

    Outside ``serve``, MuJoCo's warnings (printed by default on stderr, e.g. before a
    divergence) are held back: shown as ``sandbox: warning: MuJoCo: ...`` lines after a
    successful command, dropped after an error, whose one line says what happened.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    held: list[str] = []
    try:
        args = build_parser().parse_args(argv)
        if args.command in (None, "serve"):
            return cmd_serve(
                getattr(args, "target", None),
                getattr(args, "host", "127.0.0.1"),
                getattr(args, "port", 8080),
                getattr(args, "set", []),
                getattr(args, "workers", None),
                getattr(args, "follow", False),
                getattr(args, "public_url", None),
            )
        with _held_mujoco_warnings(held):
            code = _dispatch(args)
    except SandboxError as exc:
        print(f"sandbox: error: {one_line(str(exc))}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        return INTERRUPTED
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0
    except Exception as exc:  # a bug: one line, never a traceback (SANDBOX_DEBUG=1 shows it)
        if os.environ.get(DEBUG_ENV) == "1":
            raise
        return _internal_error(exc)
    if code == 0:
        for text in dict.fromkeys(held):
            print(f"sandbox: warning: MuJoCo: {text}", file=sys.stderr)
    return code


def _dispatch(args: argparse.Namespace) -> int:
    if args.command == "list":
        return cmd_list()
    if args.command == "describe":
        return cmd_describe(args.target, args.json)
    if args.command == "replay":
        return cmd_replay(args)
    if args.command == "bench":
        return cmd_bench(args)
    if args.command == "sweep":
        return cmd_sweep(args)
    return cmd_run(args)


def _internal_error(exc: BaseException) -> int:
    """Print the last-resort line for an unexpected exception; exit code 1."""
    text = one_line(str(exc))
    text = text if len(text) <= 300 else text[:297] + "..."
    print(
        f"sandbox: error: internal error: {type(exc).__name__}: {text} — please report it "
        f"(with the command; {DEBUG_ENV}=1 shows the traceback)",
        file=sys.stderr,
    )
    return 1


if __name__ == "__main__":
    sys.exit(main())
