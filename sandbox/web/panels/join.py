"""Folder "Rejoindre": the address students type and its QR code, readable on a projector."""

from __future__ import annotations

import html
from collections.abc import Sequence
from typing import TYPE_CHECKING

import segno

from sandbox.web.panels.folder import Folder

if TYPE_CHECKING:
    import viser


def qr_svg(url: str, *, scale: int = 6) -> str:
    """An inline SVG QR code of ``url`` (black on white, quiet zone included)."""
    code = segno.make(url, error="m")
    return str(code.svg_inline(scale=scale, border=3, light="#fff"))


def join_html(urls: Sequence[str], *, qr: bool = True) -> str:
    """The panel's HTML: the first address large, its QR code, then the other addresses.

    Every address is escaped: it is shown as text, never interpreted.
    """
    if not urls:
        return (
            "<p style='font-size:1.1em'>Aucune adresse réseau : cette machine n'est reliée "
            "à aucun réseau local. Relancez le serveur avec <code>--host 0.0.0.0</code> "
            "une fois connecté.</p>"
        )
    first = html.escape(urls[0])
    parts = [
        "<p style='margin:0 0 4px 0'>Sur votre ordinateur, votre tablette ou votre "
        "téléphone, ouvrez :</p>",
        f"<p style='font-size:1.6em;font-weight:700;margin:0 0 8px 0;word-break:break-all'>"
        f"{first}</p>",
    ]
    if qr:
        parts.append(
            "<div style='display:flex;justify-content:center' "
            "title='Code QR de l’adresse : visez-le avec l’appareil photo'>"
            f"{qr_svg(urls[0])}</div>"
        )
    if len(urls) > 1:
        others = "<br>".join(html.escape(u) for u in urls[1:])
        parts.append(f"<p style='margin:8px 0 0 0'>Autres adresses de ce serveur :<br>{others}</p>")
    return "".join(parts)


FOLDER = "Rejoindre"


class JoinPanel:
    """Folder "Rejoindre" (shown only when the server is reachable from other machines).

    Args:
        gui: A viser GUI API (a client's).
        urls: Addresses students can type, the preferred one first.
        expand: Open the folder (it shows once picked in "Panneau affiché").
    """

    def __init__(self, gui: viser.GuiApi, urls: Sequence[str], *, expand: bool = True) -> None:
        with gui.add_folder(FOLDER, expand_by_default=expand) as self.folder:
            self.html = gui.add_html(join_html(urls))

    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché » (the addresses never change)."""
        return [Folder(FOLDER, self.folder)]
