"""``sandbox run``: simulate without a browser, write the readouts and summarise.

``sandbox run`` validates everything before simulating: the output file is created (under
a temporary name, renamed at the end) before the first step, and a run is bounded by
:data:`sandbox.runner.MAX_STEPS` steps and :data:`sandbox.runner.MAX_ROWS` rows; MJCF
files are bounded by the limits of :mod:`sandbox.physics.model`. A disk that fills up
is one line too, and a recording with no frame is removed.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import os
import shlex
import shutil
import sys
from collections.abc import Mapping
from pathlib import Path

from sandbox.accuracy import cheapest, most_accurate
from sandbox.bench import load_results
from sandbox.cli.options import no_nul, own_source, pairs
from sandbox.errors import BadOption, shown
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder
from sandbox.runner import RowWriter, check_out, check_run, simulate, special_file


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


def _exact(args: argparse.Namespace, sim: Simulation) -> None:
    """``--tolerance`` with an imposed motion: nothing to choose, it is exact (says so on
    stderr, with the error the benchmark measured against the course).

    Raises:
        BadOption: with --integrator or --timestep, or outside (0, 1), as for a choice.
    """
    tol = args.tolerance
    if args.integrator is not None or args.timestep is not None:
        raise BadOption("give --tolerance or --integrator/--timestep, not both")
    if not 0 < tol < 1:
        raise BadOption(f"--tolerance is a relative error in (0, 1), got {tol:g}; e.g. 1e-4")
    result = load_results(sim.label)
    measured = result.imposed if result is not None else None
    error = (
        f"error {measured.error:.2g} on {result.key} against the course"
        if measured is not None and result is not None
        else "error at round-off"
    )
    print(
        f"sandbox: --tolerance {tol:g}: the imposed motion is exact ({error}); "
        "--motion free chooses an integrator and a timestep instead",
        file=sys.stderr,
    )


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
    source = own_source(args.target, args.max_memory)
    values = pairs(args.set)
    if args.tolerance is not None:
        probe = Simulation(source, values=values, motion=args.motion)
        if probe.motion == "imposed":
            _exact(args, probe)
        else:
            integrator, timestep = _for_tolerance(args)
    sim = Simulation(
        source,
        values=values,
        integrator=integrator,
        timestep=timestep,
        motion=args.motion,
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
    how = (
        f"imposed motion, exact: closure equations and inverse dynamics every {sim.timestep:g} s"
        if sim.motion == "imposed"
        else f"{sim.integrator}, dt = {sim.timestep:g} s"
    )
    print(
        f"{sim.label}: {args.duration:g} s simulated ({how})"
        + (f", {writer.count} rows written to {args.out}" if writer is not None else "")
    )
    scene_names = [r.name for r in sim.scene.readouts] if sim.scene else ["T", "V", "P_acc"]
    for name in scene_names:
        value = rows[-1][columns.index(name)] + 0.0  # "-0" is no number to read: 0
        extra = f"   (course: {ref[name] + 0.0:.6g})" if name in ref else ""
        print(f"  {name:<18} {value:>14.6g} {units[name]}{extra}")
    if recorder is not None:
        print(
            f"recording: {recorder.frames} frames written to {recorder.path.absolute()}; "
            f"replay it with: sandbox replay {shlex.quote(str(recorder.path))}"
        )
    return 0


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
    no_nul(path, "--record")
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
