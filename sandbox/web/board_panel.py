"""The class board in the pages: the students' "Votre prénom" field, the teacher's folder
"La classe", and the per-process :class:`Classroom` that reads the students once a second.

Reading a student costs a few attribute reads: the lesson panel keeps the readouts of its
last refresh and its goal bars (:class:`~sandbox.web.lesson_panel.LessonPanel`), so the
board evaluates nothing and a session's frames are untouched. The rows go to a hub: in one
process, a :class:`LocalHub` merges them (a :class:`~sandbox.web.board.Roster`); with
``--workers N`` the worker's hub sends them to the parent, which merges every worker's
students and sends the board back to the workers serving a teacher's page
(:mod:`sandbox.web.workers`).

In the default mode (every browser its own simulation) the teacher's secret link
``/prof/<token>`` opens the teacher's own simulation plus "La classe"
(:class:`ClassApp`); in follow mode the teacher's page has it too
(:mod:`sandbox.web.follow`).
"""

from __future__ import annotations

import logging
import math
import secrets
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Protocol

import viser

from sandbox.challenges import Attempt, Challenge, for_scene, start
from sandbox.lessons import Progress
from sandbox.physics.simulation import Simulation
from sandbox.scenes.base import as_scene
from sandbox.web import network
from sandbox.web.app import App
from sandbox.web.board import (
    GOALS,
    REFRESH,
    SORT_LABEL,
    SORTS,
    Board,
    Roster,
    Row,
    Run,
    board_html,
    clean_name,
    csv_text,
    duration,
    from_wire,
    progress_of,
    sort_rows,
    summary,
    to_wire,
)
from sandbox.web.challenge_panel import ChallengePanel
from sandbox.web.fields import on_user, set_value
from sandbox.web.lesson_goal import parts
from sandbox.web.loop import Session
from sandbox.web.projector import key_readouts, overlay_lines

log = logging.getLogger(__name__)

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
"""Place of "Votre prénom" on a student's page: last, below every control (first, it
pushed the last parameters of a lesson step below a projected 1280×720 page)."""

ARRIVAL_GAP = 0.25
"""Seconds at least between two readings of the students: an arrival is reported at once
(not at the next second), a class arriving together in a few reports."""

BALANCING: dict[str, tuple[str, str]] = {
    "rotor": ("bearing_A", "bearing_B"),
    "wheel_balancer": ("bearing_inner", "bearing_outer"),
}
"""Scenes whose key readout on the board is the larger bearing force (what balancing
brings down), outside a lesson step that checks its own readouts."""

_GOAL_KEYS = {word: key for key, word in GOALS.items()}


def teacher_path(token: str) -> str:
    """Path of the teacher's link."""
    return f"{TEACHER_PREFIX}/{token}"


class Hub(Protocol):
    """Where a process's rows go: merged here, or sent to the parent process."""

    def publish(self, rows: list[dict[str, Any]], wants: bool) -> None:
        """This process's students now (wire dicts); ``wants``: a teacher's page here
        waits for the merged board."""

    def announce(self, run: Run) -> None:
        """A teacher here started or stopped a challenge (every process is told)."""


class LocalHub:
    """The hub of one process serving the whole class: merges and delivers at once.

    Args:
        start: When the class started (wall clock [s]).
        deliver: Called with the merged board.
        clock: Wall clock [s].
    """

    def __init__(
        self,
        start: float,
        deliver: Callable[[Board], None],
        *,
        clock: Callable[[], float] = time.time,
    ) -> None:
        self.roster = Roster(start)
        self.deliver = deliver
        self.clock = clock
        self.run: Run | None = None

    def publish(self, rows: list[dict[str, Any]], wants: bool) -> None:
        now = self.clock()
        checked = [r for r in (from_wire(d) for d in rows) if r is not None]
        self.roster.update("local", checked, now)
        if wants:
            self.deliver(replace(self.roster.board(now), run=self.run))

    def announce(self, run: Run) -> None:
        self.run = run
        self.deliver(replace(self.roster.board(self.clock()), run=run))


