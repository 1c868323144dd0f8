"""Follow mode (``sandbox serve X --follow``): the teacher drives one simulation that
every other browser watches.

The shared simulation is drawn once into viser's broadcast scene (``server.scene``,
under ``/prof``), so its cost does not grow with the number of watchers: a follower
only receives the same pose messages and, a few times a second, a short table of the
key readouts. The teacher opens a secret link (``/prof/<token>``, printed at start)
whose page carries the full panels, driving the shared simulation, and the folder
"La classe": two buttons that send the teacher's parameters or lesson step to every
student's own copy, and the class board (:mod:`sandbox.web.panels.board`: one row per
student, following or on their own copy).

A student leaves with "Ma simulation" for a copy of their own (starting from the
teacher's parameters; the teacher's scene is hidden in that browser only, by a
client-scoped variant of ``/prof``), and comes back with "Suivre le professeur".
"""

from __future__ import annotations

import functools
import logging
import math
import secrets
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import viser

from sandbox.physics.model import Source
from sandbox.physics.simulation import Simulation
from sandbox.web.client.text import plain, table_row
from sandbox.web.loop import Controller, Frame, Notice, Session
from sandbox.web.loop.requests import Integrator, Reset, SetValue, Timestep
from sandbox.web.loop.study_queue import StudyJob, progress_words
from sandbox.web.page.link import arrival
from sandbox.web.panels.board import BOARD_FOLDER, TEACHER_PREFIX
from sandbox.web.panels.board import teacher_path as teacher_path  # re-exported
from sandbox.web.panels.projector import FONT_SIZES, held_line, style_html
from sandbox.web.panels.study_chart import StudyChart
from sandbox.web.panels.tables import fmt
from sandbox.web.serving import network
from sandbox.web.serving.class_board import Classroom
from sandbox.web.serving.own_page import own_page
from sandbox.web.serving.server import App, SimOptions
from sandbox.web.view3d.arrows import ArrowLayer
from sandbox.web.view3d.camera import point_camera
from sandbox.web.view3d.renderer import SceneRenderer
from sandbox.web.view3d.stage import draw_scene
from sandbox.web.views.browser import WebView, arrow_layer
from sandbox.written import time_line, written

log = logging.getLogger(__name__)

SHARED = TEACHER_PREFIX
"""Scene-tree folder of the shared simulation (hidden per browser in own mode)."""

SUMMARY_RATE = 4.0
"""Refreshes per second of the followers' readout table [Hz]."""

FOLLOWER_FPS = 8.0
"""Frame rate of a follower's own (GUI-only) loop [Hz]; the 3D view comes from the
broadcast at the teacher's frame rate."""

OWN = "Ma simulation"
FOLLOW = "Suivre le professeur"
SEND_LABEL = "Envoyer aux élèves"
SEND_VALUES = "Mes réglages"
SEND_STEP = "Mon étape de leçon"
SEND_STUDY = "Mon étude"
STUDY_FOLDER = "Étude du professeur"
"""The teacher's two buttons, short enough for one line at 24 px on a 1280×720 page
("Envoyer mes réglages aux élèves" was cut)."""


@dataclass(frozen=True)
class Setting:
    """What the teacher sends to the students' own copies."""

    values: Mapping[str, float]
    integrator: str
    timestep: float
    lesson: tuple[str | None, int] | None = None


