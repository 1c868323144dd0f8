"""Folder "Partager": the link of the page's setup, and the setup a link brings.

A teacher prepares a page (sliders, the panel shown, a lesson's step), chooses which
controls the students will find locked or hidden, and clicks "Copier le lien de cette
configuration": the link (:mod:`sandbox.web.panels.setup_link`) appears in a read-only field and
the page's script copies it (:mod:`sandbox.web.page.link`).

A browser opening such a link gets, once, when it connects (:func:`attach`, before its
session's loop starts; nothing per frame):

- the lesson and its step opened at once (their presets queued first), then every setting
  queued as the user's own requests, so that the simulation loop checks and applies them
  exactly as a slider move (a value that would not build the model is refused there, in
  French, like any other);
- the "Panneau affiché" choice; the folded folders it names are opened by the page's
  script;
- hidden controls removed from the page and locked ones disabled, with a French tooltip
  saying the teacher fixed them. Both are also refused on the server side (a disabled
  control's messages are ignored, see :func:`sandbox.web.client.fields.on_user`) and a lesson's
  presets leave them alone (:attr:`sandbox.web.panels.lesson.LessonPanel.fixed`);
- one French notification naming the parts of the link that were ignored, and why.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import viser

from sandbox.web.client import viser_internals
from sandbox.web.client.fields import on_user, param_label, set_value
from sandbox.web.client.text import plain
from sandbox.web.loop.requests import Command, Integrator, SetValue, Speed, Timestep
from sandbox.web.page.link import (
    BUTTON,
    FOLDABLE,
    LINK_LABEL,
    SHARE_FOLDER,
    from_query,
    link_base,
    page_address,
    request_query,
)
from sandbox.web.panels import setup_link
from sandbox.web.panels.controls import (
    ADVANCED_FOLDER,
    INTEGRATOR_LABEL,
    SPEED_LABEL,
    TIMESTEP_LABEL,
    advanced,
)
from sandbox.web.panels.display import FOLDER as DISPLAY_FOLDER
from sandbox.web.panels.join import FOLDER as JOIN_FOLDER
from sandbox.web.panels.projector import style_html
from sandbox.web.panels.setup_link import Page, Setup
from sandbox.web.views.browser import LESSON_WIDTH, WebView, point_camera

log = logging.getLogger(__name__)

CONTROL_LABEL = "Réglage"
ACCESS_LABEL = "Pour l'élève"
OPEN_LABEL = "Dossier ouvert"
FREE, LOCKED, HIDDEN = "Modifiable", "Verrouillé", "Caché"
ACCESS = (FREE, LOCKED, HIDDEN)
NO_FOLDER = "Aucun"

LOCKED_HINT = "Réglage fixé par l'enseignant : il ne se modifie pas sur cette page."
"""Tooltip of a control a link locked."""

NOTICE_TITLE = "Lien de configuration"
NOTICE_SECONDS = 20.0
"""Seconds the notification of the ignored parts of a link stays (time to read it)."""

INTRO = (
    "Le lien ouvre cette page avec ses réglages, le panneau affiché, le dossier choisi "
    "ci-dessous et l'étape de leçon en cours. Choisissez d'abord les réglages que les "
    "élèves trouveront verrouillés ou cachés."
)

SETTING_KINDS: Mapping[str, Callable[[Any], Command]] = {
    "speed": Speed,
    "integrator": Integrator,
    "timestep": Timestep,
}
"""The command of each simulation setting of a link (a parameter's is :class:`SetValue`)."""


def attach(
    server: viser.ViserServer,
    client: viser.ClientHandle,
    view: WebView,
    *,
    lesson: str | None = None,
    join_urls: Sequence[str] = (),
) -> SharePanel | None:
    """Add "Partager" to a live session's page and apply the link it was opened with.

    Called once, when the browser connects, before its session starts. Never raises for
    what the link holds (its refused parts are told in the page).

    Args:
        server: The viser server (the websocket's handshake carries the link).
        client: The browser.
        view: Its view, just built.
        lesson: The lesson the page opens by itself (``sandbox serve LESSON``).
        join_urls: Addresses students type: links start with the first
            (:func:`~sandbox.web.page.link.link_base`).

    Returns:
        The folder, or None when the view is not a live session's.
    """
    if view.live is None or view.control_panel is None:
        return None
    query, host, path = request_query(server, client.client_id)
    fragment, page = from_query(query)
    base, whose = link_base(join_urls, page_address(page, host, path))
    panel = SharePanel(client.gui, view, base=base, lesson=lesson, whose=whose)
    setup, ignored = setup_link.read(fragment, panel.page)
    panel.apply(setup)
    line = setup_link.refusal_line(ignored)
    if line:
        log.info("a link was partly ignored: %s", line)
        client.add_notification(
            NOTICE_TITLE,
            line,
            color="orange",
            with_close_button=True,
            auto_close_seconds=NOTICE_SECONDS,
        )
    return panel


class SharePanel:
    """The "Partager" folder of one page, and what a link does to that page.

    Args:
        gui: The page's ``GuiApi``.
        view: The page's view (a live session's).
        base: The address (origin and path) links start with.
        lesson: The lesson the page opens by itself.
        whose: The sentence saying whose address ``base`` is (shown under the link).
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        view: WebView,
        *,
        base: str,
        lesson: str | None = None,
        whose: str = "",
    ) -> None:
        controller, controls = view.live, view.control_panel
        if controller is None or controls is None:
            raise TypeError("« Partager » is for a live session's page")
        self.view = view
        self.controller = controller
        self.controls_panel = controls
        self.base = base
        sim = controller.sim
        with sim.lock:
            self.start_values = dict(sim.values)
            self.start_integrator = sim.integrator
            self.start_timestep = sim.timestep
        self.start_folder = view.shown
        self._lock = threading.Lock()
        scene = sim.scene
        params = tuple(scene.params) if scene is not None else ()
        # every control a link can hide or lock: name -> (label, its handles)
        self.controls: dict[str, tuple[str, list[viser.GuiInputHandle[Any]]]] = {}
        for p in params:
            handle = controls.sliders.get(p.name)
            if handle is not None:
                self.controls[p.name] = (param_label(p), [handle])
        slow = view.display.slow if view.display is not None else None
        speed: list[viser.GuiInputHandle[Any]] = [controls.speed]
        if slow is not None:
            speed.append(slow)
        self.controls["speed"] = (SPEED_LABEL, speed)
        self.controls["integrator"] = (INTEGRATOR_LABEL, [controls.integrator])
        self.controls["timestep"] = (TIMESTEP_LABEL, [controls.timestep])
        self.access: dict[str, str] = {name: FREE for name in self.controls}
        foldable = [f for f in FOLDABLE if f != ADVANCED_FOLDER or any(map(advanced, params))]
        if view.display is None:
            foldable = [f for f in foldable if f != DISPLAY_FOLDER]
        self.foldable = tuple(foldable)
        pickable = (*view.groups, *view.picker.options)
        lessons = view.lesson.available if view.lesson is not None else {}
        self.page: Page = setup_link.page_of(
            sim,
            folders=tuple(dict.fromkeys((*pickable, *self.foldable))),
            lessons={name: len(les.steps) for name, les in lessons.items()},
            lesson=lesson if lesson in lessons else None,
        )
        self.link = ""
        labels = tuple(label for label, _ in self.controls.values())
        self._by_label = {label: name for name, (label, _) in self.controls.items()}
        with gui.add_folder(SHARE_FOLDER, expand_by_default=False) as self.folder:
            gui.add_markdown(INTRO)
            self.control = gui.add_dropdown(
                CONTROL_LABEL,
                labels,
                hint="Le réglage dont vous choisissez l'accès pour les élèves",
            )
            self.choice = gui.add_dropdown(
                ACCESS_LABEL,
                ACCESS,
                hint="Modifiable : l'élève le change ; verrouillé : il le voit sans pouvoir "
                "le changer ; caché : il ne le voit pas",
            )
            self.summary = gui.add_markdown(self._summary())
            self.open_choice = gui.add_dropdown(
                OPEN_LABEL,
                (NO_FOLDER, *self.foldable),
                hint="Un dossier replié que la page des élèves ouvre d'elle-même",
            )
            self.button = gui.add_button(
                BUTTON, hint="Écrit le lien ci-dessous et le copie dans le presse-papiers"
            )
            self.field = gui.add_text(
                LINK_LABEL,
                "",
                multiline=True,  # the whole link in view, on a few lines
                hint="Le lien à donner aux élèves (si la copie est refusée : sélectionnez-le "
                "puis Ctrl+C)",
            )
            self.whose = gui.add_markdown(_address_words(whose, base)) if whose else None
        on_user(self.control, self._on_control)
        on_user(self.choice, self._on_choice)
        self.button.on_click(self._on_share)
        self.field.on_update(self._on_field)

    # -- viser's threads -----------------------------------------------------------------
    def _on_control(self, label: object) -> None:
        name = self._by_label.get(label) if isinstance(label, str) else None
        if name is not None:
            with self._lock:
                set_value(self.choice, self.access[name])

    def _on_choice(self, choice: object) -> None:
        name = self._by_label.get(self.control.value)
        if name is None or choice not in ACCESS:
            return
        with self._lock:
            self.access[name] = str(choice)
            self.summary.content = self._summary()

    def _on_share(self, _event: viser.GuiEvent[Any]) -> None:
        self.share()

    def _on_field(self, event: viser.GuiEvent[Any]) -> None:
        if event.client is not None and self.field.value != self.link:  # read-only
            set_value(self.field, self.link)

    def _summary(self) -> str:
        """Which controls are hidden and locked, in words (Markdown)."""

        def names(state: str) -> str:
            chosen = [
                plain(label) for n, (label, _) in self.controls.items() if self.access[n] == state
            ]
            return " ; ".join(chosen) if chosen else "aucun"

        return f"Réglages cachés : {names(HIDDEN)}  \nRéglages verrouillés : {names(LOCKED)}"

    def share(self) -> str:
        """Write the link of the page as it is now into the field; returns it."""
        with self._lock:
            self.link = setup_link.link(self.base, self.setup())
            set_value(self.field, self.link)
            return self.link

    def setup(self) -> Setup:
        """The page's setup now: settings that differ from the page's start (and every
        parameter a step of the open lesson presets), the panel shown, the folder chosen,
        the access chosen for each control, the lesson and its step."""
        ctl = self.controller
        sim = ctl.sim
        lesson, index = (None, 0)
        presets: set[str] = set()
        if self.view.lesson is not None:
            lesson, index = self.view.lesson.position()
            progress = self.view.lesson.progress
            if progress is not None:
                presets = {n for step in progress.lesson.steps for n, _ in step.preset}
        settings: list[tuple[str, float | str]] = []
        secret = ctl.secret  # a challenge's values never go into a link
        kept = secret.locked if secret is not None else frozenset()
        with sim.lock:
            for name, value in sim.values.items():
                if (
                    name in self.controls
                    and name not in kept
                    and (value != self.start_values.get(name) or name in presets)
                ):
                    settings.append((name, float(value)))
            if ctl.speed != 1.0:
                settings.append(("speed", float(ctl.speed)))
            if sim.integrator != self.start_integrator:
                settings.append(("integrator", sim.integrator))
            if sim.timestep != self.start_timestep:
                settings.append(("timestep", float(sim.timestep)))
        opened = []
        # « Rejoindre » is the teacher's own (the address to type): never a student's
        if self.view.shown not in (self.start_folder, JOIN_FOLDER):
            opened.append(setup_link.slug(self.view.shown))
        if self.open_choice.value in self.foldable:
            opened.append(setup_link.slug(self.open_choice.value))
        return Setup(
            settings=tuple(settings),
            open=tuple(opened),
            hide=tuple(n for n, a in self.access.items() if a == HIDDEN),
            lock=tuple(n for n, a in self.access.items() if a == LOCKED),
            lesson=lesson,
            step=index + 1 if lesson is not None else None,
        )

    # -- at connect, before the session's loop starts -----------------------------------
    def apply(self, setup: Setup) -> None:
        """Apply a checked link to this page (see the module's docstring)."""
        view, submit = self.view, self.controller.submit
        fixed = frozenset((*setup.hide, *setup.lock))
        if view.lesson is not None:
            view.lesson.fixed = fixed & frozenset(self.page.params)
            lesson = setup.lesson or self.page.lesson
            if lesson is not None and (setup.lesson is not None or setup.step is not None):
                view.lesson.open_at(lesson, (setup.step or 1) - 1)
                _show_lesson(view)
        for name, value in setup.settings:
            make = SETTING_KINDS.get(name)
            submit(make(value) if make is not None else SetValue(name, value))
        for slug in setup.open:
            label = self.page.folders.get(slug)
            if label is not None and label not in self.foldable:
                _show_panel(view, label)
            elif label is not None:
                set_value(self.open_choice, label)
        for name in setup.hide:
            self._restrict(name, HIDDEN)
        for name in setup.lock:
            self._restrict(name, LOCKED)
        shown = self._by_label.get(self.control.value)
        if shown is not None:  # "Pour l'élève" tells the truth for the control shown
            set_value(self.choice, self.access[shown])

    def _restrict(self, name: str, access: str) -> None:
        label_handles = self.controls.get(name)
        if label_handles is None:
            return
        self.access[name] = access
        for handle in label_handles[1]:
            handle.disabled = True
            if access == HIDDEN:
                handle.visible = False
            else:
                handle.hint = LOCKED_HINT
        self.summary.content = self._summary()


def _address_words(sentence: str, address: str) -> str:
    """``sentence`` as markdown, the ``address`` it ends with in a code span: markdown
    would turn it into a link whose backslashed characters show (« salle\\-b12 »)."""
    if address and sentence.endswith(address):
        words = sentence[: -len(address)].rstrip()
        return f"{plain(words)} `{address.replace('`', '')}`"
    return plain(sentence, limit=800)


def _show_lesson(view: WebView) -> None:
    """Unfold the lesson's column (the view folds it when the page opens no lesson by
    itself) and step the camera back for the 3D view between two columns. viser gives no
    public way from a folder to its panel: a later viser may leave the column folded."""
    lesson = view.lesson
    if lesson is None:
        return
    column = viser_internals.panel_of(lesson.gui, lesson.folder)
    if isinstance(column, viser.PanelHandle):
        column.expand()
        point_camera(view.client, view.controller.sim, narrow=True)
        projector = view.projector  # its overlay starts past the column, as the view's does
        projector.left = 16 + LESSON_WIDTH
        projector.style.content = style_html(
            projector.font, left=projector.left, right=projector.right
        )


def _show_panel(view: WebView, label: str) -> None:
    """Choose ``label`` in "Panneau affiché" as the user would (the view applies it at its
    next frame)."""
    view.show_folder(label)
