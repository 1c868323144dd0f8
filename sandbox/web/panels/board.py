"""The class board in the pages: the students' "Votre prénom" field and the teacher's
folder "La classe" (:class:`BoardPanel`: a summary line, the challenges, "Trier par", the
CSV download and the table).

The teacher's secret link is ``/prof/<token>`` (:func:`teacher_path`); the per-process
:class:`~sandbox.web.serving.class_board.Classroom` reads the students once a second and shows
the merged board in every teacher's folder.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import replace

import viser

from sandbox.challenges import Challenge
from sandbox.web.client.fields import on_user, set_value
from sandbox.web.panels.board_rows import Board, Run
from sandbox.web.panels.board_table import (
    SORT_LABEL,
    SORTS,
    board_html,
    capacity_words,
    csv_text,
    duration,
    sort_rows,
    summary,
)

TEACHER_PREFIX = "/prof"
"""First segment of the teacher's secret link."""

BOARD_FOLDER = "La classe"
NAME_LABEL = "Votre prénom"
CSV_BUTTON = "Télécharger le tableau (CSV)"
CHALLENGE_LABEL = "Défi"
START_BUTTON = "Lancer le défi"
STOP_BUTTON = "Arrêter et montrer les solutions"
WAITING = "En attente des élèves…"
BOARD_ORDER = -900.0
"""Place of "La classe" on the teacher's page: first (the page's style elements are at
-1000)."""
NAME_ORDER = 900.0
"""Place of "Votre prénom" on a student's page once their browser knows their name: last,
below every control (first, it pushed the last parameters of a lesson step below a
1280×720 page)."""
NAME_FIRST_ORDER = -950.0
"""Place of "Votre prénom" on the page of a student whose name is not known yet: first,
asked on arrival."""


def teacher_path(token: str) -> str:
    """Path of the teacher's link."""
    return f"{TEACHER_PREFIX}/{token}"


def name_field(gui: viser.GuiApi, name: str = "") -> viser.GuiTextHandle:
    """The student's "Votre prénom" box (read once a second; cleaned when read): first on
    the page while no name is known, last once it is."""
    return gui.add_text(
        NAME_LABEL,
        initial_value=name,
        hint="Le nom sous lequel l'enseignant vous voit dans la classe (40 caractères au "
        "plus) ; ce navigateur le retient",
        order=NAME_ORDER if name else NAME_FIRST_ORDER,
    )


class BoardPanel:
    """The folder "La classe" of one teacher's page: a summary line, the challenges of
    the scene ("Défi", "Lancer le défi", "Arrêter et montrer les solutions"), "Trier
    par", the CSV download and the table.

    Args:
        client: The teacher's browser.
        folder: The folder to fill (default: a new "La classe", first on the page).
        challenges: The challenges the teacher may start (none: no "Défi").
        announce: Where a started or stopped challenge goes (the class's hub).
        followed: The students follow the teacher's simulation (``--follow``): only those
            who chose a simulation of their own get a challenge.
    """

    def __init__(
        self,
        client: viser.ClientHandle,
        *,
        folder: viser.GuiFolderHandle | None = None,
        challenges: Sequence[Challenge] = (),
        announce: Callable[[Run], None] | None = None,
        followed: bool = False,
    ) -> None:
        gui = client.gui
        self.followed = followed
        self.client = client
        self.folder = folder or gui.add_folder(BOARD_FOLDER, order=BOARD_ORDER)
        self.challenges = {c.title: c for c in challenges}
        self.announce = announce
        self.run: Run | None = None
        self.challenge: viser.GuiDropdownHandle[str] | None = None
        with self.folder:
            self.summary = gui.add_markdown(WAITING)
            self.capacity = gui.add_markdown("")
            if self.challenges and announce is not None:
                titles = tuple(self.challenges)
                self.challenge = gui.add_dropdown(
                    CHALLENGE_LABEL,
                    titles,
                    initial_value=titles[0],
                    hint="Chaque élève reçoit sa propre machine mystère, tirée au hasard ; "
                    "sa page ne montre ni le défaut caché ni les grandeurs qui le trahiraient",
                )
                self.run_button = gui.add_button(START_BUTTON)
                self.run_state = gui.add_markdown("")
                self.run_button.on_click(lambda _: self._start_or_stop())
            self.sort = gui.add_dropdown(
                SORT_LABEL,
                tuple(SORTS),
                initial_value=next(iter(SORTS)),
                hint="Arrivée : dans l'ordre où les élèves ont ouvert la page ; Étape et "
                "Progression : les plus en retard d'abord ; Défi : les plus rapides "
                "d'abord ; les élèves partis en dernier",
            )
            self.download = gui.add_button(
                CSV_BUTTON,
                hint="Le tableau de la classe dans un fichier pour un tableur",
            )
            self.table = gui.add_html(board_html(()))
        self.by = SORTS[next(iter(SORTS))]
        self.board: Board | None = None
        self._lock = threading.Lock()
        on_user(self.sort, self._choose)
        self.download.on_click(lambda _: self._download())

    def _start_or_stop(self) -> None:
        """The teacher's button: start the chosen challenge, or stop the one running."""
        if self.announce is None or self.challenge is None:
            return
        run = self.run
        if run is not None and not run.ended:
            self.announce(replace(run, ended=time.time()))
            return
        chosen = self.challenges.get(str(self.challenge.value))
        if chosen is None:  # a crafted option
            set_value(self.challenge, next(iter(self.challenges)))
            return
        self.announce(Run(secrets.token_urlsafe(8), chosen.name, time.time()))

    def _show_run(self, run: Run | None) -> None:
        if self.challenge is None:
            return
        self.run = run
        running = run is not None and not run.ended
        label = STOP_BUTTON if running else START_BUTTON
        if self.run_button.label != label:
            self.run_button.label = label
            self.run_button.color = "red" if running else None
        self.challenge.disabled = running
        title = next((t for t, c in self.challenges.items() if run and c.name == run.name), "")
        if run is None:
            text = ""
        elif running:
            text = f"Défi en cours depuis {duration(time.time() - run.started)} : {title}"
            if self.followed:
                text += " (seuls les élèves passés sur « Ma simulation » le reçoivent)"
        else:
            text = f"Défi terminé : les élèves voient la solution de leur machine ({title})."
        if self.run_state.content != text:
            self.run_state.content = text

    def _choose(self, option: object) -> None:
        by = SORTS.get(option) if isinstance(option, str) else None
        if by is None:  # a crafted option: put the choice back
            set_value(self.sort, next(k for k, v in SORTS.items() if v == self.by))
            return
        self.by = by
        if self.board is not None:
            self.show(self.board)

    def show(self, board: Board) -> None:
        """Show ``board`` (sorted by the teacher's choice); sends only what changed."""
        with self._lock:
            self.board = board
            self._show_run(board.run)
            rows = sort_rows(board.rows, self.by)
            text = summary(rows, board.left_out)
            html = board_html(rows)
            load = capacity_words(board.load)
            if self.summary.content != text:
                self.summary.content = text
            if self.capacity.content != load:
                self.capacity.content = load
            if self.table.content != html:
                self.table.content = html

    def csv(self) -> str:
        """The board as the teacher sees it (sorted the same), in CSV."""
        board = self.board
        if board is None:
            return csv_text((), time.time())
        return csv_text(sort_rows(board.rows, self.by), board.start)

    def _download(self) -> None:
        stamp = time.strftime("%Y-%m-%d-%Hh%M")
        self.client.send_file_download(
            f"classe-{stamp}.csv", self.csv().encode("utf-8"), save_immediately=True
        )