class BroadcastView:
    """Draws the shared simulation into the broadcast scene and keeps the followers'
    readout table (implements the session ``View`` protocol)."""

    def __init__(self, server: viser.ViserServer, controller: Controller) -> None:
        self.server = server
        self.controller = controller
        sim = controller.sim
        self.renderer = SceneRenderer(server.scene, prefix=f"{SHARED}/model")
        self.arrows: ArrowLayer | None = arrow_layer(server.scene, sim, prefix=SHARED)
        spec = sim.scene
        self.names = [r.name for r in spec.readouts][:8] if spec else ["T", "V"]
        known = set(sim.readout_names())  # the labels write these at the summary's instant
        arrows = self.arrows.arrows if self.arrows is not None else ()
        self.asked = [*self.names, *(a.name for a in arrows if a.name in known)]
        infos = {i.name: i for i in sim.readout_infos()}
        self.units = {n: i.unit for n, i in infos.items()}  # contract units
        zero = dict(spec.zero) if spec is not None else {}
        self.zeros = {n: zero.get(i.unit, 0.0) for n, i in infos.items()}
        self.labels = {n: plain(i.label or n) for n, i in infos.items()}
        self.summary = ""
        self.version = 0
        self.teachers: list[WebView] = []
        self._summary_at = -math.inf

    @property
    def draws(self) -> bool:
        """True while a browser watches: nobody watching, nothing is drawn nor sent."""
        return bool(self.server.get_clients())

    def wants(self, now: float) -> list[str] | None:
        """The followers' table readouts, :data:`SUMMARY_RATE` times a second."""
        if now - self._summary_at < 1.0 / SUMMARY_RATE or not self.server.get_clients():
            return None
        self._summary_at = now
        return self.asked

    def render(self, frame: Frame) -> None:
        """The picture (once for every follower: the broadcast scene), and the followers'
        table at :data:`SUMMARY_RATE`."""
        if frame.picture is None and frame.readouts is None and not frame.diverged:
            return
        with self.server.atomic():
            draw_scene(self.renderer, self.arrows, frame.picture, bool(frame.diverged))
            if frame.readouts is not None or frame.diverged:
                self._summarise(frame)
                if self.arrows is not None:
                    held = None if frame.held is None else frame.held.magnitudes
                    self.arrows.relabel(frame.readouts, held)

    def _summarise(self, frame: Frame) -> None:
        controller = self.controller
        state = "en pause" if not frame.playing else f"vitesse ×{fmt(controller.speed)}"
        # the instant the numbers are read at (a fast rotation's held one)
        at = frame.time if frame.state is None else float(frame.state.data.time)
        lines = [f"{time_line(at)} · {state}"]
        if frame.diverged:
            lines.append(f"**{frame.diverged}**")
        elif frame.readouts is not None:
            values = frame.readouts
            rows = [table_row("Grandeur", "Valeur"), "|:--|--:|"]
            # the words of the way the motion is computed now (« Couple nécessaire »)
            self.labels = {i.name: plain(i.label or i.name) for i in controller.sim.readout_infos()}
            for name in self.names:  # written as the page's table writes it
                shown = written(
                    name,
                    values.get(name, math.nan),
                    self.units.get(name, ""),
                    zero=self.zeros.get(name, 0.0),
                )
                rows.append(table_row(self.labels.get(name, name), str(shown)))
            lines.append("\n".join(rows))
            if frame.held is not None:
                lines.append(held_line(values))
        text = "\n\n".join(lines)
        if text != self.summary:
            self.summary = text
            self.version += 1

    def notify(self, notice: Notice) -> None:
        """Refusals and divergences of the shared simulation go to the teacher's pages."""
        for view in list(self.teachers):
            try:
                view.notify(notice)
            except Exception:
                log.debug("teacher page gone", exc_info=True)


def counts_text(followers: int, own: int) -> str:
    """The teacher's line of who follows: « Élèves : 1 suit la projection, 2 en
    autonomie. » (the verb agrees: 0 and 1 suit, 2 suivent)."""
    verb = "suit" if followers < 2 else "suivent"
    return f"Élèves : {followers} {verb} la projection, {own} en autonomie."


class FollowerView:
    """A student watching the shared simulation: the broadcast 3D view, the key
    readouts, and the way out to a simulation of their own."""

    def __init__(
        self,
        client: viser.ClientHandle,
        broadcast: BroadcastView,
        on_own: Callable[[], None],
        *,
        intro: str = "Vous suivez la simulation que le professeur projette.",
    ) -> None:
        self.broadcast = broadcast
        self._seen = -1
        client.gui.configure_theme(control_width="large", show_share_button=False)
        client.gui.add_html(style_html(FONT_SIZES[0]))  # the page's 16 px text
        with client.gui.add_folder("Simulation du professeur"):
            self.intro = client.gui.add_markdown(intro)
            self.text = client.gui.add_markdown("")
            self.own = client.gui.add_button(
                OWN,
                hint="Explorer votre propre copie de la scène, avec les réglages actuels "
                "du professeur",
            )
        self.own.on_click(lambda _: on_own())
        self.client = client
        self.study: StudyJob | None = None
        self.chart: StudyChart | None = None
        self._study_done = -1

    def receive_study(self, job: StudyJob) -> None:
        """The teacher sent a study: a folder with its chart (replacing an older one),
        its progress and its files; drawn by :meth:`render` as its runs finish."""
        gui = self.client.gui
        if self.chart is None:
            with gui.add_folder(STUDY_FOLDER) as folder:
                self.study_text = gui.add_markdown("")
            self.chart = StudyChart(gui, folder, self.broadcast.controller.sim)
            with folder:
                csv = gui.add_button("Télécharger l'étude (CSV)", color="gray")
                png = gui.add_button("Télécharger l'étude (PNG)", color="gray")
            csv.on_click(lambda e: self._download(e.client, "csv"))
            png.on_click(lambda e: self._download(e.client, "png"))
        self.study, self._study_done = job, -1

    def _download(self, client: viser.ClientHandle | None, kind: str) -> None:
        job = self.study
        if client is not None and job is not None and job.done > 0:
            StudyChart.download(client, kind, job)

    draws = False  # the broadcast draws the scene once for every follower

    def wants(self, now: float) -> None:
        return None  # the broadcast computes the table once for every follower

    def render(self, frame: Frame) -> None:
        if self.broadcast.version != self._seen:
            self._seen = self.broadcast.version
            self.text.content = self.broadcast.summary
        job = self.study
        if job is not None and self.chart is not None and job.done != self._study_done:
            self._study_done = job.done
            self.study_text.content = progress_words(job, 0)
            self.chart.draw(job)

    def notify(self, notice: Notice) -> None:
        pass


