"""Folder "Leçon": lesson picker, step text, presets, live readouts, questions, live check.

Free exploration stays possible: every other control keeps working during a lesson, and
"Exploration libre" leaves it. Presets go through the session's request queue like any
slider move; the check is evaluated on the readouts the panels show.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from sandbox.lessons import Lesson, Progress, lessons
from sandbox.web.plots import Plot, group_by_unit
from sandbox.web.session import Request
from sandbox.web.tables import fmt

FREE = "Exploration libre"
NAV = ("◀ Précédent", "Suivant ▶")


class LessonPanel:
    """The lesson runner of one session.

    Args:
        gui: A viser ``GuiApi``.
        controller: The session's controller (requests, recorder).
        lesson: Lesson to open at once (``sandbox serve LESSON``), else free exploration.
        arrows: The arrow layer, to show only the step's arrows.
    """

    def __init__(
        self, gui: Any, controller: Any, *, lesson: str | None = None, arrows: Any = None
    ) -> None:
        self.gui = gui
        self.controller = controller
        self.arrows = arrows
        sim = controller.sim
        scene = sim.scene.name if sim.scene is not None else None
        self.available: dict[str, Lesson] = {
            name: les for name, les in lessons().items() if scene and les.for_scene(scene)
        }
        self.progress: Progress | None = None
        self.plots: list[Plot] = []
        self._step_handles: list[Any] = []
        self._pending: str | None = lesson if lesson in self.available else None
        self._pending_step: int | None = None
        self.folder = gui.add_folder("Leçon", expand_by_default=bool(self.available))
        with self.folder:
            titles = {FREE: FREE} | {les.title: name for name, les in self.available.items()}
            self._by_title = titles
            start = self.available[lesson].title if self._pending else FREE
            self.picker = gui.add_dropdown("Leçon", tuple(titles), initial_value=start)
            self.header = gui.add_markdown("")
            self.nav = gui.add_button_group("Étapes", NAV, visible=False)
            self.text = gui.add_markdown("")
            self.table = gui.add_markdown("")
            self.status = gui.add_markdown("")
            self.hint_button = gui.add_button("Indice", visible=False)
            self.hints = gui.add_markdown("")
        if not self.available:
            self.header.content = "Aucune leçon pour ce modèle : exploration libre."

        @self.picker.on_update
        def _(event: Any) -> None:
            if event.client is not None:
                self._pending = self._by_title.get(event.target.value, FREE)

        self.nav.on_click(lambda event: self._nav(event.target.value))
        self.hint_button.on_click(lambda _: self._hint())

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

    def position(self) -> tuple[str | None, int]:
        """The lesson followed (None: none) and the index of its current step."""
        if self.progress is None:
            return None, 0
        return self.progress.lesson.name, self.progress.index

    # -- loop thread ---------------------------------------------------------------------
    def refresh(self, values: Mapping[str, float]) -> None:
        """Apply a pending choice, then show the step and evaluate its check."""
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
        rows = [f"| {n} | {fmt(values.get(n, math.nan))} |" for n in step.show]
        table = ("| grandeur | valeur |\n|:--|--:|\n" + "\n".join(rows)) if rows else ""
        _set(self.table, table)
        if step.check is None:
            status = ""
        elif ok:
            status = f"✅ **Réussi.** {step.success}"
        elif progress.index in progress.passed:
            status = "✅ Étape déjà réussie ; la condition n'est plus remplie."
        else:
            status = f"⏳ Objectif : `{step.check.source}`"
        _set(self.status, status)
        shown = step.hints[: progress.hints_shown]
        _set(self.hints, "\n\n".join(f"💡 {h}" for h in shown))
        self.hint_button.visible = progress.hints_shown < len(step.hints)

    def _open(self, lesson: Lesson | None) -> None:
        for handle in self._step_handles:
            handle.remove()
        self._step_handles = []
        self.controller.lesson = lesson.name if lesson else None
        title = lesson.title if lesson is not None else FREE
        if self.picker.value != title and title in self._by_title:
            self.picker.value = title  # the control tells the truth
        if lesson is None:
            self.progress = None
            self.plots = []
            self.nav.visible = False
            self.hint_button.visible = False
            for handle in (self.header, self.text, self.table, self.status, self.hints):
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
            self.controller.submit(Request("set_value", value, name=name))
        recorder = getattr(self.controller, "recorder", None)
        if recorder is not None:
            recorder.event("lesson", step=index)
        n = len(progress.lesson.steps)
        _set(
            self.header,
            f"**{progress.lesson.title}** — étape {index + 1}/{n} : **{step.title}**",
        )
        _set(self.text, step.text)
        for handle in self._step_handles:
            handle.remove()
        self._step_handles = []
        self.plots = []
        with self.folder:
            if step.plots:
                units = {i.name: i.unit for i in self.controller.sim.readout_infos()}
                for plot in group_by_unit(step.plots, units, {}):
                    plot.attach(self.gui, title=f"{', '.join(plot.names)} [{plot.unit}]")
                    self.plots.append(plot)
                    self._step_handles.append(plot.handle)
            for question, answer in step.questions:
                q = self.gui.add_markdown(f"❓ {question}")
                button = self.gui.add_button("Voir la réponse", color="gray")
                reply = self.gui.add_markdown("")
                button.on_click(lambda _, r=reply, a=answer: setattr(r, "content", f"➜ {a}"))
                self._step_handles += [q, button, reply]
        if self.arrows is not None:
            self.arrows.only(step.arrows or None)


def _set(handle: Any, content: str) -> None:
    if handle.content != content:
        handle.content = content
