"""The class board ("La classe" on the teacher's page): one row per student browser.

A row is read, once a second, from what a student's session already computed for its own
page (the lesson's step and goal bars, the readouts of its last panel refresh): the board
never evaluates the physics. Rows are small dicts of plain values because they travel
between processes: with ``--workers N`` every worker sends its students' rows to the
parent, whose :class:`~sandbox.web.serving.roster.Roster` merges them (numbering the class in
order of arrival, keeping a student who left for a while as "parti") and hands the merged
board back to the workers serving a teacher's page. Everything here is pure (no viser):
sorting, the CSV export and the HTML table (:mod:`sandbox.web.panels.board_table`) are tested
without a browser.

Names are typed by students: they are cleaned (one line, at most :data:`MAX_NAME`
characters), escaped in the HTML table and defused in the CSV (a spreadsheet would run a
cell starting with ``=``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields
from typing import Any

from sandbox.web.loop.capacity import Load

MAX_NAME = 40
"""Longest name a student may give [characters]."""

MAX_ROWS = 200
"""Rows the board holds; past them the newest arrivals are left out (and counted)."""

KEEP_GONE = 600.0
"""Seconds a student who left stays on the board, marked "parti"."""

STALE = 5.0
"""Seconds without news from a worker process before its students count as gone."""

REFRESH = 1.0
"""Seconds between two readings of the students (the board's refresh period)."""

SETTLE = 1.5
"""Seconds after a student's arrival before the parent of several workers numbers them:
each worker reports every :data:`REFRESH` seconds, and the parent looks at its workers
every tenth of a second."""

GOALS: dict[str, str] = {
    "reached": "Réussi",
    "in_progress": "En cours",
    "was_reached": "Déjà réussi",
    "cannot_check": "Vérification impossible",
}
"""Goal states (CSV word: words of the lesson's goal block); "" for a step without goal."""


_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029\u200b-\u200f\u202a-\u202e\u2066-\u2069]")
_SPACES = re.compile(r"\s+")


TAB_KEY = "b:"
"""Prefix of a row key made of the tab's own key (kept across reloads and restarts)."""


def clean_name(value: object, limit: int = MAX_NAME) -> str:
    """A name typed in a browser, made safe to keep: text only, control and direction
    characters removed, blanks collapsed, at most ``limit`` characters ("" for none)."""
    if not isinstance(value, str):
        return ""
    text = _SPACES.sub(" ", _CONTROL.sub(" ", value[: 4 * limit])).strip()
    return text[:limit].rstrip()


@dataclass(frozen=True)
class Row:
    """One student browser on the board.

    Attributes:
        key: Unique in the class ("worker:client").
        joined: When the browser arrived (wall clock, seconds since the epoch).
        name: The name the student typed ("" until they type one).
        scene: Scene name (or the MJCF file's name).
        mode: "own" (their own simulation) or "follow" (watching the teacher's).
        lesson: Lesson name ("" in free exploration).
        lesson_title: The lesson's title as the page shows it.
        step: Current step, from 1 (0: no lesson).
        steps: Steps in the lesson.
        goal: A key of :data:`GOALS`, "" when the step has no goal.
        progress: Way done towards the step's goal, in [0, 1] (NaN: no goal).
        readout: Key readout's name (a readout contract name, "" when none).
        label: Its words on the page ("Palier A").
        value: Its value in ``unit``.
        unit: Its contract unit ("N", "rad/s").
        shown: The value as the student's page writes it ("54,4 N").
        number: Order of arrival in the class, from 1 (0 until the roster numbers it).
        left: When the browser left (wall clock; 0 while connected).
        challenge: The challenge they are given (a name of
            :data:`sandbox.challenges.CHALLENGES`, "" when none).
        tries: Their checks of it so far.
        solved_s: Seconds they took to solve it (NaN: not solved).
    """

    key: str
    joined: float
    name: str = ""
    scene: str = ""
    mode: str = "own"
    lesson: str = ""
    lesson_title: str = ""
    step: int = 0
    steps: int = 0
    goal: str = ""
    progress: float = math.nan
    readout: str = ""
    label: str = ""
    value: float = math.nan
    unit: str = ""
    shown: str = ""
    number: int = 0
    left: float = 0.0
    challenge: str = ""
    tries: int = 0
    solved_s: float = math.nan

    @property
    def connected(self) -> bool:
        """True while the student's browser is there."""
        return not self.left

    @property
    def display_name(self) -> str:
        """The typed name, else "Élève 7" (its order of arrival)."""
        return self.name or (f"Élève {self.number}" if self.number else "Nouvel élève")