class FollowApp(App):
    """The web app of ``--follow``: one shared simulation, a teacher, followers and
    students exploring their own copies.

    Args:
        server: The viser server.
        host: Interface listened on.
        target: The scene or MJCF file served (resolved by :func:`sandbox.scenes.resolve`).
        options: Simulation options (values, integrator, timestep).
        lesson: Lesson opened on the teacher's page and the students' copies.
        token: Secret of the teacher's link (random when None).
        join_urls: Addresses students type (folder "Rejoindre" on the teacher's page).
    """

    def __init__(
        self,
        server: viser.ViserServer,
        host: str,
        target: Source,
        options: SimOptions,
        *,
        lesson: str | None = None,
        token: str | None = None,
        join_urls: tuple[str, ...] = (),
        max_sessions: int = 200,
    ) -> None:
        self.target = target
        self.options = options
        self.lesson = lesson
        self.token = token or secrets.token_urlsafe(9)
        self.join_urls = join_urls
        self.shared = Controller(Simulation(target, **self.options))
        self.broadcast = BroadcastView(server, self.shared)
        self.broadcast_session = Session(self.shared, self.broadcast)
        self.modes: dict[int, str] = {}
        self._views: dict[int, WebView] = {}
        self._followers: dict[int, FollowerView] = {}
        self.study: StudyJob | None = None  # the teacher's, sent to every student
        self._switch = threading.Lock()
        network.page_alias(teacher_path(self.token))
        self.classroom = Classroom(lambda cid: self.connected(cid))
        super().__init__(server, host, self._open, max_sessions=max_sessions)
        self.broadcast_session.start()
        self.classroom.start()

    @property
    def teacher_url(self) -> str:
        """The teacher's link (on this machine)."""
        return self.url + teacher_path(self.token)

    # -- sessions of each kind -----------------------------------------------------------
    def _open(self, client: viser.ClientHandle) -> Session:
        if network.request_path(self.server, client.client_id) == teacher_path(self.token):
            return self._teacher(client)
        return self._follower(client)

    def _teacher(self, client: viser.ClientHandle) -> Session:
        self.modes[client.client_id] = "teacher"
        with client.gui.add_folder(BOARD_FOLDER) as folder:
            counts = client.gui.add_markdown("")
            buttons = client.gui.add_button_group(
                SEND_LABEL,
                (SEND_VALUES, SEND_STEP, SEND_STUDY),
                hint="Vos réglages ou l'étape de leçon où vous êtes, vers la simulation de "
                "chaque élève en autonomie ; votre étude paramétrique, vers tous les élèves",
            )
        view = WebView(
            client,
            self.shared,
            live=self.shared,
            lesson=self.lesson,
            join_urls=self.join_urls,
            draw=False,
            shared_arrows=self.broadcast.arrows,
        )
        self._views[client.client_id] = view
        self.broadcast.teachers.append(view)
        scene = self.shared.sim.scene
        self.classroom.teacher(
            client, folder=folder, scene=scene.name if scene else "", followed=True
        )
        buttons.on_click(lambda event: self._send(event.target.value, view))
        session = _TeacherSession(self, view, counts)
        return session

    def _follower(self, client: viser.ClientHandle) -> Session:
        cid = client.client_id
        self.modes[cid] = "follower"
        point_camera(client, self.shared.sim)
        view = FollowerView(client, self.broadcast, lambda: self.switch(client, own=True))
        self._followers[cid] = view
        if self.study is not None:  # the teacher's study, to a student joining later
            view.receive_study(self.study)
        self.classroom.seat(
            client, self.shared.sim, mode="follow", who=functools.partial(arrival, self.server, cid)
        )
        return Session(
            self.shared, view, fps=FOLLOWER_FPS, alive=lambda: self.connected(cid), drive=False
        )

    def _own(self, client: viser.ClientHandle) -> Session:
        cid = client.client_id
        self.modes[cid] = "own"
        sim = self.shared.sim
        controller = Controller(
            Simulation(
                self.target,
                values=dict(sim.values),
                integrator=sim.integrator,
                timestep=sim.timestep,
                motion=sim.motion,
            )
        )
        client.scene.add_frame(SHARED, show_axes=False, visible=False)  # this browser only
        with client.gui.add_folder("Classe"):
            back = client.gui.add_button(
                FOLLOW, hint="Revenir à la simulation projetée par le professeur"
            )
        back.on_click(lambda _: self.switch(client, own=False))
        # the same page as a class's student: « Partager » and « Rejoindre » included
        page = own_page(
            self.server,
            client,
            controller,
            lesson=self.lesson,
            join_urls=self.join_urls,
            alive=lambda: self.connected(cid),
        )
        view = page.view
        self._views[cid] = view
        if self.study is not None and view.study is not None:
            view.study.receive(self.study)
        self.classroom.seat(
            client, controller.sim, view, who=functools.partial(arrival, self.server, cid)
        )
        return page.session

    def switch(self, client: viser.ClientHandle, *, own: bool) -> None:
        """Move a student between following and a simulation of their own."""
        cid = client.client_id
        with self._switch:
            with self._lock:
                old = self.sessions.pop(cid, None)
            if old is None:  # gone, or being opened
                return
            old.stop()
            self._views.pop(cid, None)
            self._followers.pop(cid, None)
            client.gui.reset()
            client.scene.reset()  # own nodes go; the broadcast's show again
            try:
                session = self._own(client) if own else self._follower(client)
            except Exception as exc:
                log.exception("cannot switch a student's mode")
                client.add_notification("Erreur", f"Changement impossible : {exc}", color="red")
                session = self._follower(client)
            with self._lock:
                self.sessions[cid] = session
            session.start()

    def _send(self, what: str, teacher: WebView) -> None:
        """The teacher's buttons: parameters or lesson step to every own copy, a study to
        every student."""
        if what == SEND_STUDY:
            self._send_study(teacher)
            return
        sim = self.shared.sim
        lesson = teacher.lesson.position() if teacher.lesson is not None else None
        setting = Setting(dict(sim.values), sim.integrator, sim.timestep, lesson)
        count = 0
        for cid, view in list(self._views.items()):
            if self.modes.get(cid) != "own":
                continue
            count += 1
            if what == SEND_VALUES:
                ctl = view.controller
                for name, value in setting.values.items():
                    ctl.submit(SetValue(name, value))
                ctl.submit(Integrator(setting.integrator))
                ctl.submit(Timestep(setting.timestep))
                ctl.submit(Reset())
            elif view.lesson is not None and setting.lesson is not None:
                view.lesson.go_to(*setting.lesson)
        message = (
            f"Réglages envoyés à {count} élève(s) en autonomie."
            if what == SEND_VALUES
            else f"Étape de leçon envoyée à {count} élève(s) en autonomie."
        )
        teacher.notify(Notice("info", "Classe", message))

    def _send_study(self, teacher: WebView) -> None:
        """The teacher's study (running or done) to every student: followers get it in a
        folder of their page, students on their own copy in their « Étude paramétrique »;
        students who arrive later get it too."""
        job = teacher.study.job if teacher.study is not None else None
        if job is None or (teacher.study is not None and teacher.study.received):
            teacher.notify(
                Notice(
                    "error",
                    "Classe",
                    "Lancez d'abord une étude dans « Étude paramétrique », puis envoyez-la.",
                )
            )
            return
        self.study = job
        count = 0
        for cid, follower in list(self._followers.items()):
            if self.modes.get(cid) == "follower":
                follower.receive_study(job)
                count += 1
        for cid, view in list(self._views.items()):
            if self.modes.get(cid) == "own" and view.study is not None:
                view.study.receive(job)
                count += 1
        teacher.notify(Notice("info", "Classe", f"Étude envoyée à {count} élève(s)."))

    def counts(self) -> tuple[int, int, int]:
        """(teachers, followers, students on their own copy) connected now."""
        modes = [self.modes.get(cid) for cid in list(self.sessions)]
        return modes.count("teacher"), modes.count("follower"), modes.count("own")

    def _disconnect(self, client: viser.ClientHandle) -> None:
        super()._disconnect(client)
        self._followers.pop(client.client_id, None)
        view = self._views.pop(client.client_id, None)
        if view is not None and view in self.broadcast.teachers:
            self.broadcast.teachers.remove(view)
        self.modes.pop(client.client_id, None)
        self.classroom.forget(client.client_id)

    def stop(self) -> None:
        self.classroom.stop()
        self.broadcast_session.stop()
        super().stop()


class _TeacherSession(Session):
    """The teacher's panels on the shared simulation (the broadcast steps it)."""

    def __init__(self, app: FollowApp, view: WebView, counts: viser.GuiMarkdownHandle) -> None:
        cid = view.client.client_id
        super().__init__(app.shared, view, alive=lambda: app.connected(cid), drive=False)
        self.app = app
        self.counts = counts
        self._shown = ""

    def run_once(self, now: float | None = None) -> None:
        super().run_once(now)
        teachers, followers, own = self.app.counts()
        text = counts_text(followers, own)
        if text != self._shown:
            self._shown = self.counts.content = text
