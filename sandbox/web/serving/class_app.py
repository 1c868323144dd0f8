"""The default mode with a teacher (:class:`ClassApp`): every browser its own
simulation; the teacher's secret link ``/prof/<token>`` opens the teacher's own
simulation plus "La classe"; every other page gets "Votre prénom" and a row on the
board. In follow mode the teacher's page has it too (:mod:`sandbox.web.serving.follow`).

When the process is saturated (its frame rate at the governor's floor and still too
costly, :mod:`sandbox.web.loop.governor`), a student who arrives follows the teacher's
simulation instead, drawn once into the broadcast scene for every such student (the
follow mode's view, which costs nothing per student): the teacher's own when the
teacher's page is served by this process, else one shared copy at the class's settings.

A class arrives together: thirty students open the page within seconds, before the
governor's windows can tell that the process is saturated. So the students who arrived
last (within :data:`SHED_RECENT` seconds, and not recording) are moved to the projected
simulation too, as many as the frames the process gave short of the floor say, until it
is no longer saturated (:meth:`ClassApp.shed`); each reads why.
"""

from __future__ import annotations

import functools
import logging
import math
import secrets
import threading
import time
from collections.abc import Callable

import viser

from sandbox.web.loop import Controller, Session
from sandbox.web.loop.scheduler import Scheduler
from sandbox.web.page.link import arrival
from sandbox.web.panels.board import teacher_path
from sandbox.web.panels.join import FOLDER as JOIN_FOLDER
from sandbox.web.serving import network
from sandbox.web.serving.class_board import Classroom
from sandbox.web.serving.follow import FOLLOWER_FPS, SHARED, BroadcastView, FollowerView
from sandbox.web.serving.own_page import OwnPage
from sandbox.web.serving.server import App
from sandbox.web.view3d.camera import point_camera
from sandbox.web.views.browser import WebView

log = logging.getLogger(__name__)

SATURATED_INTRO = (
    "Le portable du professeur est saturé : vous suivez la simulation qu'il projette, "
    "sans réglages personnels. « Ma simulation » vous en donnera une dès qu'il aura de "
    "la place."
)
"""What a student who arrives while the process is saturated reads first."""

STILL_SATURATED = (
    "Le portable du professeur est encore saturé : restez sur la simulation projetée pour "
    "l'instant, puis réessayez."
)


SHED_RECENT = 60.0
"""Seconds after their arrival during which a student counts as newly connected: moved
to the projected simulation when the process saturates (the class that just arrived
together), never one who has worked on their own simulation for longer."""

SHED_PAUSE = 3.0
"""Seconds between two moves of students to the projected simulation: the governor's
windows (:data:`~sandbox.web.loop.governor.WINDOW`) see the lighter load first."""

SHED_CHECK = 0.5
"""Seconds between two looks at the governor's saturation."""

SHED_MIN = 6
"""Students with a simulation of their own below which nobody is moved: a class arriving
together, not two browsers on a machine busy with something else for a while."""


JOIN_FIRST_ORDER = -950.0
"""Place of « Rejoindre » on the teacher's page until the first student arrives: first,
above « La classe » (the readout folders are below the controls)."""


def _join_until_students(view: WebView) -> Callable[[], None] | None:
    """The teacher's page shows « Rejoindre » (the address and its QR code) until the
    first students arrive, then its usual panel, unless the teacher picked another one
    meanwhile. None when the students cannot reach this server (no « Rejoindre »)."""
    join = view.join
    if join is None:
        return None
    view.show_folder(JOIN_FOLDER)
    place = join.folder.order
    join.folder.order = JOIN_FIRST_ORDER  # first on the page, above « La classe »

    def arrived() -> None:
        join.folder.order = place
        if view.picker.value == JOIN_FOLDER:  # the teacher has not picked another
            view.show_folder(view.default_folder)

    return arrived


