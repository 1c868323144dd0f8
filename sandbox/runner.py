"""The sampling loop shared by ``sandbox run`` and ``sandbox bench``, and the row writers.

:func:`simulate` steps a :class:`~sandbox.physics.simulation.Simulation` in C by chunks
of whole timesteps and takes a row of readouts between chunks; a divergence stops it and
keeps the rows computed so far. :func:`write_rows` writes them as CSV or JSON (the
columns are the readouts' names: a contract with the students' scripts).

Layer: above physics and scenes, below recording, bench, lessons, replay, web and cli
(see ``tests/test_layers.py``).
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import secrets
import stat
import sys
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import IO, Protocol

from sandbox.errors import BadOption, Diverged, shown
from sandbox.physics.simulation import Simulation

PROGRESS_PERIOD = 2.0
"""Wall seconds between two progress lines on stderr."""

MAX_STEPS = 10_000_000
"""Most timesteps one run may take (duration / timestep): 10 to 100 s of CPU for the
scenes (1 to 10 µs a step); beyond, a typo such as ``--duration 1e300`` would run for
ever. The web app may use it as a budget too."""

MAX_ROWS = 1_000_000
"""Most rows one run may write (duration x rate + 1): about 400 MB of CSV."""

MIN_RATE = 1e-3
"""Slowest sampling rate [rows per simulated second]."""

MAX_RATE = 1e6
"""Fastest sampling rate [rows per simulated second] (a rate above 1 / timestep takes a
row every step anyway)."""


def check_run(duration: float, rate: float, timestep: float) -> tuple[int, int]:
    """Validate a run and return :func:`chunks` (steps in all, steps between rows).

    Raises:
        BadOption: a duration or rate that is not a finite number in range, or a run
            over :data:`MAX_STEPS` steps or :data:`MAX_ROWS` rows (the message says the
            longest duration that fits).
    """
    if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration >= 0):
        raise BadOption(f"--duration must be zero or a positive number, got {duration!r}")
    if not (isinstance(rate, (int, float)) and math.isfinite(rate)) or not (
        MIN_RATE <= rate <= MAX_RATE
    ):
        raise BadOption(
            f"--rate {rate!r} is outside [{MIN_RATE:g}, {MAX_RATE:g}] rows per second; "
            "e.g. --rate 100"
        )
    steps = duration / timestep
    if steps > MAX_STEPS:
        raise BadOption(
            f"--duration {duration:g} s at dt = {timestep:g} s takes {steps:.3g} steps "
            f"(max {MAX_STEPS:,}); simulate at most {MAX_STEPS * timestep:g} s, or give a "
            "larger --timestep"
        )
    rows = min(duration * rate, steps) + 1
    if rows > MAX_ROWS:
        raise BadOption(
            f"--duration {duration:g} s at --rate {rate:g} writes {rows:.3g} rows "
            f"(max {MAX_ROWS:,}); give a smaller --rate"
        )
    return chunks(duration, rate, timestep)


class FrameSink(Protocol):
    """What :func:`simulate` feeds each row to (a :class:`~sandbox.recording.Recorder`)."""

    def frame(self, values: Mapping[str, float]) -> None: ...


def chunks(duration: float, rate: float, timestep: float) -> tuple[int, int]:
    """(steps in all, steps between two rows) to sample ``duration`` seconds ``rate``
    times per simulated second at ``timestep`` [s] (at least one step between rows)."""
    total = int(round(duration / timestep))
    per_row = max(1, round(1.0 / (rate * timestep)))
    return total, per_row


def simulate(
    sim: Simulation,
    duration: float,
    rate: float,
    progress: bool = True,
    recorder: FrameSink | None = None,
    *,
    names: Iterable[str] | None = None,
    keep: bool = True,
) -> tuple[list[str], list[list[float]], Diverged | None]:
    """Run ``duration`` seconds, sampling the readouts ``rate`` times per second.

    Args:
        sim: The simulation, at its starting state (the first row is taken there).
        duration: Simulated time [s] (rounded to whole timesteps; 0 gives one row).
        rate: Rows per simulated second (at most one per timestep).
        progress: Print a progress line on stderr every :data:`PROGRESS_PERIOD` s.
        recorder: Also given every row (``frame(values)``).
        names: Readouts sampled (default: every readout, in column order).
        keep: Keep every row (False: only the last one; the recorder, e.g. a
            :class:`RowWriter`, has them all, and memory stays bounded).

    Returns:
        (columns, rows, error): the readout names, one row of values per sample
        (shape (n, len(columns))), and the :class:`~sandbox.errors.Diverged` that
        stopped the run or None; rows computed before a divergence are kept.

    Raises:
        BadOption: see :func:`check_run` (nothing is simulated).
    """
    columns = sim.readout_names() if names is None else list(names)
    total, per_row = check_run(duration, rate, sim.timestep)
    rows: list[list[float]] = []

    def sample() -> None:
        values = sim.readouts(columns)
        if not keep:
            rows.clear()
        rows.append(list(values.values()))
        if recorder is not None:
            recorder.frame(values)

    sample()
    done, start, shown = 0, time.perf_counter(), time.perf_counter()
    try:
        while done < total:
            n = min(per_row, total - done)
            sim.step(n)
            done += n
            sample()
            now = time.perf_counter()
            if progress and now - shown > PROGRESS_PERIOD:
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


def csv_cell(value: object) -> object:
    """A value as every CSV of the sandbox writes it: floats with 10 significant digits
    and a dot, an empty cell for NaN or an infinity, anything else as it is."""
    if isinstance(value, float):
        return f"{value:.10g}" if math.isfinite(value) else ""
    return value


def special_file(path: Path) -> str | None:
    """What ``path`` is in words when it exists and is not a regular file or a folder
    ("a named pipe", "a device", "a socket"), else None. Writing to a named pipe blocks
    until something reads it: an output must be a file."""
    try:
        mode = path.stat().st_mode
    except OSError:
        return None
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return None


def check_out(
    out: Path, option: str = "--out", suffixes: tuple[str, ...] = (".csv", ".json")
) -> None:
    """Refuse an output path that cannot be written, before anything is simulated.

    Raises:
        BadOption: not one of ``suffixes``, a directory, a named pipe or device, a missing or
            non-folder parent, or a folder (or file) that cannot be written.
    """
    name = shown(str(out))
    if "\x00" in str(out):
        raise BadOption(f"{option} {name} contains a NUL character; give another path")
    if out.suffix.lower() not in suffixes:
        raise BadOption(f"{option} {name} must end in {' or '.join(suffixes)}")
    folder = out.parent
    try:
        if out.is_dir():
            raise BadOption(f"{option} {name} is a directory; give a file name such as run.csv")
        special = special_file(out)
        if special is not None:
            raise BadOption(f"{option} {name} is {special}, not a file; give a file name")
        if not folder.exists():
            raise BadOption(
                f"folder {shown(str(folder))} of {option} does not exist; create it first"
            )
        if not folder.is_dir():
            raise BadOption(
                f"{option} {name}: {shown(str(folder))} is a file, not a folder; "
                "give a path in an existing folder"
            )
    except OSError as exc:  # a name too long, a loop of links
        raise BadOption(f"{option} {name}: {exc.strerror}; give another path") from None
    if not os.access(folder, os.W_OK | os.X_OK) or (out.exists() and not os.access(out, os.W_OK)):
        raise BadOption(f"{option} {name} cannot be written (permission denied); give another path")


class RowWriter:
    """Rows streamed to CSV (header = column names) or JSON (with units and metadata).

    The file is written under a temporary name in the output's folder, opened before
    the run (so a folder that refuses it is known before anything is simulated), and
    renamed to ``out`` by :meth:`close`; :meth:`discard` removes it (nothing
    half-written is left behind). It is a :class:`FrameSink` for :func:`simulate`.

    The JSON document has ``scene``, ``params``, ``integrator``, ``timestep``,
    ``columns``, ``units`` and ``rows`` (non-finite values as null).

    Raises:
        BadOption: the file cannot be created (see :func:`check_out`).
    """

    def __init__(self, out: Path, sim: Simulation, columns: list[str]) -> None:
        check_out(out)
        self.out, self.columns, self.count = out, list(columns), 0
        self._json = out.suffix.lower() == ".json"
        tmp = out.parent / f".{out.name[:100]}.{os.getpid()}.{secrets.token_hex(4)}.part"
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except OSError as exc:
            raise BadOption(
                f"cannot create --out {shown(str(out))}: {exc.strerror}; give another path"
            ) from None
        self._tmp = Path(tmp)
        self._fh: IO[str] = os.fdopen(fd, "w", newline="", encoding="utf-8")
        if self._json:
            units = {r.name: r.unit for r in sim.readout_infos()}
            head = {
                "scene": sim.label,
                "params": sim.values,
                "integrator": sim.integrator,
                "timestep": sim.timestep,
                "columns": self.columns,
                "units": units,
            }
            self._fh.write(json.dumps(head)[:-1] + ', "rows": [')
        else:
            self._csv = csv.writer(self._fh)
            self._csv.writerow(self.columns)

    def row(self, values: Iterable[float]) -> None:
        """Append one row (in column order)."""
        if self._json:
            clean = [v if math.isfinite(v) else None for v in values]
            self._fh.write(("," if self.count else "") + json.dumps(clean))
        else:
            self._csv.writerow([csv_cell(float(v)) for v in values])
        self.count += 1

    def frame(self, values: Mapping[str, float]) -> None:
        """:class:`FrameSink`: the row of ``values`` taken in column order."""
        self.row(values[c] for c in self.columns)

    def close(self) -> None:
        """Finish the file and give it its name."""
        try:
            if self._json:
                self._fh.write("]}")
            self._fh.close()
            os.replace(self._tmp, self.out)
        except BaseException:
            self.discard()
            raise

    def discard(self) -> None:
        """Remove the unfinished file."""
        with contextlib.suppress(OSError):
            self._fh.close()
        with contextlib.suppress(OSError):
            self._tmp.unlink()


def write_rows(out: Path, sim: Simulation, columns: list[str], rows: list[list[float]]) -> None:
    """Write readout rows to CSV or JSON at once (see :class:`RowWriter`)."""
    writer = RowWriter(out, sim, columns)
    try:
        for row in rows:
            writer.row(row)
    except BaseException:
        writer.discard()
        raise
    writer.close()
