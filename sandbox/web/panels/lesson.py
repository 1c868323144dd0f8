"""Folder "Leçon": lesson picker, step text, presets, live readouts, questions, live check.

Free exploration stays possible: every other control keeps working during a lesson, and
"Exploration libre" leaves it. Presets go through the session's request queue like any
slider move; the check is evaluated on the readouts the panels show.

Lesson files are untrusted: titles are escaped with :func:`sandbox.web.client.text.plain`, step
texts come out of :func:`sandbox.lessons.render_text` (no raw HTML), a refused file is named
in the folder (the other lessons stay available), and a check that cannot be computed with
the live values is reported once in the status line, in French with ``file:line``: the
student reads "vérification impossible : … (fichier:ligne)" and is told to go on with
"Suivant ▶" (the navigation never depends on the check).

The goal is written in words with a progress bar per condition
(:mod:`sandbox.web.panels.lesson_goal`), readouts by their French label and unit with a
decimal comma, and no emoji anywhere (lab PCs without an emoji font show empty boxes):
"Question", "Indice", "Réponse", "Réussi".
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping
from typing import Protocol

import viser

from sandbox.lessons import Lesson, Progress, catalogue
from sandbox.web.client.text import plain, table_row
from sandbox.web.loop.requests import SetValue
from sandbox.web.loop.state import SessionState
from sandbox.web.panels.lesson_goal import Line, Words, goal_html, lines
from sandbox.web.panels.plots import Plot, group_by_unit
from sandbox.web.view3d.arrows import ArrowLayer

FREE = "Exploration libre"
NAV = ("◀ Précédent", "Suivant ▶")
SHOWN_ERROR = 400
"""Longest refusal or check error shown in the folder [characters]."""

log = logging.getLogger(__name__)
_LOGGED: set[str] = set()


class _Removable(Protocol):
    def remove(self) -> None: ...


class _Content(Protocol):
    content: str


class LessonPanel:
    """The lesson runner of one session.

    Args:
        gui: A viser ``GuiApi``.
        controller: The session's controller (requests, recorder).
        lesson: Lesson to open at once (``sandbox serve LESSON``), else free exploration.
        arrows: The arrow layer, to show only the step's arrows.
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        controller: SessionState,
        *,
        lesson: str | None = None,
        arrows: ArrowLayer | None = None,
    ) -> None:
        self.gui = gui
        self.controller = controller
        self.arrows = arrows
        sim = controller.sim
        scene = sim.scene.name if sim.scene is not None else None
        found, refused = catalogue()
        for exc in refused:
            if str(exc) not in _LOGGED:  # once per process, for the teacher's console
                _LOGGED.add(str(exc))
                log.warning("lesson file refused: %s", exc)
        self.available: dict[str, Lesson] = {
            name: les for name, les in found.items() if scene and les.for_scene(scene)
        }
        infos = sim.readout_infos()
        zero_for = getattr(sim.scene, "zero_for", None)  # the scene's round-off by unit
        self.units = {i.name: i.unit for i in infos}
        self.words = Words(
            {i.name: i.label for i in infos},
            self.units,
            {i.name: zero_for(i.unit) for i in infos} if callable(zero_for) else {},
        )
        self.progress: Progress | None = None
        # what the page shows, kept for the class board (read once a second elsewhere)
        self.values: Mapping[str, float] = {}  # the readouts of the last refresh
        self.goal_state = ""  # the goal block's state ("" without a goal)
        self.goal_lines: tuple[Line, ...] = ()  # its lines and bars
        self.plots: list[Plot] = []
        self._step_handles: list[_Removable] = []
        self._pending: str | None = lesson if lesson in self.available else None
        self._pending_step: int | None = None
        self.fixed: frozenset[str] = frozenset()  # parameters a shared link fixed
        self.folder = gui.add_folder("Leçon", expand_by_default=bool(self.available))
        with self.folder:
            titles = {FREE: FREE} | {les.title: name for name, les in self.available.items()}
            self._by_title = titles
            start = self.available[self._pending].title if self._pending else FREE
            self.picker = gui.add_dropdown("Leçon", tuple(titles), initial_value=start)
            self.header = gui.add_markdown("")
            self.nav = gui.add_button_group("Étapes", NAV, visible=False)
            self.goal = gui.add_html("")  # the goal first: in view without scrolling
            self.text = gui.add_markdown("")
            self.table = gui.add_markdown("")
            self.status = gui.add_markdown("")
            self.hint_button = gui.add_button("Indice", visible=False)
            self.hints = gui.add_markdown("")
            self.refused = gui.add_markdown(_refusals(refused))
        if not self.available:
            self.header.content = "Aucune leçon pour ce modèle : exploration libre."

        @self.picker.on_update
        def _(event: viser.GuiEvent[viser.GuiDropdownHandle[str]]) -> None:
            if event.client is not None:
                self._pending = self._by_title.get(event.target.value, FREE)

        @self.nav.on_click
        def _(event: viser.GuiEvent[viser.GuiButtonGroupHandle]) -> None:
            self._nav(event.target.value)

        @self.hint_button.on_click
        def _(_: viser.GuiEvent[viser.GuiButtonHandle]) -> None:
            self._hint()

    # -- callbacks (any thread): only remember what to do --------------------------------
    def _nav(self, label: str) -> None:
        if self.progress is not None:
            delta = -1 if label == NAV[0] else 1
            self._pending_step = self.progress.index + delta

    def _hint(self) -> None:
        if self.progress is not None:
            self.progress.next_hint()

    def go_to(self, lesson: str | None, step: int = 0) -> None:
        """Open ``lesson`` (None: free exploration) at ``step`` at the next refresh
        (the teacher sends a step to the class)."""
        current = self.progress.lesson.name if self.progress is not None else None
        if lesson != current:
            self._pending = lesson if lesson in self.available else FREE
        self._pending_step = step if lesson is not None else None

    def open_at(self, lesson: str, step: int = 0) -> None:
        """Open ``lesson`` at ``step`` now, before the session's loop starts (a shared
        link): its presets are queued at once, so that requests queued next win."""
        found = self.available.get(lesson)
        if found is None:
            return
        self._pending = self._pending_step = None
        if self.progress is None or self.progress.lesson.name != lesson:
            self._open(found)
        if self.progress is not None and 0 <= step < len(found.steps):
            if step != self.progress.index:
                self._enter(step)

    def position(self) -> tuple[str | None, int]:
        """The lesson followed (None: none) and the index of its current step."""
        if self.progress is None:
            return None, 0
        return self.progress.lesson.name, self.progress.index

    # -- loop thread ---------------------------------------------------------------------
    def refresh(self, values: Mapping[str, float]) -> None:
        """Apply a pending choice, then show the step and evaluate its check."""
        self.values = values
        if self._pending is not None:
            name, self._pending = self._pending, None
            self._open(self.available.get(name))
        if self._pending_step is not None and self.progress is not None:
            index, self._pending_step = self._pending_step, None
            if index != self.progress.index and 0 <= index < len(self.progress.lesson.steps):
                self._enter(index)
        progress = self.progress
        if progress is None:
            return
        for plot in self.plots:
            plot.append(values)
            plot.push()
        step = progress.step
        ok = progress.observe(values, self.controller.sim.values)
        rows = [
            table_row(plain(self.words.label(n)), self.words.quantity(values.get(n, math.nan), n))
            for n in step.show
        ]
        table = "\n".join([table_row("Grandeur", "Valeur"), "|:--|--:|", *rows]) if rows else ""
        _set(self.table, table)
        _set(self.status, status_text(progress, ok))
        _set(self.goal, self._goal(progress, values, ok))
        shown = step.hints[: progress.hints_shown]
        _set(
            self.hints,
            "\n\n".join(f"**Indice {k} :** {h}" for k, h in enumerate(shown, start=1)),
        )
        self.hint_button.visible = progress.hints_shown < len(step.hints)

    def _open(self, lesson: Lesson | None) -> None:
        for handle in self._step_handles:
            handle.remove()
        self._step_handles = []
        self.controller.lesson = lesson.name if lesson else None
        self.controller.lesson_step = None  # until its first step is entered
        title = lesson.title if lesson is not None else FREE
        if self.picker.value != title and title in self._by_title:
            # the control tells the truth; viser's value setter reads as read-only to mypy
            self.picker.value = title  # type: ignore[misc]
        if lesson is None:
            self.progress = None
            self.goal_state, self.goal_lines = "", ()
            self.plots = []
            self.nav.visible = False
            self.hint_button.visible = False
            for handle in (self.header, self.text, self.goal, self.table, self.status, self.hints):
                _set(handle, "")
            if self.arrows is not None:
                self.arrows.only(None)
            return
        self.progress = Progress(lesson)
        self.nav.visible = True
        self._enter(0)

    def _enter(self, index: int) -> None:
        progress = self.progress
        assert progress is not None
        step = progress.go(index)
        for name, value in step.preset:
            if name not in self.fixed:  # the teacher's link wins over a step's presets
                self.controller.submit(SetValue(name, value))
        self.controller.lesson_step = index
        recorder = self.controller.recorder
        if recorder is not None:
            recorder.event("lesson", step=index)
        n = len(progress.lesson.steps)
        _set(
            self.header,
            f"**{plain(progress.lesson.title)}** — étape {index + 1}/{n} : **{plain(step.title)}**",
        )
        _set(self.text, step.text)
        for handle in self._step_handles:
            handle.remove()
        self._step_handles = []
        self.plots = []
        with self.folder:
            if step.plots:
                scene = self.controller.sim.scene
                arrows = scene.page.arrows if scene is not None else ()
                colours = {a.name: a.color for a in arrows}  # a curve has its arrow's colour
                words = {n: self.words.label(n) for n in step.plots}
                units = {n: self.units.get(n, "") for n in step.plots}
                zero = {u: scene.zero_for(u) for u in units.values()} if scene else {}
                for plot in group_by_unit(step.plots, units, colours, labels=words, zero=zero):
                    unit = f" [{plot.shown_unit}]" if plot.shown_unit else ""
                    plot.attach(self.gui, title=f"{', '.join(plot.labels)}{unit}")
                    self.plots.append(plot)
                    if plot.handle is not None:
                        self._step_handles.append(plot.handle)
            for question, answer in step.questions:
                q = self.gui.add_markdown(f"**Question :** {question}")
                button = self.gui.add_button("Voir la réponse", color="gray")
                reply = self.gui.add_markdown("")
                button.on_click(_reveal(reply, answer))
                self._step_handles += [q, button, reply]
        if self.arrows is not None:
            self.arrows.only(step.arrows or None)

    def _goal(self, progress: Progress, values: Mapping[str, float], ok: bool | None) -> str:
        """The goal block of the current step ("" when the step has no check)."""
        step = progress.step
        if step.check is None:
            self.goal_state, self.goal_lines = "", ()
            return ""
        if ok:
            state = "Réussi"
        elif progress.index in progress.passed:
            state = "Déjà réussi"
        elif progress.error is not None:
            state = "Vérification impossible"
        else:
            state = "En cours"
        shown = lines(step.check, self.words, values, progress.initial, brief=bool(step.goal))
        self.goal_state, self.goal_lines = state, shown
        return goal_html(shown, state=state, sentence=step.goal)


