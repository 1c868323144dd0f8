"""The viser side of a session: 3D scene, arrows, panels and messages for one browser."""

from __future__ import annotations

import logging
import math
from collections import deque
from collections.abc import Callable, Collection, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Literal, Protocol

from sandbox.lessons import catalogue
from sandbox.web.client import wire
from sandbox.web.client.fields import set_value
from sandbox.web.loop import EVERY, Frame, Notice
from sandbox.web.loop.frame import Source
from sandbox.web.loop.requests import Integrator, Timestep
from sandbox.web.loop.secret import Secret
from sandbox.web.loop.state import SessionState
from sandbox.web.panels.accuracy import AccuracyPanel
from sandbox.web.panels.bearing import BearingPanel
from sandbox.web.panels.challenge import ChallengePanel
from sandbox.web.panels.controls import ControlPanel, HypothesesPanel
from sandbox.web.panels.cycle import CyclePanel
from sandbox.web.panels.display import DisplayPanel
from sandbox.web.panels.folder import Folder
from sandbox.web.panels.isolate import IsolatePanel
from sandbox.web.panels.join import JoinPanel
from sandbox.web.panels.lesson import LessonPanel
from sandbox.web.panels.polar import PolarPanel
from sandbox.web.panels.power_flow import PowerFlowPanel
from sandbox.web.panels.projector import Projector
from sandbox.web.panels.readouts import (
    PLOTS_FOLDER,
    SCENE_FOLDER,
    ReadoutPanel,
)
from sandbox.web.panels.study import StudyPanel
from sandbox.web.panels.xy import XYPanel
from sandbox.web.video.export import VideoExport
from sandbox.web.view3d.arrows import ArrowLayer
from sandbox.web.view3d.camera import point_camera
from sandbox.web.view3d.geoms import mechanism_size
from sandbox.web.view3d.renderer import SceneRenderer
from sandbox.web.view3d.stage import draw_scene
from sandbox.web.view3d.trail import Trail

if TYPE_CHECKING:
    import viser

    from sandbox.physics.picture import Picture
    from sandbox.physics.simulation import Simulation

PANEL_RATE = 10.0
"""Refresh rate of the tables and plots [Hz] (poses and arrows go at the frame rate)."""

ALL_FOLDERS = "Tous les panneaux"
MAX_HELD = 0.5
"""Seconds a session may go without drawing while its sender holds frames; then it
draws anyway (a browser never waits for its 3D view longer, whatever held it)."""

IN_FLIGHT = 3
"""Frames a browser's sender may hold before its session stops drawing new ones. viser
takes a window every 1/60 s, in no step with the frames, and its thread waits for the
interpreter lock on a busy server: with one frame allowed, a session waited on a sender
that waited on it, and an engine class got 9 frames/s instead of 18."""

LESSON_TAB = "Leçon"
LESSON_WIDTH = 380
"""Width [px] of the lesson's column, docked left of the 3D view: the step's text stays
beside the simulation controls on a 1280×720 projector, with no scrolling."""
CONTROLS_WIDTH = 430
"""Width [px] of the control panel, docked right of the 3D view (labels of 16 px text on
two lines at most)."""


class Controls(Protocol):
    """The top panel of a view: the live :class:`ControlPanel` or a replay's timeline."""

    def refresh(self, time: float | None = None) -> None: ...
    def sync(self) -> None: ...


def arrow_layer(scene: viser.SceneApi, sim: Simulation, *, prefix: str = "") -> ArrowLayer | None:
    """The scene's force arrows in a viser scene (None when the scene has none)."""
    spec = sim.scene
    if spec is None or not spec.page.arrows:
        return None
    units = {i.name: i.unit for i in sim.readout_infos()}
    return ArrowLayer(
        scene,
        spec.page.arrows,
        extent=float(sim.model.stat.extent),
        size=mechanism_size(sim.model, sim.data),
        units=[units.get(a.name, "") for a in spec.page.arrows],
        zero=spec.zero,
        prefix=prefix,
    )


