"""``sandbox bench --classroom``: the command's entry.

Usage::

    sandbox bench --classroom 30 --all [--seconds 10] [--save bench/classroom.json]
    sandbox bench --classroom 30 --all --compare bench/classroom.json
    sandbox bench --classroom 60 rotor --compare bench/classroom.json
    sandbox bench --classroom 30 rotor --flood     # plus a student flooding "Pas"
    sandbox bench --classroom 30 rotor --studies 5 # 25 measured, 5 running studies
    sandbox bench --classroom 30 --all --busy-core # one core kept busy by another program

Each scene runs as :func:`sandbox.bench.classroom.run.run_classroom` does alone (its own
server, N headless browsers, each pressing « Lecture » when the scene opens paused);
``--all`` leaves out the connect-and-drop phase (13 s a scene) that a single run keeps.
``--save`` and ``--compare`` keep and compare the runs (:mod:`sandbox.bench.classroom.suite`).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sandbox.bench.classroom import flood as classroom_flood
from sandbox.bench.classroom import studies as classroom_studies
from sandbox.bench.classroom.report import jsonable, report
from sandbox.bench.classroom.run import run_classroom
from sandbox.bench.classroom.suite import compare, load, run_key, save, table
from sandbox.errors import BadOption
from sandbox.scenes import DEFAULT_SCENE, SCENES

if TYPE_CHECKING:
    import argparse


def scenes_of(args: argparse.Namespace) -> list[str]:
    """The scenes a ``--classroom`` command runs (``--all``: every registered scene)."""

    scenes = list(args.scenes or ())
    if getattr(args, "all", False):
        if scenes:
            raise BadOption(
                f"--all runs every scene: drop {' '.join(scenes)}, or drop --all to run those"
            )
        return list(SCENES)
    if len(scenes) > 1:
        raise BadOption(
            f"--classroom takes one scene, got {len(scenes)}: {' '.join(scenes)} "
            "(--all runs every scene)"
        )
    return scenes or [DEFAULT_SCENE]


def _json_path(value: Path | None, option: str) -> Path | None:
    if value is None:
        return None
    if value.suffix.lower() != ".json":
        raise BadOption(f"{option} needs a .json file, got {str(value)!r}")
    if not value.parent.exists():
        raise BadOption(f"folder {str(value.parent)!r} of {option} does not exist; create it")
    return value


def cli_classroom(
    args: argparse.Namespace, *, run: Callable[..., dict[str, Any]] = run_classroom
) -> int:
    """``sandbox bench --classroom N [SCENE | --all] [--follow] [--seconds S]
    [--out FILE.json] [--save FILE.json] [--compare FILE.json]``."""
    clients = int(args.classroom)
    if not 1 <= clients <= 200:
        raise BadOption(f"--classroom needs 1 to 200 clients, got {clients!r}")
    scenes = scenes_of(args)
    studies = int(getattr(args, "studies", None) or 0)
    videos = int(getattr(args, "videos", None) or 0)
    option = "--videos" if videos else "--studies"
    if studies and videos:
        raise BadOption("give --studies or --videos, not both")
    studies = studies or videos
    if studies and not 1 <= studies < clients:
        raise BadOption(f"{option} needs 1 to {clients - 1} students (of --classroom {clients})")
    if studies and (getattr(args, "flood", False) or getattr(args, "follow", False)):
        raise BadOption(f"{option} goes alone: drop --flood and --follow")
    seconds = float(args.seconds) if getattr(args, "seconds", None) else 15.0
    out: Path | None = getattr(args, "out", None)
    if out is not None and out.suffix.lower() != ".json":
        out = None  # the grid's --out folder: not for this command
    if out is not None and not out.parent.exists():
        raise BadOption(f"folder {str(out.parent)!r} of --out does not exist; create it first")
    save_to = _json_path(getattr(args, "save", None), "--save")
    compare_to = _json_path(getattr(args, "compare", None), "--compare")
    saved = load(compare_to) if compare_to is not None else {}
    many = len(scenes) > 1
    runs = []
    for scene in scenes:
        follow = bool(getattr(args, "follow", False))
        side = classroom_flood.side(follow=follow) if getattr(args, "flood", False) else None
        if studies:
            work = classroom_studies.VIDEO if videos else classroom_studies.STUDY
            side = classroom_studies.side(studies, work)
        results = run(
            scene,
            clients - studies,
            seconds=seconds,
            follow=follow,
            workers=getattr(args, "workers", None),
            drop_clients=0 if many else 20,
            progress=lambda line: print(line, file=sys.stderr, flush=True),
            side=side,
            busy_core=bool(getattr(args, "busy_core", False)),
        )
        runs.append(results)
        print(report(results), flush=True)
    if many:
        print()
        print(table(runs))
    if compare_to is not None:
        print()
        print(compare(runs, saved))
    if out is not None:
        data = runs[0] if not many else {run_key(r): r for r in runs}
        out.write_text(json.dumps(jsonable(data), indent=2) + "\n", encoding="utf-8")
        print(f"written: {out}")
    if save_to is not None:
        save(save_to, runs)
        print(f"saved: {save_to}")
    return 0
