"""A parameter study's rows written out: CSV or JSON files (the columns are a contract,
shared by ``sandbox sweep --out`` and the page's download) and aligned text for a terminal.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

from sandbox.runner import csv_cell
from sandbox.sweep.study import Study

COLUMNS_AFTER = ("measure", "closed_form", "gap", "status")
"""Columns after the varied parameters' (a contract): the measure, the course's value
where the scene has one for this readout and statistic (its final or mean value: the
readout's own closed form; an order: the closed form named ``READOUT_hN``), measure minus
closed form, and ``ok`` or ``diverged``."""


def columns(study: Study) -> list[str]:
    """The output's columns: the varied parameters, then :data:`COLUMNS_AFTER`."""
    return [*(v.name for v in study.varies), *COLUMNS_AFTER]


def write(out: Path, study: Study, rows: Sequence[Mapping[str, Any]]) -> None:
    """The rows as CSV (dot decimals, empty cells for NaN) or JSON (NaN as null)."""
    names = columns(study)
    if out.suffix.lower() == ".json":

        def clean(v: Any) -> Any:
            return None if isinstance(v, float) and not math.isfinite(v) else v

        payload = {
            "target": study.target,
            "measure": study.measure.label,
            "duration": study.duration,
            "settle": study.settle,
            "columns": names,
            "rows": [[clean(r[n]) for n in names] for r in rows],
        }
        out.write_text(json.dumps(payload, indent=1), encoding="utf-8")
        return
    with out.open("w", newline="", encoding="utf-8") as f:
        write_csv(f, study, rows)


def write_csv(stream: TextIO, study: Study, rows: Sequence[Mapping[str, Any]]) -> None:
    """The rows as CSV on ``stream`` (dot decimals, empty cells for NaN): the columns of
    :func:`columns`, a contract shared by ``--out`` and the page's download."""
    names = columns(study)
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(names)
    for r in rows:
        writer.writerow([csv_cell(r[n]) for n in names])


def table(study: Study, rows: Sequence[Mapping[str, Any]]) -> Iterator[str]:
    """The rows as aligned text lines for a terminal."""
    names = columns(study)
    yield "  ".join(f"{n:>14}" for n in names)
    for r in rows:
        yield "  ".join(
            f"{r[n]:>14.6g}" if isinstance(r[n], float) else f"{r[n]!s:>14}" for n in names
        )
