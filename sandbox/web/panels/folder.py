"""The folders of « Panneau affiché », as a list: each panel declares its folders (title,
whether a challenge keeps it, the readouts it needs from a frame, its refresh), and the
view iterates the list to build the picker, to close folders during a challenge, to ask
a frame for readouts and to refresh what is shown. A new panel adds its folders here and
nowhere else.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import viser

    from sandbox.web.loop.frame import Frame


def _nothing() -> Collection[str]:
    return ()


@dataclass(frozen=True)
class Folder:
    """One folder a browser may pick in « Panneau affiché ».

    Attributes:
        title: The folder's title (what the picker lists).
        handle: Its viser folder (shown only while picked).
        refresh: Rewrites it from a frame while it is shown, at the panels' rate (None:
            it never changes, or another part of the view fills it).
        names: The readouts it needs from a frame while shown.
        secret_safe: A challenge keeps it open: it shows only the frame's readouts (the
            withheld ones removed), never the simulation itself.
        needs_readouts: Refreshed only by frames that bring readouts (False: also while
            the simulation diverged, e.g. the hypotheses or the polar diagram).
        watch: Told at every tick whether the folder is shown (a panel that samples
            between refreshes, like the X–Y plot, samples only then).
    """

    title: str
    handle: viser.GuiFolderHandle
    refresh: Callable[[Frame], None] | None = None
    names: Callable[[], Collection[str]] = field(default=_nothing)
    secret_safe: bool = False
    needs_readouts: bool = True
    watch: Callable[[bool], None] | None = None


def kept_during_challenge(folders: Sequence[Folder], *also: str) -> tuple[str, ...]:
    """Titles a challenge keeps open: the secret-safe folders and ``also``."""
    return tuple(f.title for f in folders if f.secret_safe or f.title in also)