@dataclass(frozen=True)
class _Readouts:
    """How one scene's key readouts are written (computed once per student)."""

    names: tuple[str, ...]
    labels: Mapping[str, str]
    units: Mapping[str, str]
    zeros: Mapping[str, float]

    @classmethod
    def of(cls, sim: Simulation) -> _Readouts:
        infos = {i.name: i for i in sim.readout_infos()}
        short = key_readouts(sim)
        spec = as_scene(sim.scene)
        names = tuple(short)
        labels = {n: (short.get(n) or i.label or n) for n, i in infos.items()}
        units = {n: i.unit for n, i in infos.items()}
        zeros = {n: spec.zero_for(i.unit) for n, i in infos.items()} if spec else {}
        return cls(names, labels, units, zeros)

    def written(self, name: str, values: Mapping[str, float]) -> str:
        """The value as the page's overlay writes it ("54,4 N", "1 500 tr/min")."""
        label = self.labels.get(name, name)
        (line,) = overlay_lines([name], values, {name: label}, self.units, self.zeros)
        return line.removeprefix(f"{label} = ")


@dataclass
class _Student:
    client: viser.ClientHandle
    joined: float
    scene: str
    readouts: _Readouts
    view: object = None
    mode: str = "own"
    field: viser.GuiTextHandle | None = None
    name: str = ""
    sim: Simulation | None = None
    challenge: ChallengePanel | None = None
    attempt: Attempt | None = None  # kept across a follow-mode student's switches


def _read_lesson(view: object, row: Row) -> tuple[Row, str, Mapping[str, float]]:
    """``row`` with the lesson as the student's page shows it, the readout its step
    checks ("" when none) and the page's readouts (each attribute read once: the
    session's loop may change them meanwhile)."""
    panel = getattr(view, "lesson", None)
    if panel is None:
        return row, "", {}
    values: Mapping[str, float] = panel.values
    progress: Progress | None = panel.progress
    if progress is None:
        return row, "", values
    state, lines = panel.goal_state, panel.goal_lines
    goal = _GOAL_KEYS.get(state, "")
    done = [line.done for line in lines]
    checked = ""
    check = progress.step.check
    found = parts(check) if check is not None else None
    if found and len(found) == len(done):  # the part furthest from its goal
        ranked = [(d if d is not None else 2.0, k) for k, d in enumerate(done)]
        checked = found[min(ranked)[1]].readout
    row = replace(
        row,
        lesson=progress.lesson.name,
        lesson_title=progress.lesson.title,
        step=progress.index + 1,
        steps=len(progress.lesson.steps),
        goal=goal,
        progress=progress_of(done, goal) if goal else math.nan,
    )
    return row, checked, values


def key_readout(
    scene: str, names: tuple[str, ...], checked: str, values: Mapping[str, float]
) -> str:
    """The readout a student's row shows: the one their lesson step checks (the part
    furthest from its goal), else a balancing scene's larger bearing force, else the
    scene's first key readout ("" when none)."""
    if checked:
        return checked
    pair = BALANCING.get(scene)
    if pair is not None and all(n in values for n in pair):
        a, b = (values[n] for n in pair)
        return pair[1] if b > a else pair[0]
    return names[0] if names else ""


def student_row(key: str, student: _Student) -> Row:
    """One student's row from what their page last showed."""
    if student.field is not None:
        student.name = clean_name(student.field.value)
    base = Row(key=key, joined=student.joined, name=student.name, scene=student.scene)
    if student.mode == "follow":
        return replace(base, mode="follow")
    row, checked, values = _read_lesson(student.view, base)
    readouts = student.readouts
    given, tries, solved_s = student.challenge.state() if student.challenge else ("", 0, math.nan)
    name = key_readout(student.scene, readouts.names, checked, values)
    value = float(values.get(name, math.nan)) if name else math.nan
    return replace(
        row,
        readout=name,
        label=readouts.labels.get(name, name) if name else "",
        value=value,
        unit=readouts.units.get(name, "") if name else "",
        shown=readouts.written(name, values) if name and math.isfinite(value) else "",
        challenge=given,
        tries=tries,
        solved_s=solved_s,
    )


