"""``sandbox sweep``: a parameter study (:mod:`sandbox.sweep`) from the command line,
checked whole before its first run, with a progress bar on a terminal; its rows as a
table, a file or a chart.
"""

from __future__ import annotations

import argparse
import sys

from tqdm import tqdm  # type: ignore[import-untyped]  # (viser needs it; no stubs)

from sandbox import sweep
from sandbox.cli.options import MAX_WORKERS, own_source, pairs
from sandbox.cores import default_workers
from sandbox.errors import BadOption
from sandbox.runner import check_out


def cmd_sweep(args: argparse.Namespace) -> int:
    """``sandbox sweep``: a parameter study, checked whole before its first run; a
    progress bar on a terminal; exit 3 when a run diverged (its row is kept)."""
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
        fixed=tuple(pairs(args.set).items()),
        integrator=args.integrator,
        timestep=args.timestep,
        motion=args.motion,
        max_bytes=own_source(args.target, args.max_memory).max_bytes,
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
