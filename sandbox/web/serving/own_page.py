"""The page of a browser's own simulation, built the same way in every mode: a class
(``sandbox serve``) and a student who leaves the teacher's simulation in follow mode
(``--follow``) get the same panels, « Partager » (a link to this setup, at the address
the students use) and « Rejoindre » (the address students type).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import viser

from sandbox.web.loop import Controller, Session
from sandbox.web.views import share as share_panel
from sandbox.web.views.browser import WebView


@dataclass(frozen=True)
class OwnPage:
    """One browser's own simulation.

    Attributes:
        session: What the loop runs for it.
        view: Its page.
        controller: Its live simulation.
    """

    session: Session
    view: WebView
    controller: Controller


def own_page(
    server: viser.ViserServer,
    client: viser.ClientHandle,
    controller: Controller,
    *,
    lesson: str | None = None,
    join_urls: Sequence[str] = (),
    alive: Callable[[], bool] | None = None,
) -> OwnPage:
    """Every panel of ``controller``'s simulation for ``client``, with « Partager » (the
    link the page was opened with applied) and « Rejoindre » when ``join_urls`` is given.

    Args:
        server: The viser server (the websocket's handshake carries the page's link).
        client: The browser.
        controller: Its own simulation's controller.
        lesson: The lesson the page opens by itself.
        join_urls: Addresses students type to join.
        alive: False once the page is gone (default: the server's connection).
    """
    view = WebView(client, controller, live=controller, lesson=lesson, join_urls=join_urls)
    share_panel.attach(server, client, view, lesson=lesson, join_urls=join_urls)
    return OwnPage(Session(controller, view, alive=alive), view, controller)
