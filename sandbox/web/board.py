"""The class board ("La classe" on the teacher's page): one row per student browser.

A row is read, once a second, from what a student's session already computed for its own
page (the lesson's step and goal bars, the readouts of its last panel refresh): the board
never evaluates the physics. Rows are small dicts of plain values because they travel
between processes: with ``--workers N`` every worker sends its students' rows to the
parent, whose :class:`Roster` merges them (numbering the class in order of arrival, keeping
a student who left for a while as "parti") and hands the merged board back to the workers
serving a teacher's page. Everything here is pure (no viser): sorting, the CSV export and
the HTML table are tested without a browser.

Names are typed by students: they are cleaned (one line, at most :data:`MAX_NAME`
characters), escaped in the HTML table and defused in the CSV (a spreadsheet would run a
cell starting with ``=``).
"""

from __future__ import annotations

import csv
import io
import math
import re
import unicodedata
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

from sandbox.web.text import html_text

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

SORT_LABEL = "Trier par"
SORTS: dict[str, str] = {
    "Arrivée": "arrival",
    "Nom": "name",
    "Étape": "step",
    "Progression": "progress",
    "Défi": "challenge",
}
"""The teacher's sort choices (French label: key of :func:`sort_rows`)."""

CSV_COLUMNS = (
    "name",
    "connected",
    "scene",
    "lesson",
    "step",
    "goal",
    "progress",
    "readout",
    "value",
    "unit",
    "joined_s",
    "challenge",
    "solved",
    "tries",
    "time_s",
)
"""Columns of the board's CSV export (a contract: English names, dot decimals)."""

_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029\u200b-\u200f\u202a-\u202e\u2066-\u2069]")
_SPACES = re.compile(r"\s+")
_DIGITS = re.compile(r"(\d+)")
_FORMULA = ("=", "+", "-", "@", "\t", "\r")


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


@dataclass
class _Entry:
    row: Row
    source: Hashable


def _arrival(entry: _Entry) -> tuple[bool, int, float]:
    """Numbered students first, by number; then those not numbered yet."""
    row = entry.row
    return (not row.number, row.number, row.joined)


