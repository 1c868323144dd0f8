"""The command line's grammar: ``sandbox [--host H] [--port P] [--workers N] COMMAND ...``,
one sub-parser per command, and argparse's errors as one line (exit code 2, no usage dump).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from importlib import metadata
from pathlib import Path
from typing import NoReturn

from sandbox.errors import BadOption, shown
from sandbox.physics.imposed import MOTIONS
from sandbox.physics.model import INTEGRATORS


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


def version_text() -> str:
    """ "sandbox 0.1.0 (MuJoCo 3.3.0, viser 1.0.0, Python 3.11.2)": what a bug report needs."""

    def of(dist: str) -> str:
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            return "?"

    python = ".".join(str(n) for n in sys.version_info[:3])
    return f"sandbox {of('sandbox')} (MuJoCo {of('mujoco')}, viser {of('viser')}, Python {python})"


def _motion(parser: argparse.ArgumentParser) -> None:
    """``--motion imposed|free``: how a scene whose input the course imposes is computed."""
    parser.add_argument(
        "--motion",
        choices=MOTIONS,
        help="imposed: the input's imposed motion (a crank at constant speed) computed "
        "exactly by the closure equations and inverse dynamics; free: simulated by MuJoCo "
        "(default: the scene's own, see 'sandbox describe')",
    )


def _max_memory(parser: argparse.ArgumentParser) -> None:
    """``--max-memory MB``: what the user's own MJCF file may take to compile."""
    parser.add_argument(
        "--max-memory",
        type=_positive_float("--max-memory"),
        metavar="MB",
        help="what an MJCF file named here may take to compile [MB] (default: half the "
        "machine's memory; files from a browser or a recording stay under 256 MB)",
    )


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
    _max_memory(d)
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
    _motion(r)
    _max_memory(r)
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
    _motion(w)
    _max_memory(w)
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
    _motion(s)
    _max_memory(s)
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
        "--busy-core",
        action="store_true",
        help="--classroom: another program keeps one core busy during the run (a laptop "
        "that also drives a projector and a video call)",
    )
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