def status_text(progress: Progress, ok: bool | None) -> str:
    """The status line of the current step (Markdown), given the check's last result
    ("" while the goal is not reached: the goal block says it, with its bars).

    A check that cannot be computed is said once, with its ``file:line``, and the student
    is told to go on: a broken check never blocks silently.
    """
    step = progress.step
    if step.check is None:
        return ""
    if ok:
        return f"**Réussi.** {step.success}"
    if progress.index in progress.passed:
        return "**Étape déjà réussie** ; la condition n'est plus remplie."
    if progress.error is not None:
        return (
            f"**Vérification impossible** : {plain(progress.error, SHOWN_ERROR)}. "
            "Observez le phénomène, puis passez à la suite avec « Suivant ▶ »."
        )
    return ""


def _reveal(
    reply: viser.GuiMarkdownHandle, answer: str
) -> Callable[[viser.GuiEvent[viser.GuiButtonHandle]], None]:
    """The click callback of a "Voir la réponse" button (the answer is rendered Markdown)."""

    def show(_: viser.GuiEvent[viser.GuiButtonHandle]) -> None:
        reply.content = f"**Réponse :** {answer}"

    return show


def _refusals(refused: tuple[Exception, ...]) -> str:
    """The lesson files refused at load time, for their author (one line each)."""
    return "\n\n".join(
        f"**Fichier de leçon refusé** (à corriger par son auteur) : {plain(exc, SHOWN_ERROR)}"
        for exc in refused
    )


def _set(handle: _Content, content: str) -> None:
    if handle.content != content:
        handle.content = content
