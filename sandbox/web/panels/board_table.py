"""The class board as the teacher reads it: rows sorted (:func:`sort_rows`), the CSV
export (:func:`csv_text`) and the HTML table of "La classe" (:func:`board_html`), all
pure (no viser) and tested without a browser.

Names are typed by students: they are escaped in the HTML table and defused in the CSV
(a spreadsheet would run a cell starting with ``=``).
"""

from __future__ import annotations

import csv
import io
import math
import re
import unicodedata
from collections.abc import Iterable, Sequence

from sandbox.web.client.text import html_text
from sandbox.web.loop.capacity import ESTIMATE_FPS, Load, students_at
from sandbox.web.loop.frame import FPS
from sandbox.web.panels.board_rows import MAX_NAME, Row

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

_DIGITS = re.compile(r"(\d+)")
_FORMULA = ("=", "+", "-", "@", "\t", "\r")


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


def capacity_words(load: Load | None) -> str:
    """What the laptop holds, in the teacher's words (markdown): « Ce portable tient
    environ N élèves sur cette scène », the frame rate when the class's was lowered, and
    « Portable saturé » past the lowest one ("" before anything was measured)."""
    if load is None:
        return ""
    held = students_at(load)
    lines = []
    if held is not None:
        lines.append(
            f"Ce portable tient environ **{held} élève{'s' if held > 1 else ''}** sur cette "
            f"scène, à {ESTIMATE_FPS:.0f} images par seconde."
        )
    if load.saturated:
        lines.append(
            "**Portable saturé : les nouveaux élèves suivent votre simulation** (projetée, "
            "sans réglages personnels) ; fermez d'autres programmes ou ajoutez une machine."
        )
    elif load.fps < FPS - 0.5:
        lines.append(
            f"Portable chargé : images abaissées à {load.fps:.0f} par seconde pour tous ; "
            "le temps simulé reste celui de l'horloge."
        )
    return "\n\n".join(lines)


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
