"""Parameter studies (``sandbox sweep``): one readout measured over a grid of parameter
values, beside the course's closed form.

A study is a list of runs, one per point of the grid (one or two parameters varied, the
others fixed). Each run builds its own :class:`~sandbox.physics.simulation.Simulation`,
steps it for ``duration`` seconds, samples the readout after ``settle`` seconds and
reduces the samples to one number (:data:`STATISTICS`). Runs are independent: they go to
a pool of processes (``jobs``), and their rows come back in the grid's order whatever
the order they finish in, so a study gives the same rows with one process or several.
A run that diverges is kept as a row marked ``diverged``; the study goes on.

The package, lowest first: :mod:`~sandbox.sweep.reduction` (what a run keeps of its
samples), :mod:`~sandbox.sweep.study` (the grid and its checks),
:mod:`~sandbox.sweep.runs` (one run, a pool of processes, a Dask cluster),
:mod:`~sandbox.sweep.output` (CSV, JSON, terminal table) and :mod:`~sandbox.sweep.chart`
(the chart for a slide). The names other modules use are imported from here.

Layer: tools (above :mod:`sandbox.runner`, below cli; see ``tests/test_layers.py``).
"""

from __future__ import annotations

from sandbox.sweep.chart import plot
from sandbox.sweep.output import COLUMNS_AFTER, table, write, write_csv
from sandbox.sweep.reduction import STATISTICS, reduce
from sandbox.sweep.runs import SMALL_STEPS, run_one, run_study
from sandbox.sweep.study import (
    MAX_RUNS,
    Measure,
    Study,
    Vary,
    bench_study,
    check,
    parse_measure,
    parse_vary,
)

__all__ = [
    "COLUMNS_AFTER",
    "MAX_RUNS",
    "SMALL_STEPS",
    "STATISTICS",
    "Measure",
    "Study",
    "Vary",
    "bench_study",
    "check",
    "parse_measure",
    "parse_vary",
    "plot",
    "reduce",
    "run_one",
    "run_study",
    "table",
    "write",
    "write_csv",
]
