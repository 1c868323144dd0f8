"""The sampling loop shared by ``sandbox run`` and ``sandbox bench``, and the row writers.

:func:`simulate` steps a :class:`~sandbox.physics.simulation.Simulation` in C by chunks
of whole timesteps and takes a row of readouts between chunks; a divergence stops it and
keeps the rows computed so far. :func:`write_rows` writes them as CSV or JSON (the
columns are the readouts' names: a contract with the students' scripts).

Layer: above physics and scenes, below recording, bench, lessons, replay, web and cli
(see ``tests/test_layers.py``).
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Protocol

from sandbox.errors import Diverged
from sandbox.physics.simulation import Simulation

PROGRESS_PERIOD = 2.0
"""Wall seconds between two progress lines on stderr."""


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
) -> tuple[list[str], list[list[float]], Diverged | None]:
    """Run ``duration`` seconds, sampling the readouts ``rate`` times per second.

    Args:
        sim: The simulation, at its starting state (the first row is taken there).
        duration: Simulated time [s] (rounded to whole timesteps; 0 gives one row).
        rate: Rows per simulated second (at most one per timestep).
        progress: Print a progress line on stderr every :data:`PROGRESS_PERIOD` s.
        recorder: Also given every row (``frame(values)``).
        names: Readouts sampled (default: every readout, in column order).

    Returns:
        (columns, rows, error): the readout names, one row of values per sample
        (shape (n, len(columns))), and the :class:`~sandbox.errors.Diverged` that
        stopped the run or None; rows computed before a divergence are kept.
    """
    columns = sim.readout_names() if names is None else list(names)
    total, per_row = chunks(duration, rate, sim.timestep)
    rows: list[list[float]] = []

    def sample() -> None:
        values = sim.readouts(columns)
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


def write_rows(out: Path, sim: Simulation, columns: list[str], rows: list[list[float]]) -> None:
    """Write readout rows to CSV (header = column names) or JSON (with units and metadata).

    The JSON document has ``scene``, ``params``, ``integrator``, ``timestep``,
    ``columns``, ``units`` and ``rows`` (non-finite values as null).
    """
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