class WebView:
    """Draws a source's simulation into one viser client (implements ``View``).

    Args:
        client: The viser ``ClientHandle`` of the browser.
        source: What the page shows: a live session's :class:`Controller`, or a replay.
        live: The live session the page drives (the same controller, seen as its panels
            see it): its controls, lesson, challenge, « Affichage », X–Y plot, study,
            video and accuracy cost. None for a replay, which brings its own ``controls``.
        controls: Builds the top panel (default: the live :class:`ControlPanel`).
        lesson: Lesson to open at once (live sessions only).
        join_urls: Addresses students type to join (folder "Rejoindre" when given).
        draw: Draw the 3D scene; False when another view draws it for everyone (the
            teacher's panels in follow mode), whose arrows are then ``shared_arrows``.
        shared_arrows: The arrows drawn by that other view.
    """

    def __init__(
        self,
        client: viser.ClientHandle,
        source: Source,
        *,
        live: SessionState | None = None,
        controls: Callable[[viser.GuiApi], Controls] | None = None,
        lesson: str | None = None,
        join_urls: Sequence[str] = (),
        draw: bool = True,
        shared_arrows: ArrowLayer | None = None,
    ) -> None:
        self.client = client
        self.controller = source
        self.live = live
        sim = source.sim
        model = sim.model
        client.gui.configure_theme(control_width="large", show_share_button=False)
        client.gui.main_panel.dock_right()
        client.gui.main_panel.set_width(CONTROLS_WIDTH)
        point_camera(client, sim)
        self.renderer: SceneRenderer | None = None
        self.arrows: ArrowLayer | None = shared_arrows
        self.trail: Trail | None = None
        if draw:
            self.renderer = SceneRenderer(client.scene)
            self.arrows = arrow_layer(client.scene, sim)
            scene = sim.scene
            if scene is not None and scene.page.trail is not None:
                self.trail = Trail(client.scene, extent=float(model.stat.extent))
        known = set(sim.readout_names())
        arrows = self.arrows.arrows if self.arrows is not None else ()
        self._arrow_readouts = {a.name for a in arrows if a.name in known}
        self.lesson: LessonPanel | None = None
        self.challenge: ChallengePanel | None = None
        self.control_panel: ControlPanel | None = None  # a live page's (a link hides its
        # controls, a challenge its secret ones)
        self._allowed: tuple[str, ...] | None = None  # folders left by a challenge
        self.controls: Controls
        if controls is not None:
            self.controls = controls(client.gui)
        elif live is not None:
            self.challenge = ChallengePanel(
                client.gui, live, self, announce=lambda title, text: _notify(client, title, text)
            )
            self.controls = self.control_panel = ControlPanel(client.gui, live)
        else:
            raise TypeError("a page without a live session needs its own controls")
        own = live if controls is None else None  # a page of the live session's own
        self.video = VideoExport(client.gui, own) if own is not None else None
        self.join = JoinPanel(client.gui, join_urls) if join_urls else None
        left = 16
        if own is not None:
            self.lesson, docked = _lesson_column(client.gui, own, lesson, self.arrows)
            left += LESSON_WIDTH if docked else 0
        if left > 16:
            point_camera(client, sim, narrow=True)
        self.display: DisplayPanel | None = None
        if live is not None:  # "Affichage": slow motion, Pas, camera
            self.display = DisplayPanel(
                client.gui,
                live,
                scene=client.scene if draw else None,
                renderer=self.renderer,
                camera=client.camera if draw else None,
                arrows=self.arrows,
                point=lambda: self.readouts.chosen_point(),
            )
        self.picker = client.gui.add_dropdown(
            "Panneau affiché",
            (ALL_FOLDERS,),
            hint="Un seul panneau de mesures à la fois : il reste lisible au projecteur et "
            "seules ses grandeurs sont calculées",
        )
        self.readouts = ReadoutPanel(client.gui, sim, arrows=self.arrows)
        self.polar = PolarPanel.create(client.gui, sim)
        self.bearing = BearingPanel.create(client.gui, sim)
        self.power_flow = PowerFlowPanel.create(client.gui, sim)
        self.cycle = CyclePanel(client.gui, sim)
        self.xy = XYPanel(client.gui, live) if live is not None else None
        self.study = StudyPanel(client.gui, live) if live is not None else None
        self.isolate = IsolatePanel(client.gui, sim)
        self.accuracy = AccuracyPanel(
            client.gui,
            sim,
            choose=_chooser(live) if live is not None else None,
            cost=_cost(live) if live is not None else None,
        )
        self.hypotheses = HypothesesPanel(client.gui, sim)
        self.projector = Projector(client.gui, sim, left=left, right=CONTROLS_WIDTH + 16)
        # « Panneau affiché »: every panel's folders, in the picker's order. A new panel
        # adds its folders here (its own pickable() says how each is shown and refreshed).
        self.pickable: list[Folder] = [
            *self.readouts.pickable(),
            *(self.polar.pickable() if self.polar is not None else ()),
            *(self.bearing.pickable() if self.bearing is not None else ()),
            *(self.power_flow.pickable() if self.power_flow is not None else ()),
            *self.cycle.pickable(),
            *(self.xy.pickable() if self.xy is not None else ()),
            *(self.study.pickable() if self.study is not None else ()),
            *self.isolate.pickable(),
            *self.accuracy.pickable(),
            *self.hypotheses.pickable(),
            *(self.join.pickable() if self.join is not None else ()),
            *self.projector.pickable(),
        ]
        if self.arrows is not None:  # labels placed in this browser's view, at its text size
            self.arrows.watch(
                client.camera,
                font=lambda: self.projector.font,
                marks=self.renderer,
            )
        self._picture: Picture | None = None  # the last one drawn
        self._held_since: float | None = None  # first frame not drawn for the sender
        self.holding = False  # the last frame was not drawn: the sender still held frames
        self._marks: deque[int] = deque(maxlen=IN_FLIGHT)  # viser's last message id
        # before each of the last frames drawn
        self._last_panel = -math.inf
        self._resync_controls = False
        self._add_picker()

    # -- which folder is shown -----------------------------------------------------------
    def _add_picker(self) -> None:
        """One readout folder shown at a time (only it is computed and sent)."""
        self._by_title = {f.title: f for f in self.pickable}
        self._watching = [f for f in self.pickable if f.watch is not None]
        groups = {f.title: f.handle for f in self.pickable}
        self.groups = groups
        default = SCENE_FOLDER if SCENE_FOLDER in groups else next(iter(groups), ALL_FOLDERS)
        self.shown = self.default_folder = default
        self.picker.options = (*groups, ALL_FOLDERS)
        # viser declares value both as a property and as a props field: mypy reads the
        # field as read-only, the property assigns it.
        self.picker.value = default  # type: ignore[misc]

        self._pending_folder: str | None = default

        @self.picker.on_update
        def _(event: viser.GuiEvent[viser.GuiDropdownHandle[str]]) -> None:
            if event.client is not None:
                self._pending_folder = str(event.target.value)

    def show_folder(self, label: str) -> None:
        """Show the folder ``label`` of « Panneau affiché » (or every one) as if the user
        picked it: the picker says so, and the view applies it at its next frame (a
        folder a challenge closed is refused then)."""
        set_value(self.picker, label)
        self._pending_folder = label

    def _apply_folder(self) -> None:
        choice, self._pending_folder = self._pending_folder, None
        if choice is None:
            return
        allowed = self._allowed if self._allowed is not None else tuple(self.groups)
        self.shown = choice if choice in allowed or choice == ALL_FOLDERS else self.shown
        if self.shown not in (*allowed, ALL_FOLDERS):
            self.shown = SCENE_FOLDER if SCENE_FOLDER in allowed else ALL_FOLDERS
        for label, folder in self.groups.items():
            folder.visible = self.shown in (label, ALL_FOLDERS) and label in allowed
        self._last_panel = -math.inf  # fill the folder just shown at once

    def _showing(self, folder: str) -> bool:
        if self._allowed is not None and folder not in self._allowed:
            return False  # closed by a challenge: neither refreshed nor sent
        return self.shown in (folder, ALL_FOLDERS)

    # -- a challenge ---------------------------------------------------------------------
    def restrict(self, secret: Secret) -> None:
        """A challenge starts (from the class board's thread): the secret controls go,
        the readouts that would give it away and the folders that read the simulation
        are closed until :meth:`unrestrict`."""
        # kept: the folders that show only the frame's readouts (withheld ones removed);
        # the others read the simulation itself (isolating a solid, the polar diagram,
        # accuracy against the course's closed form): closed until it ends
        self._allowed = tuple(f.title for f in self.pickable if f.secret_safe)
        self.readouts.withheld = secret.withheld
        if self.control_panel is not None:
            self.control_panel.conceal(secret.public, secret.locked)
        self.picker.options = (*self._allowed, ALL_FOLDERS)
        self._pending_folder = self.shown

    def unrestrict(self) -> None:
        """The challenge is over: every folder and control back."""
        self._allowed = None
        self.readouts.withheld = frozenset()
        if self.control_panel is not None:
            self.control_panel.reveal()
        self.picker.options = (*self.groups, ALL_FOLDERS)
        self._pending_folder = self.shown

    # -- View protocol -------------------------------------------------------------------
    @property
    def draws(self) -> bool:
        """True when this view draws the 3D scene now: not for the teacher's panels in
        follow mode (the broadcast draws), nor while its browser's sender still holds
        :data:`IN_FLIGHT` frames (a slow link: that session draws fewer frames, and spends
        nothing on frames viser would merge)."""
        if self.renderer is None:
            return False
        marks = wire.sent_marks(self.client)
        if marks is None or len(self._marks) < IN_FLIGHT or marks[1] >= self._marks[0]:
            self._held_since = None
            self.holding = False
            return True
        now = self.controller.clock()  # the source's wall clock
        if self._held_since is None:
            self._held_since = now
        self.holding = now - self._held_since <= MAX_HELD  # never silent for long
        return not self.holding

    def _note_sent(self) -> None:
        """Before a new frame's messages: the last message queued so far, which must have
        gone out before :data:`IN_FLIGHT` more frames are drawn."""
        marks = wire.sent_marks(self.client)
        if marks is not None:
            self._marks.append(marks[0])

    def wants(self, now: float) -> Collection[str] | None:
        """Readouts this tick needs: those of the shown folder, the plots and an open
        lesson, at :data:`PANEL_RATE`; None between refreshes."""
        if self._pending_folder is not None:
            self._apply_folder()
        for folder in self._watching:  # every tick: only the folders that sample
            if folder.watch is not None:
                folder.watch(self._showing(folder.title))
        if now - self._last_panel < 1.0 / PANEL_RATE:
            return None
        if self.lesson is not None and self.lesson.progress is not None:
            return EVERY  # the lesson's checks may use any readout
        if self.shown == ALL_FOLDERS:
            return EVERY
        names = {"time", *self.readouts.plot_names()}
        names.update(self.projector.names)
        names.update(self._arrow_readouts)  # the labels write them, at the same instant
        shown = self._by_title.get(self.shown)
        if shown is not None:
            names.update(shown.names())
        return names

    def render(self, frame: Frame) -> None:
        """The frame's picture when it brings one (the drawn state changed): poses and
        arrows that moved; the shown folder, plots and lesson when it brings readouts
        (:data:`PANEL_RATE`)."""
        with self.client.atomic():
            if self._resync_controls:
                self._resync_controls = False
                self.controls.sync()
            drawing = None if frame.diverged or self.renderer is None else frame.picture
            if drawing is not None:
                self._note_sent()  # viser's last message before this frame's
                self._picture = drawing
            drawn = draw_scene(self.renderer, self.arrows, drawing, bool(frame.diverged))
            if drawn and drawing is not None and self.display is not None:
                self.display.draw(drawing)
            still = None if drawn or frame.diverged else self._picture
            if still is not None and self.arrows is not None and self.arrows.dirty:
                # a scale or a lesson's choice changed while nothing moves
                self.arrows.draw(still.arrows, still.magnitudes)
            if frame.readouts is not None or (
                frame.diverged and frame.now - self._last_panel >= 1.0 / PANEL_RATE
            ):
                self._last_panel = frame.now
                self._refresh_panels(frame)

    def _refresh_panels(self, frame: Frame) -> None:
        """What every page refreshes at the panels' rate, then the folders shown."""
        # the status line's t is the instant the tables show (the drawn state's)
        self.controls.refresh(None if frame.state is None else float(frame.state.data.time))
        if self.video is not None:
            self.video.refresh()
        self.projector.refresh(
            None if frame.diverged else frame.readouts, held=frame.held is not None
        )
        if self.display is not None:
            self.display.refresh()
        values = None if frame.diverged else frame.readouts
        arrows_at = frame.held or self._picture  # the instant the numbers are read at
        if values is not None:
            self.readouts.sample(values, push=self._showing(PLOTS_FOLDER), picture=arrows_at)
            if self.lesson is not None:
                self.lesson.refresh(values)
            drawing = self._picture
            if self.trail is not None and drawing is not None and drawing.trail is not None:
                self.trail.add(drawing.time, drawing.trail)
        for folder in self.pickable:
            if folder.refresh is None or not self._showing(folder.title):
                continue
            if values is not None or not folder.needs_readouts:
                folder.refresh(frame)
        if values is not None and self.arrows is not None:
            # the instant the tables and the overlay show (a fast rotation's held angle)
            held = None if frame.held is None else frame.held.magnitudes
            self.arrows.relabel(values, held)

    def notify(self, notice: Notice) -> None:
        """A toast for every notice; refused values put the controls back; a finished
        recording is also sent to the browser as a download."""
        if notice.level == "file":
            path = Path(notice.text)
            self.client.send_file_download(path.name, path.read_bytes())
            # The page names the file only (where the server keeps it is no business of
            # a student's); the teacher's terminal says where it is.
            logging.getLogger(__name__).warning("recording saved: %s", path)
            notice = Notice("info", notice.title, f"Fichier {path.name} (aussi téléchargé).")
        color: Literal["red", "orange", "blue"] = (
            "red" if notice.level == "error" else "orange" if notice.level == "diverged" else "blue"
        )
        self.client.add_notification(
            notice.title,
            notice.text,
            with_close_button=True,
            auto_close_seconds=None if notice.level == "diverged" else 8.0,
            color=color,
        )
        if notice.level == "error":
            self._resync_controls = True
        self._last_panel = -math.inf  # show the new state at once