def name_field(gui: viser.GuiApi, name: str = "") -> viser.GuiTextHandle:
    """The student's "Votre prénom" box (read once a second; cleaned when read)."""
    return gui.add_text(
        NAME_LABEL,
        initial_value=name,
        hint="Le nom sous lequel l'enseignant vous voit dans la classe (40 caractères au plus)",
        order=NAME_ORDER,
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
            if self.summary.content != text:
                self.summary.content = text
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


class Classroom:
    """The students of this process and the teacher pages showing the board.

    Once every :data:`~sandbox.web.board.REFRESH` seconds a thread reads each student's
    row and publishes them to the hub; the merged board comes back through
    :meth:`receive` and goes to the teacher pages.

    Args:
        connected: Whether a browser is still connected (by client id).
        clock: Wall clock [s].
        period: Seconds between readings.
    """

    def __init__(
        self,
        connected: Callable[[int], bool],
        *,
        clock: Callable[[], float] = time.time,
        period: float = REFRESH,
    ) -> None:
        self.connected = connected
        self.clock = clock
        self.period = period
        self.start_time = clock()
        self.source = "p"
        self.hub: Hub = LocalHub(self.start_time, self.receive, clock=clock)
        self.board = Board(self.start_time)
        self.run: Run | None = None  # the class's challenge, as last heard
        self._students: dict[int, _Student] = {}
        self._teachers: dict[int, BoardPanel] = {}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._wake = threading.Event()  # a student arrived: report now
        self._thread: threading.Thread | None = None
        self._failed = False

    def relay(self, hub: Hub, source: str) -> None:
        """Send the rows to ``hub`` (another process merges them); ``source`` makes this
        process's row keys unique in the class."""
        self.hub, self.source = hub, source

    # -- who is here ---------------------------------------------------------------------
    def student(
        self,
        client: viser.ClientHandle,
        sim: Simulation,
        view: object = None,
        *,
        mode: str = "own",
        field: viser.GuiTextHandle | None = None,
    ) -> None:
        """A student's page (new, or rebuilt when they switch mode in follow mode: their
        name and arrival are kept)."""
        cid = client.client_id
        with self._lock:
            old = self._students.get(cid)
        panel = getattr(view, "challenge", None)
        if old is not None:
            if old.field is not None:
                old.name = clean_name(old.field.value)
            old.view, old.mode, old.field = view, mode, field
            old.sim = sim
            old.challenge = panel if isinstance(panel, ChallengePanel) else None
            entry = old
        else:
            scene = sim.scene.name if sim.scene is not None else Path(str(sim.label)).stem
            entry = _Student(client, self.clock(), scene[:80], _Readouts.of(sim), view, mode, field)
            entry.sim = sim
            entry.challenge = panel if isinstance(panel, ChallengePanel) else None
            with self._lock:
                self._students[cid] = entry
        with self._lock:
            run = self.run
        self._wake.set()  # on the board within a fraction of a second, not the next one
        if run is not None:  # a challenge runs: this student gets one too (the same one
            self._give(entry, run)  # when they come back to their own simulation)

    def name_of(self, client_id: int) -> str:
        """The name a student typed so far ("" when none)."""
        with self._lock:
            entry = self._students.get(client_id)
        if entry is None:
            return ""
        return clean_name(entry.field.value) if entry.field is not None else entry.name

    def teacher(
        self,
        client: viser.ClientHandle,
        *,
        folder: viser.GuiFolderHandle | None = None,
        scene: str = "",
        followed: bool = False,
    ) -> BoardPanel:
        """Add the board to a teacher's page (with the challenges of ``scene``, whose
        students each have their own simulation)."""
        panel = BoardPanel(
            client,
            folder=folder,
            challenges=for_scene(scene),
            announce=self.announce,
            followed=followed,
        )
        panel.show(self.board)
        with self._lock:
            self._teachers[client.client_id] = panel
        return panel

    def forget(self, client_id: int) -> None:
        """A browser left."""
        with self._lock:
            self._students.pop(client_id, None)
            self._teachers.pop(client_id, None)

    def students(self) -> int:
        """Student pages of this process."""
        with self._lock:
            return len(self._students)

    # -- once a second ---------------------------------------------------------------------
    def rows(self) -> list[Row]:
        """This process's students now (those whose browser left are forgotten)."""
        with self._lock:
            entries = list(self._students.items())
        out = []
        for cid, entry in entries:
            if not self.connected(cid):
                self.forget(cid)
                continue
            out.append(student_row(f"{self.source}:{cid}", entry))
        return out

    def tick(self) -> None:
        """Read the students and publish them (never raises: the board is not worth a
        session)."""
        try:
            with self._lock:
                wants = bool(self._teachers)
            self.hub.publish([to_wire(r) for r in self.rows()], wants)
        except Exception:
            if not self._failed:  # once: the next ticks would say the same
                self._failed = True
                log.exception("the class board could not be read")

    # -- challenges ------------------------------------------------------------------------
    def announce(self, run: Run) -> None:
        """A teacher's page started or stopped a challenge: to the class's hub (every
        process hears it back through :meth:`receive`)."""
        try:
            self.hub.announce(run)
        except Exception:
            log.exception("the challenge could not be announced")

    def _give(self, student: _Student, run: Run) -> None:
        """``run`` for one student: their own secret when it starts (or when they arrive
        while it runs), the solution when it ends; nothing for another scene's."""
        panel, sim = student.challenge, student.sim
        if panel is None or sim is None or student.mode != "own":
            return
        if run.name not in {c.name for c in for_scene(student.scene)}:
            return
        attempt = panel.attempt
        try:
            if not run.ended and (attempt is None or attempt.run != run.id):
                kept = student.attempt
                if kept is None or kept.run != run.id:
                    with sim.lock:
                        values = dict(sim.values)
                    kept = student.attempt = start(run.name, run.id, values, self.clock())
                panel.begin(kept)
            elif run.ended and attempt is not None and attempt.run == run.id and not panel.ended:
                panel.end()
        except Exception:
            log.exception("a student's challenge could not be changed")

    def receive(self, board: Board) -> None:
        """The merged board: to every teacher page of this process; a challenge started
        or stopped, to every student."""
        self.board = board
        if board.run is not None and board.run != self.run:
            with self._lock:
                self.run = board.run
                students = list(self._students.values())
            for student in students:
                self._give(student, board.run)
        with self._lock:
            panels = list(self._teachers.values())
        for panel in panels:
            try:
                panel.show(board)
            except Exception:
                log.debug("a teacher's page is gone", exc_info=True)

    def start(self) -> None:
        """Read the students every :attr:`period` seconds in a thread of its own."""

        def run() -> None:
            last = -math.inf
            while not self._stop.is_set():
                self._wake.wait(self.period)  # a second, or at once for an arrival
                gap = ARRIVAL_GAP - (time.monotonic() - last)
                if gap > 0 and self._stop.wait(gap):  # a crowd arriving: one report
                    return
                if self._stop.is_set():
                    return
                self._wake.clear()
                last = time.monotonic()
                self.tick()

        self._thread = threading.Thread(target=run, name="sandbox-board", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop reading."""
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(2.0)


class ClassApp(App):
    """The default mode with a teacher: every browser its own simulation (made by
    ``factory``); the secret link ``/prof/<token>`` adds "La classe" to the teacher's own,
    every other page gets "Votre prénom" and a row on the board.

    Args:
        server: The viser server.
        host: Interface listened on.
        factory: A browser's session (its view a :class:`~sandbox.web.view.WebView`).
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
                self.classroom.student(client, sim, session.view, field=box)
        except Exception:
            log.exception("the class board could not take this browser")
        return session

    def _disconnect(self, client: viser.ClientHandle) -> None:
        super()._disconnect(client)
        self.classroom.forget(client.client_id)

    def stop(self) -> None:
        self.classroom.stop()
        super().stop()