class ClassApp(App):
    """The default mode with a teacher: every browser its own simulation (made by
    ``factory``); the secret link ``/prof/<token>`` adds "La classe" to the teacher's own,
    every other page gets "Votre prénom" and a row on the board.

    Args:
        server: The viser server.
        host: Interface listened on.
        factory: A browser's own page (its session, view and live controller).
        token: Secret of the teacher's link (random when None).
        max_sessions: Browsers served at once by this process.
        port: The port students reach (the workers' shared one).
        shared: Makes the class's shared simulation (at the server's settings) that the
            students arriving on a saturated process follow when the teacher's page is
            not served here (None: they always get their own).
        scheduler: The loop whose governor says when the process is saturated.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        host: str,
        factory: Callable[[viser.ClientHandle], OwnPage],
        *,
        token: str | None = None,
        max_sessions: int,
        port: int | None = None,
        shared: Callable[[], Controller] | None = None,
        scheduler: Scheduler | None = None,
    ) -> None:
        self.build = factory
        self.shared = shared
        self.scheduler = scheduler or Scheduler.shared()
        self.token = token or secrets.token_urlsafe(9)
        network.page_alias(teacher_path(self.token))
        self.classroom = Classroom(lambda cid: self.connected(cid))
        self.broadcast: BroadcastView | None = None
        self._broadcast_session: Session | None = None
        self._broadcasting = threading.Lock()  # browsers arriving together make one
        self._teacher: tuple[int, Controller] | None = None  # the teacher's page here
        self.overflow: set[int] = set()  # students following because of saturation
        self.arrived: dict[int, float] = {}  # own students' arrival (monotonic clock)
        self.shed_count = 0  # students moved to the projected simulation so far
        self._shed_after = 0.0
        self._shedding = threading.Event()
        super().__init__(server, host, self._open, max_sessions=max_sessions, port=port)
        self.classroom.start()
        self._shedder: threading.Thread | None = None
        if self.shared is not None:
            self._shedder = threading.Thread(target=self._shed_loop, name="shed", daemon=True)
            self._shedder.start()

    @property
    def teacher_url(self) -> str:
        """The teacher's link (on this machine)."""
        return self.url + teacher_path(self.token)

    def _open(self, client: viser.ClientHandle) -> Session:
        teacher = network.request_path(self.server, client.client_id) == teacher_path(self.token)
        if not teacher and self.shared is not None and self.scheduler.governor.saturated:
            try:
                return self._follower(client)
            except Exception:  # a simulation of their own, then: never no page at all
                log.exception("a student could not follow the projected simulation")
                client.gui.reset()
                client.scene.reset()
        page = self.build(client)
        session = page.session
        self._hide_broadcast(client)
        try:  # the board is not worth a session: a failure here is only logged
            if teacher:
                scene = page.controller.sim.scene
                self.classroom.teacher(
                    client,
                    scene=scene.name if scene is not None else "",
                    arrived=_join_until_students(page.view),
                )
                self._teacher = (client.client_id, page.controller)
            else:
                who = functools.partial(arrival, self.server, client.client_id)
                self.classroom.seat(client, page.controller.sim, page.view, who=who)
                self.arrived[client.client_id] = time.monotonic()
        except Exception:
            log.exception("the class board could not take this browser")
        return session

    # -- a class arriving together on a process it saturates -----------------------------
    def _shed_loop(self) -> None:
        while not self._shedding.wait(SHED_CHECK):
            try:
                self.shed()
            except Exception:  # the class goes on as it is
                log.exception("students could not be moved to the projected simulation")

    def shed(self, now: float | None = None) -> int:
        """While the process is saturated with :data:`SHED_MIN` students or more, move
        the students who arrived last (within :data:`SHED_RECENT` s, not recording) to
        the projected simulation: as many as
        the frames each session got short of the floor say (at least one), then wait
        :data:`SHED_PAUSE` s for the governor to see the lighter load. Returns how many
        were moved."""
        governor = self.scheduler.governor
        students = len(self.arrived) + len(self.overflow)  # own, and following
        if self.shared is None or not governor.saturated or students < SHED_MIN:
            return 0
        now = time.monotonic() if now is None else now
        if now < self._shed_after:
            return 0
        recent = sorted(
            (at, cid) for cid, at in list(self.arrived.items()) if now - at <= SHED_RECENT
        )
        if not recent:
            return 0
        given = float(getattr(governor, "given", 0.0))
        floor = float(getattr(governor, "floor", 15.0))
        short = 1.0 - given / floor if 0.0 < given < floor else 0.0
        count = max(1, math.ceil(len(self.arrived) * short))
        moved = 0
        for _, cid in reversed(recent):  # the last to arrive first
            if moved >= count:
                break
            moved += self._to_projected(cid)
        self._shed_after = now + SHED_PAUSE
        self.shed_count += moved
        if moved:
            log.info("saturated: %d newly arrived student(s) now follow the projection", moved)
        return moved

    def _to_projected(self, cid: int) -> bool:
        """One student's own simulation replaced by the projected one (False: gone, or
        recording: a recording is never cut short)."""
        with self._lock:
            old = self.sessions.get(cid)
            if old is None or getattr(old.controller, "recorder", None) is not None:
                return False
            del self.sessions[cid]
        self.arrived.pop(cid, None)
        client = self.server.get_clients().get(cid)
        if client is None:
            old.stop()
            return False
        # never no page at all: a simulation of their own again if the move fails
        self._swap(client, old, self._follower, self._open)
        return True

    def _swap(
        self,
        client: viser.ClientHandle,
        old: Session,
        make: Callable[[viser.ClientHandle], Session],
        fallback: Callable[[viser.ClientHandle], Session],
    ) -> None:
        """Replace a page's session ``old`` (already out of :attr:`sessions`) by the one
        ``make`` builds on a cleared page, or ``fallback``'s when ``make`` fails."""
        old.stop()
        client.gui.reset()
        client.scene.reset()
        try:
            session = make(client)
        except Exception:
            log.exception("a page's new session could not be made")
            client.gui.reset()
            client.scene.reset()
            session = fallback(client)
        with self._lock:
            self.sessions[client.client_id] = session
        session.start()

    @staticmethod
    def _hide_broadcast(client: viser.ClientHandle) -> None:
        """A page with a simulation of its own never shows the projected one (drawn for
        the students who follow it, should the process saturate): a node of this page
        named like its folder hides it here only."""
        client.scene.add_frame(SHARED, show_axes=False, visible=False)

    # -- the students who arrive on a saturated process ----------------------------------
    def _projected(self) -> BroadcastView:
        """The broadcast the saturated process's new students follow (made once): the
        teacher's simulation when their page is here, else the class's shared copy.

        Browsers connect on threads of their own: made under a lock, or two arriving
        together made two, the second's nodes replacing the first's (same names) while
        the first still drew them ("Cannot assign to 'visible' on a removed handle")."""
        with self._broadcasting:
            return self._projected_locked()

    def _projected_locked(self) -> BroadcastView:
        if self.broadcast is None:
            teacher = self._teacher
            if teacher is not None and self.connected(teacher[0]):
                controller, drive = teacher[1], False  # the teacher's page steps it
            else:
                assert self.shared is not None
                controller, drive = self.shared(), True
            self.broadcast = BroadcastView(self.server, controller)
            self._broadcast_session = Session(controller, self.broadcast, drive=drive)
            self._broadcast_session.start()
        return self.broadcast

    def _follower(self, client: viser.ClientHandle) -> Session:
        cid = client.client_id
        broadcast = self._projected()
        point_camera(client, broadcast.controller.sim)
        view = FollowerView(client, broadcast, lambda: self._own(client), intro=SATURATED_INTRO)
        who = functools.partial(arrival, self.server, cid)
        self.classroom.seat(client, broadcast.controller.sim, mode="follow", who=who)
        self.overflow.add(cid)
        return Session(
            broadcast.controller, view, fps=FOLLOWER_FPS, alive=lambda: self.connected(cid),
            drive=False,
        )  # fmt: skip

    def _own(self, client: viser.ClientHandle) -> None:
        """A following student asks for a simulation of their own: given once the
        process is no longer saturated, else a French line says to wait."""
        cid = client.client_id
        if self.scheduler.governor.saturated:
            client.add_notification("Classe", STILL_SATURATED, auto_close_seconds=8.0)
            return
        with self._lock:
            old = self.sessions.pop(cid, None)
        if old is None:
            return
        self.overflow.discard(cid)
        self._swap(client, old, self._open, self._follower)

    def _disconnect(self, client: viser.ClientHandle) -> None:
        super()._disconnect(client)
        self.classroom.forget(client.client_id)
        self.overflow.discard(client.client_id)
        self.arrived.pop(client.client_id, None)
        teacher = self._teacher
        if teacher is not None and teacher[0] == client.client_id:
            self._teacher = None
            session = self._broadcast_session
            if session is not None and session.controller is teacher[1]:
                session.drive = True  # nobody steps the teacher's simulation now: this one

    def stop(self) -> None:
        self._shedding.set()
        if self._shedder is not None:
            self._shedder.join(2.0)
        self.classroom.stop()
        if self._broadcast_session is not None:
            self._broadcast_session.stop()
        super().stop()