_FIELDS = {f.name: f.type for f in fields(Row)}
_TEXT_LIMIT = 200


def to_wire(row: Row) -> dict[str, Any]:
    """``row`` as a dict of plain values (pickled between processes)."""
    return {name: getattr(row, name) for name in _FIELDS}


def from_wire(data: object) -> Row | None:
    """A row back from :func:`to_wire`, every field checked and bounded (None when it is
    not one)."""
    if not isinstance(data, Mapping):
        return None
    out: dict[str, Any] = {}
    for name, kind in _FIELDS.items():
        if name not in data:
            continue
        value = data[name]
        if kind == "str":
            if not isinstance(value, str):
                return None
            out[name] = clean_name(value) if name == "name" else value[:_TEXT_LIMIT]
        elif kind == "int":
            if not isinstance(value, int) or isinstance(value, bool):
                return None
            out[name] = max(0, min(value, 1_000_000))
        elif kind == "float":
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                return None
            out[name] = float(value)
    if not isinstance(out.get("key"), str) or not math.isfinite(out.get("joined", math.nan)):
        return None
    if out.get("goal", "") not in ("", *GOALS):
        out["goal"] = ""
    progress = out.get("progress", math.nan)
    if math.isfinite(progress):
        out["progress"] = min(max(progress, 0.0), 1.0)
    return Row(**out)


def progress_of(done: Iterable[float | None], goal: str) -> float:
    """One number for a goal of several bars: their mean (1 once the goal is reached;
    NaN when no bar can be drawn)."""
    if goal == "reached":
        return 1.0
    bars = [d for d in done if d is not None and math.isfinite(d)]
    return sum(bars) / len(bars) if bars else math.nan


@dataclass(frozen=True)
class Run:
    """A challenge the teacher started for the class.

    Attributes:
        id: Unique to this start (a student's attempt belongs to one run).
        name: The challenge's name.
        started: When it started (wall clock [s]).
        ended: When the teacher stopped it (0 while it runs).
    """

    id: str
    name: str
    started: float
    ended: float = 0.0

    def wire(self) -> dict[str, Any]:
        """As plain values."""
        return {"id": self.id, "name": self.name, "started": self.started, "ended": self.ended}

    @classmethod
    def from_wire(cls, data: object) -> Run | None:
        """Back from :meth:`wire`, checked (None when it is not a run)."""
        if not isinstance(data, Mapping):
            return None
        rid, name = data.get("id"), data.get("name")
        started, ended = data.get("started"), data.get("ended", 0.0)
        if not (isinstance(rid, str) and isinstance(name, str) and 0 < len(rid) <= 64):
            return None
        if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in (started, ended)):
            return None
        return cls(rid, name[:64], float(started), float(ended))  # type: ignore[arg-type]


@dataclass(frozen=True)
class Board:
    """What a teacher's page shows: the rows, when the class started (wall clock [s]) and
    how many connected students the full board leaves out."""

    start: float
    rows: tuple[Row, ...] = ()
    left_out: int = 0
    run: Run | None = None
    load: Load | None = None
    """What the class's sessions cost, every process's added up (None: not measured)."""

    def wire(self) -> dict[str, Any]:
        """As plain values, for a pipe between processes."""
        return {
            "start": self.start,
            "rows": [to_wire(r) for r in self.rows],
            "left_out": self.left_out,
            "run": self.run.wire() if self.run is not None else None,
            "load": self.load.wire() if self.load is not None else None,
        }

    @classmethod
    def from_wire(cls, data: object) -> Board | None:
        """Back from :meth:`wire` (rows checked one by one; None when it is not a board)."""
        if not isinstance(data, Mapping):
            return None
        start, rows, left_out = data.get("start"), data.get("rows"), data.get("left_out", 0)
        if not isinstance(start, (int, float)) or not isinstance(rows, list):
            return None
        checked = [from_wire(r) for r in rows[:MAX_ROWS]]
        count = left_out if isinstance(left_out, int) else 0
        rows_ = tuple(r for r in checked if r is not None)
        run, load = Run.from_wire(data.get("run")), Load.from_wire(data.get("load"))
        return cls(float(start), rows_, max(count, 0), run, load)