def _chooser(live: SessionState) -> Callable[[str, float], None]:
    """« Précision et coût »'s choice of a precision: its setting applied to ``live``."""

    def choose(integrator: str, timestep: float) -> None:
        live.submit(Integrator(integrator))
        live.submit(Timestep(timestep))

    return choose


def _notify(client: viser.ClientHandle, title: str, text: str) -> None:
    """A notice on the page, wherever the student has scrolled."""
    client.add_notification(title, text, with_close_button=True, auto_close_seconds=12.0)


def _cost(live: SessionState) -> Callable[[], float]:
    """This session's CPU cost per simulated second, read when the folder refreshes."""
    return lambda: live.cost


def _lesson_column(
    gui: viser.GuiApi, controller: SessionState, lesson: str | None, arrows: ArrowLayer | None
) -> tuple[LessonPanel, bool]:
    """The lesson panel, in its own column docked left of the 3D view when the scene has
    lessons (minimised unless a lesson opens at once); else in the control panel.

    Returns:
        The panel, and True when it is docked (the 3D view then starts past it).
    """
    scene = controller.sim.scene
    name = scene.name if scene is not None else None
    found = catalogue()[0] if name is not None else {}
    if name is None or not any(les.for_scene(name) for les in found.values()):
        return LessonPanel(gui, controller, lesson=lesson, arrows=arrows), False
    column = gui.add_panel()
    with column.add_tab(LESSON_TAB):
        panel = LessonPanel(gui, controller, lesson=lesson, arrows=arrows)
    column.dock_left()
    column.set_width(LESSON_WIDTH)
    if lesson is None:
        column.minimize()
        return panel, False
    return panel, True
