"""A student's row on the class board, read from what their page last showed.

Reading a student costs a few attribute reads: the lesson panel keeps the readouts of its
last refresh and its goal bars (:class:`~sandbox.web.panels.lesson.LessonPanel`), so the
board evaluates nothing and a session's frames are untouched.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Protocol

import viser

from sandbox.challenges import Attempt
from sandbox.lessons import Progress
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.scenes import SCENES
from sandbox.web.panels.board_rows import GOALS, Row, clean_name, progress_of
from sandbox.web.panels.challenge import ChallengePanel
from sandbox.web.panels.lesson import LessonPanel
from sandbox.web.panels.lesson_goal import parts
from sandbox.web.panels.projector import overlay_labels, overlay_lines

_GOAL_KEYS = {word: key for key, word in GOALS.items()}


@dataclass(frozen=True)
class Readouts:
    """How one scene's key readouts are written (computed once per student)."""

    names: tuple[str, ...]
    labels: Mapping[str, str]
    units: Mapping[str, str]
    zeros: Mapping[str, float]

    @classmethod
    def of(cls, sim: ReadOnlySimulation) -> Readouts:
        infos = {i.name: i for i in sim.readout_infos()}
        short = overlay_labels(sim)
        spec = sim.scene
        names = tuple(short)
        labels = {n: (short.get(n) or i.label or n) for n, i in infos.items()}
        units = {n: i.unit for n, i in infos.items()}
        zeros = {n: spec.zero_for(i.unit) for n, i in infos.items()} if spec else {}
        return cls(names, labels, units, zeros)

    def written(self, name: str, values: Mapping[str, float]) -> str:
        """The value as the page's overlay writes it ("54,4 N", "1 500 tr/min")."""
        label = self.labels.get(name, name)
        (line,) = overlay_lines([name], values, {name: label}, self.units, self.zeros)
        return line.removeprefix(f"{label} = ")


class StudentPage(Protocol):
    """What the board reads of a student's own page (the browser view): its lesson panel
    and its challenge panel, each None when the page has none."""

    @property
    def lesson(self) -> LessonPanel | None: ...

    @property
    def challenge(self) -> ChallengePanel | None: ...


@dataclass
class Student:
    """One student's page as the board reads it (kept across a follow-mode switch)."""

    client: viser.ClientHandle
    joined: float
    scene: str
    readouts: Readouts
    view: StudentPage | None = None
    mode: str = "own"
    field: viser.GuiTextHandle | None = None
    name: str = ""
    sim: ReadOnlySimulation | None = None
    challenge: ChallengePanel | None = None
    attempt: Attempt | None = None  # kept across a follow-mode student's switches
    who: str = ""  # the tab's own key, kept across reloads ("" when unknown)
    identify: Callable[[], tuple[str, str]] | None = None  # asked again while who is ""
    tries: int = 0  # times ``identify`` was asked


def _read_lesson(view: StudentPage | None, row: Row) -> tuple[Row, str, Mapping[str, float]]:
    """``row`` with the lesson as the student's page shows it, the readout its step
    checks ("" when none) and the page's readouts (each attribute read once: the
    session's loop may change them meanwhile)."""
    panel = view.lesson if view is not None else None
    if panel is None:
        return row, "", {}
    values: Mapping[str, float] = panel.values
    progress: Progress | None = panel.progress
    if progress is None:
        return row, "", values
    state, lines = panel.goal_state, panel.goal_lines
    goal = _GOAL_KEYS.get(state, "")
    done = [line.done for line in lines]
    checked = ""
    check = progress.step.check
    found = parts(check) if check is not None else None
    if found and len(found) == len(done):  # the part furthest from its goal
        ranked = [(d if d is not None else 2.0, k) for k, d in enumerate(done)]
        checked = found[min(ranked)[1]].readout
    row = replace(
        row,
        lesson=progress.lesson.name,
        lesson_title=progress.lesson.title,
        step=progress.index + 1,
        steps=len(progress.lesson.steps),
        goal=goal,
        progress=progress_of(done, goal) if goal else math.nan,
    )
    return row, checked, values


def key_readout(
    scene: str, names: tuple[str, ...], checked: str, values: Mapping[str, float]
) -> str:
    """The readout a student's row shows: the one their lesson step checks (the part
    furthest from its goal), else a balancing scene's larger bearing force, else the
    scene's first key readout ("" when none)."""
    if checked:
        return checked
    spec = SCENES.get(scene)
    pair = spec.page.balancing if spec is not None else None
    if pair is not None and all(n in values for n in pair):
        a, b = (values[n] for n in pair)
        return pair[1] if b > a else pair[0]
    return names[0] if names else ""


def student_row(key: str, student: Student) -> Row:
    """One student's row from what their page last showed."""
    if student.field is not None:
        student.name = clean_name(student.field.value)
    base = Row(key=key, joined=student.joined, name=student.name, scene=student.scene)
    if student.mode == "follow":
        return replace(base, mode="follow")
    row, checked, values = _read_lesson(student.view, base)
    readouts = student.readouts
    given, tries, solved_s = student.challenge.state() if student.challenge else ("", 0, math.nan)
    name = key_readout(student.scene, readouts.names, checked, values)
    value = float(values.get(name, math.nan)) if name else math.nan
    return replace(
        row,
        readout=name,
        label=readouts.labels.get(name, name) if name else "",
        value=value,
        unit=readouts.units.get(name, "") if name else "",
        shown=readouts.written(name, values) if name and math.isfinite(value) else "",
        challenge=given,
        tries=tries,
        solved_s=solved_s,
    )
