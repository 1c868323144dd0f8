"""The page of a browser's own simulation, built the same way in every mode: a class
(``sandbox serve``) and a student who leaves the teacher's simulation in follow mode
(``--follow``) get the same panels, « Partager » (a link to this setup, at the address
the students use) and « Rejoindre » (the address students type).
"""

from __future__ import annotations

from collections.abc import Sequence

import viser

from sandbox.web.loop import Controller
from sandbox.web.views import share as share_panel
from sandbox.web.views.browser import WebView


def own_view(
    server: viser.ViserServer,
    client: viser.ClientHandle,
    controller: Controller,
    *,
    lesson: str | None = None,
    join_urls: Sequence[str] = (),
) -> WebView[Controller]:
    """Every panel of ``controller``'s simulation for ``client``, with « Partager » (the
    link the page was opened with applied) and « Rejoindre » when ``join_urls`` is given.

    Args:
        server: The viser server (the websocket's handshake carries the page's link).
        client: The browser.
        controller: Its own simulation's controller.
        lesson: The lesson the page opens by itself.
        join_urls: Addresses students type to join.
    """
    view = WebView(client, controller, lesson=lesson, join_urls=join_urls)
    share_panel.attach(server, client, view, lesson=lesson)
    return view