class Roster:
    """The merged board: the rows every source (a worker process) last reported.

    Students are numbered in order of arrival, once ``settle`` seconds have passed since
    they arrived: by then every source has reported those who arrived before them (two
    workers report at different instants), and a number never changes afterwards. A row
    that a source stops reporting is kept for :data:`KEEP_GONE` seconds, marked gone; a
    source silent for :data:`STALE` seconds (a worker that died) has its students marked
    gone.

    Args:
        start: When the class started (wall clock [s]): ``joined_s`` counts from it.
        keep_gone: Seconds a gone student stays listed.
        stale: Seconds of silence before a source's students count as gone.
        max_rows: Rows held at most.
        settle: Seconds after its arrival before a student is numbered (0: at once, for
            a single source).
    """

    def __init__(
        self,
        start: float,
        *,
        keep_gone: float = KEEP_GONE,
        stale: float = STALE,
        max_rows: int = MAX_ROWS,
        settle: float = 0.0,
    ) -> None:
        self.start = start
        self.settle = settle
        self.keep_gone = keep_gone
        self.stale = stale
        self.max_rows = max_rows
        self._left_out: dict[Hashable, int] = {}  # students not listed, by source
        self._entries: dict[str, _Entry] = {}
        self._heard: dict[Hashable, float] = {}
        self._next = 1

    def update(self, source: Hashable, rows: Sequence[Row], now: float) -> None:
        """The rows ``source`` has now (its connected students); those it no longer has
        are marked gone at ``now``."""
        self._heard[source] = now
        seen = set()
        for row in sorted(rows, key=lambda r: (r.joined, r.key)):
            seen.add(row.key)
            entry = self._entries.get(row.key)
            if entry is not None:
                entry.row = replace(row, number=entry.row.number, left=0.0)
                entry.source = source
                continue
            if len(self._entries) >= self.max_rows:
                self._forget_oldest_gone()
            if len(self._entries) >= self.max_rows:
                continue
            self._entries[row.key] = _Entry(replace(row, number=0, left=0.0), source)
        for key, entry in self._entries.items():
            if entry.source == source and key not in seen and entry.row.connected:
                entry.row = replace(entry.row, left=now)
        self._left_out[source] = sum(1 for r in rows if r.key not in self._entries)

    @property
    def left_out(self) -> int:
        """Connected students not listed: the board is full."""
        return sum(self._left_out.values())

    def drop(self, source: Hashable, now: float) -> None:
        """``source`` is gone (a worker restarted): its students count as gone."""
        self._heard.pop(source, None)
        self._left_out.pop(source, None)
        for entry in self._entries.values():
            if entry.source == source and entry.row.connected:
                entry.row = replace(entry.row, left=now)

    def _forget_oldest_gone(self) -> None:
        gone = [(e.row.left, k) for k, e in self._entries.items() if not e.row.connected]
        if gone:
            del self._entries[min(gone)[1]]

    def rows(self, now: float) -> list[Row]:
        """Every row (gone ones included, until :data:`KEEP_GONE` passes), in order of
        arrival."""
        for source, heard in list(self._heard.items()):
            if now - heard > self.stale:
                self.drop(source, now)
        for key in [
            k for k, e in self._entries.items() if e.row.left and now - e.row.left > self.keep_gone
        ]:
            del self._entries[key]
        settled = [e for e in self._entries.values() if not e.row.number]
        for entry in sorted(settled, key=lambda e: (e.row.joined, e.row.key)):
            if entry.row.joined > now - self.settle:
                break
            entry.row = replace(entry.row, number=self._next)
            self._next += 1
        return [e.row for e in sorted(self._entries.values(), key=_arrival)]

    def board(self, now: float) -> Board:
        """The merged board at ``now``."""
        return Board(self.start, tuple(self.rows(now)), self.left_out)


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

    def wire(self) -> dict[str, Any]:
        """As plain values, for a pipe between processes."""
        return {
            "start": self.start,
            "rows": [to_wire(r) for r in self.rows],
            "left_out": self.left_out,
            "run": self.run.wire() if self.run is not None else None,
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
        return cls(float(start), rows_, max(count, 0), Run.from_wire(data.get("run")))


def _natural(text: str) -> tuple[object, ...]:
    """Sort key of a name as a French reader sorts it: case and accents aside ("Élodie"
    between "Elise" and "Emma"), numbers by value ("Élève 2" before "Élève 10")."""
    return tuple(int(p) if p.isdigit() else _letters(p) for p in _DIGITS.split(text))


def _letters(text: str) -> str:
    decomposed = unicodedata.normalize("NFKD", text.casefold())
    return "".join(c for c in decomposed if not unicodedata.combining(c))


def sort_rows(rows: Iterable[Row], by: str) -> list[Row]:
    """``rows`` sorted for the teacher: students who left last, and among each group by
    ``by``: "arrival" (first arrived first), "name" (alphabetical), "step" or "progress"
    (the students furthest behind first).

    Raises:
        ValueError: ``by`` is none of those (the valid ones are named).
    """
    keys = {
        "arrival": lambda r: (not r.number, r.number, r.joined),
        "name": lambda r: (_natural(r.display_name), r.number),
        "step": lambda r: (r.step, r.lesson, r.number),
        "progress": lambda r: (
            r.progress if math.isfinite(r.progress) else -1.0,
            r.step,
            r.number,
        ),
        "challenge": lambda r: (  # the fastest solvers first, then the most tries
            not math.isfinite(r.solved_s),
            r.solved_s if math.isfinite(r.solved_s) else -r.tries,
            r.number,
        ),
    }
    if by not in keys:
        raise ValueError(f"unknown sort {by!r}; choose one of {', '.join(keys)}")
    key = keys[by]
    return sorted(rows, key=lambda r: (not r.connected, key(r)))


def _cell(text: str) -> str:
    """A text cell a spreadsheet will not run as a formula."""
    return "'" + text if text.startswith(_FORMULA) else text


def _num(value: float, digits: int = 6) -> str:
    return f"{value:.{digits}g}" if math.isfinite(value) else ""


def _fraction(value: float) -> str:
    return f"{value:.3f}" if math.isfinite(value) else ""


def csv_text(rows: Iterable[Row], start: float) -> str:
    """The board as CSV (:data:`CSV_COLUMNS`): ``connected`` is true or false, ``step``
    counts from 1 (empty without a lesson), ``goal`` a key of :data:`GOALS`, ``progress``
    in [0, 1], ``value`` in ``unit`` (the readout's contract unit: rad/s, not tr/min),
    ``joined_s`` the seconds from ``start`` (the server's start) to the student's arrival;
    ``challenge`` the challenge they were given, ``solved`` true or false, ``tries`` their
    checks, ``time_s`` the seconds they took to solve it. Dot decimals; empty cells for
    what does not apply."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for r in rows:
        writer.writerow(
            [
                _cell(r.display_name),
                "true" if r.connected else "false",
                _cell(r.scene),
                _cell(r.lesson),
                str(r.step) if r.step else "",
                r.goal,
                _fraction(r.progress),
                _cell(r.readout),
                _num(r.value),
                _cell(r.unit),
                f"{max(r.joined - start, 0.0):.1f}",
                _cell(r.challenge),
                ("true" if math.isfinite(r.solved_s) else "false") if r.challenge else "",
                str(r.tries) if r.challenge else "",
                f"{r.solved_s:.1f}" if math.isfinite(r.solved_s) else "",
            ]
        )
    return out.getvalue()


# -- the table on the teacher's page ------------------------------------------------------
BOARD_CLASS = "sandbox-board"
_BOX = "padding:0 0.75em;max-height:55vh;overflow-y:auto"
"""A class of 30 scrolls inside its box: the teacher's controls stay below, in reach."""
_STYLE = (
    f"<style>.{BOARD_CLASS} table{{width:100%;border-collapse:collapse;"
    "font-variant-numeric:tabular-nums}"
    f".{BOARD_CLASS} th{{text-align:left;font-weight:600;border-bottom:1px solid #999;"
    "position:sticky;top:0;background:var(--mantine-color-body)}"
    f".{BOARD_CLASS} td{{border-bottom:1px solid #ddd;vertical-align:middle;"
    "padding-top:2px;padding-bottom:2px}"
    f".{BOARD_CLASS} td.n{{max-width:6em;overflow:hidden;text-overflow:ellipsis;"
    "white-space:nowrap}"
    f".{BOARD_CLASS} td.g{{white-space:nowrap}}"
    f".{BOARD_CLASS} td.v,.{BOARD_CLASS} th.v{{text-align:right}}"
    f".{BOARD_CLASS} td.v span{{white-space:nowrap}}"
    f".{BOARD_CLASS} tr.main td{{border-bottom:none}}"
    f".{BOARD_CLASS} tr.sub td{{padding-left:1em;color:#444}}"
    f".{BOARD_CLASS} tr.gone td{{color:#666}}"
    f".{BOARD_CLASS} .bar{{display:inline-block;width:2.5em;height:0.7em;"
    "border:1px solid #888;border-radius:0.35em;background:#e8e8e8;overflow:hidden;"
    "vertical-align:middle;margin-right:0.3em}"
    f".{BOARD_CLASS} .bar>span{{display:block;height:100%}}"
    "</style>"
)


def _goal_cell(row: Row) -> str:
    if row.mode == "follow":
        return "suit la projection"
    if not row.goal:
        return "—"
    if row.goal == "cannot_check":
        return "vérification impossible"
    done = row.progress if math.isfinite(row.progress) else 0.0
    percent = round(100 * min(max(done, 0.0), 1.0))
    colour = "#2e8b3e" if row.goal in ("reached", "was_reached") or percent >= 100 else "#1f6fd1"
    word = "réussi" if row.goal == "reached" else f"{percent} %"
    return (
        f'<span class="bar" role="progressbar" aria-valuemin="0" aria-valuemax="100" '
        f'aria-valuenow="{percent}"><span style="width:{percent}%;background:{colour}">'
        f"</span></span>{word}"
    )


def duration(seconds: float) -> str:
    """A time as a teacher reads it: "45 s", "2 min 05 s"."""
    whole = max(int(round(seconds)), 0)
    minutes, rest = divmod(whole, 60)
    return f"{minutes} min {rest:02d} s" if minutes else f"{rest} s"


def _challenge_cell(row: Row) -> str:
    if not row.challenge:
        return "—"
    tries = f"{row.tries} essai{'s' if row.tries > 1 else ''}" if row.tries else "aucun essai"
    if math.isfinite(row.solved_s):
        return (
            f'<span style="color:#2e7d32;font-weight:600">réussi</span> en '
            f"{duration(row.solved_s)}, {tries}"
        )
    return tries


def summary(rows: Sequence[Row], left_out: int = 0) -> str:
    """The line above the table: "6 élèves connectés, 1 parti." (plain text)."""
    here = sum(1 for r in rows if r.connected)
    gone = len(rows) - here
    words = [f"{here} élève{'s' if here > 1 else ''} connecté{'s' if here > 1 else ''}"]
    if gone:
        words.append(f"{gone} parti{'s' if gone > 1 else ''}")
    text = ", ".join(words) + "."
    if left_out:
        s = "s" if left_out > 1 else ""
        text += f" Tableau plein : {left_out} autre{s} non affiché{s}."
    return text


def board_html(rows: Sequence[Row]) -> str:
    """The board as an HTML table (every text escaped): name, step, goal, key readout.

    The readout has a column headed by its words when every row has the same readout;
    else each student's readout is written on a line of its own under their row ("Balourd
    statique m·Y : 0,0016 kg·m" does not fit a column of a 430 px panel). The lesson's
    title is written above the table when every student follows the same lesson."""
    if not rows:
        return (
            f'<div class="{BOARD_CLASS}" style="padding:0 0.75em">'
            "Aucun élève pour l'instant : ils apparaissent ici dès qu'ils ouvrent la page."
            "</div>"
        )
    labels = {r.label for r in rows if r.label}
    column = len(labels) <= 1
    lessons = {r.lesson_title for r in rows if r.lesson_title}
    parts = [_STYLE, f'<div class="{BOARD_CLASS}" style="{_BOX}">']
    if len(lessons) == 1:
        parts.append(f"<div>Leçon : {html_text(next(iter(lessons)))}</div>")
    challenge = any(r.challenge for r in rows)  # a challenge runs: its column, not the step's
    head = "<table><tr><th>Élève</th>" + (
        "<th>Défi</th>" if challenge else "<th>Étape</th><th>Objectif</th>"
    )
    if column:
        head += f'<th class="v">{html_text(next(iter(labels))) if labels else "Mesure"}</th>'
    parts.append(head + "</tr>")
    for r in rows:
        name = html_text(r.display_name, MAX_NAME + 1)
        if not r.connected:
            name += " (parti)"
        step = f"{r.step}/{r.steps}" if r.step else "—"
        title = html_text(r.lesson_title) if r.lesson_title else ""
        state = "here" if r.connected else "gone"
        below = not column and bool(r.shown)
        parts.append(
            f'<tr class="{state}{" main" if below else ""}">'
            f'<td class="n" title="{html_text(r.display_name, MAX_NAME + 1)}">{name}</td>'
            + (
                f"<td>{_challenge_cell(r)}</td>"
                if challenge
                else f'<td title="{title}">{step}</td><td class="g">{_goal_cell(r)}</td>'
            )
        )
        if column:
            parts.append(f'<td class="v"><span>{html_text(r.shown or "—")}</span></td>')
        parts.append("</tr>")
        if below:
            words = f"{r.label} : {r.shown}" if r.label else r.shown
            span = 2 if challenge else 3
            parts.append(
                f'<tr class="{state} sub"><td colspan="{span}">{html_text(words)}</td></tr>'
            )
    parts.append("</table></div>")
    return "".join(parts)
