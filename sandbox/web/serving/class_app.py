"""The default mode with a teacher (:class:`ClassApp`): every browser its own
simulation; the teacher's secret link ``/prof/<token>`` opens the teacher's own
simulation plus "La classe"; every other page gets "Votre prénom" and a row on the
board. In follow mode the teacher's page has it too (:mod:`sandbox.web.serving.follow`).
"""

from __future__ import annotations

import logging
import secrets
from collections.abc import Callable

import viser

from sandbox.web.loop import Session
from sandbox.web.panels.board import name_field, teacher_path
from sandbox.web.serving import network
from sandbox.web.serving.class_board import Classroom
from sandbox.web.serving.server import App
from sandbox.web.views.browser import WebView

log = logging.getLogger(__name__)


class ClassApp(App):
    """The default mode with a teacher: every browser its own simulation (made by
    ``factory``); the secret link ``/prof/<token>`` adds "La classe" to the teacher's own,
    every other page gets "Votre prénom" and a row on the board.

    Args:
        server: The viser server.
        host: Interface listened on.
        factory: A browser's session (its view a :class:`~sandbox.web.views.browser.WebView`).
        token: Secret of the teacher's link (random when None).
        max_sessions: Browsers served at once by this process.
        port: The port students reach (the workers' shared one).
    """

    def __init__(
        self,
        server: viser.ViserServer,
        host: str,
        factory: Callable[[viser.ClientHandle], Session],
        *,
        token: str | None = None,
        max_sessions: int,
        port: int | None = None,
    ) -> None:
        self.build = factory
        self.token = token or secrets.token_urlsafe(9)
        network.page_alias(teacher_path(self.token))
        self.classroom = Classroom(lambda cid: self.connected(cid))
        super().__init__(server, host, self._open, max_sessions=max_sessions, port=port)
        self.classroom.start()

    @property
    def teacher_url(self) -> str:
        """The teacher's link (on this machine)."""
        return self.url + teacher_path(self.token)

    def _open(self, client: viser.ClientHandle) -> Session:
        session = self.build(client)
        try:  # the board is not worth a session: a failure here is only logged
            if network.request_path(self.server, client.client_id) == teacher_path(self.token):
                scene = session.controller.sim.scene
                self.classroom.teacher(client, scene=scene.name if scene is not None else "")
            else:
                box = name_field(client.gui)
                sim = session.controller.sim
                view = session.view if isinstance(session.view, WebView) else None
                self.classroom.student(client, sim, view, field=box)
        except Exception:
            log.exception("the class board could not take this browser")
        return session

    def _disconnect(self, client: viser.ClientHandle) -> None:
        super()._disconnect(client)
        self.classroom.forget(client.client_id)

    def stop(self) -> None:
        self.classroom.stop()
        super().stop()
