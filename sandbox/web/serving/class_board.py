"""The class board of one server process: its students, read once a second, and the
teacher pages showing the merged board (:class:`Classroom`).

The rows go to a hub: in one process, a :class:`LocalHub` merges them (a
:class:`~sandbox.web.serving.roster.Roster`); with ``--workers N`` the worker's hub sends them to
the parent, which merges every worker's students and sends the board back to the workers
serving a teacher's page (:mod:`sandbox.web.serving.workers`). A challenge a teacher starts or
stops goes the same way to every student.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any, Protocol

import viser

from sandbox.challenges import for_scene, start
from sandbox.physics.simulation import Simulation
from sandbox.web.client.fields import set_value
from sandbox.web.loop.capacity import Load
from sandbox.web.loop.scheduler import Scheduler
from sandbox.web.panels.board import NAME_ORDER, BoardPanel, name_field
from sandbox.web.panels.board_rows import (
    REFRESH,
    TAB_KEY,
    Board,
    Row,
    Run,
    clean_name,
    from_wire,
    to_wire,
)
from sandbox.web.panels.student_rows import Readouts, Student, StudentPage, student_row
from sandbox.web.serving.roster import Roster

log = logging.getLogger(__name__)


IDENTIFY_TRIES = 10
"""Readings of the board (a second apart) that ask a page's identity again."""

MAX_NAMES = 1000
"""Names kept by tab key in a process (the oldest forgotten first)."""

ARRIVAL_GAP = 0.25
"""Seconds at least between two readings of the students: an arrival is reported at once
(not at the next second), a class arriving together in a few reports."""


class Hub(Protocol):
    """Where a process's rows go: merged here, or sent to the parent process."""

    def publish(
        self, rows: list[dict[str, Any]], wants: bool, load: dict[str, Any] | None = None
    ) -> None:
        """This process's students now (wire dicts); ``wants``: a teacher's page here
        waits for the merged board; ``load``: what its sessions cost (a wire
        :class:`~sandbox.web.loop.capacity.Load`)."""

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

    def publish(
        self, rows: list[dict[str, Any]], wants: bool, load: dict[str, Any] | None = None
    ) -> None:
        now = self.clock()
        checked = [r for r in (from_wire(d) for d in rows) if r is not None]
        self.roster.update("local", checked, now, Load.from_wire(load))
        if wants:
            self.deliver(replace(self.roster.board(now), run=self.run))

    def announce(self, run: Run) -> None:
        self.run = run
        self.deliver(replace(self.roster.board(self.clock()), run=run))


class Classroom:
    """The students of this process and the teacher pages showing the board.

    Once every :data:`~sandbox.web.panels.board_rows.REFRESH` seconds a thread reads each student's
    row and publishes them to the hub; the merged board comes back through
    :meth:`receive` and goes to the teacher pages.

    Args:
        connected: Whether a browser is still connected (by client id).
        clock: Wall clock [s].
        period: Seconds between readings.
        load: What this process's sessions cost now (default: the process loop's
            governor); before any is measured, :attr:`first` (the start-up measure).
    """

    def __init__(
        self,
        connected: Callable[[int], bool],
        *,
        clock: Callable[[], float] = time.time,
        period: float = REFRESH,
        load: Callable[[], Load] | None = None,
    ) -> None:
        self.connected = connected
        self.load = load or (lambda: Scheduler.shared().governor.load)
        self.first: Load | None = None
        self.cleanups: list[Callable[[], None]] = []  # run by stop()
        """The capacity measure taken at the start, before any session (None: none)."""
        self.clock = clock
        self.period = period
        self.start_time = clock()
        self.source = "p"
        self.hub: Hub = LocalHub(self.start_time, self.receive, clock=clock)
        self.board = Board(self.start_time)
        self.run: Run | None = None  # the class's challenge, as last heard
        self._students: dict[int, Student] = {}
        self._teachers: dict[int, BoardPanel] = {}
        self._waiting: dict[int, Callable[[], None]] = {}  # teachers before any student
        self._names: dict[str, str] = {}  # the last name of each tab's key seen here
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
        view: StudentPage | None = None,
        *,
        mode: str = "own",
        field: viser.GuiTextHandle | None = None,
        who: str = "",
    ) -> None:
        """A student's page (new, or rebuilt when they switch mode in follow mode: their
        name and arrival are kept); ``who``: the tab's own key (its row on the board is
        kept across a reload or a server's restart)."""
        cid = client.client_id
        with self._lock:
            old = self._students.get(cid)
        panel = view.challenge if view is not None else None
        if old is not None:
            if old.field is not None:
                old.name = clean_name(old.field.value)
            old.view, old.mode, old.field = view, mode, field
            old.sim = sim
            old.challenge = panel
            entry = old
        else:
            scene = sim.scene.name if sim.scene is not None else Path(str(sim.label)).stem
            entry = Student(client, self.clock(), scene[:80], Readouts.of(sim), view, mode, field)
            entry.who = who
            entry.sim = sim
            entry.challenge = panel
            with self._lock:
                self._students[cid] = entry
        with self._lock:
            run = self.run
        self._wake.set()  # on the board within a fraction of a second, not the next one
        if run is not None:  # a challenge runs: this student gets one too (the same one
            self._give(entry, run)  # when they come back to their own simulation)

    def seat(
        self,
        client: viser.ClientHandle,
        sim: Simulation,
        view: StudentPage | None = None,
        *,
        mode: str = "own",
        who: Callable[[], tuple[str, str]] = lambda: ("", ""),
    ) -> None:
        """A student's page with its « Votre prénom » box: the name typed here before a
        follow-mode switch, else the one their browser kept (``who``: the tab's key and
        that name, :func:`~sandbox.web.page.link.arrival`); the box comes first while no
        name is known."""
        key, kept = who()
        with self._lock:
            known = self._names.get(key, "") if key else ""
        field = name_field(client.gui, self.name_of(client.client_id) or kept or known)
        self.student(client, sim, view, mode=mode, field=field, who=key)
        if not key:  # the handshake not yet readable (a loaded machine): asked again
            with self._lock:
                entry = self._students.get(client.client_id)
            if entry is not None:
                entry.identify = who

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
        arrived: Callable[[], None] | None = None,
    ) -> BoardPanel:
        """Add the board to a teacher's page (with the challenges of ``scene``, whose
        students each have their own simulation); ``arrived`` is called once, when the
        board first lists a connected student."""
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
            if arrived is not None:
                self._waiting[client.client_id] = arrived
        self._first_students(self.board)
        return panel

    def forget(self, client_id: int) -> None:
        """A browser left."""
        with self._lock:
            self._students.pop(client_id, None)
            self._teachers.pop(client_id, None)
            self._waiting.pop(client_id, None)

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
        keys: set[str] = set()
        named: dict[str, str] = {}
        for cid, entry in reversed(entries):  # the newest page of a reloaded tab first
            if not self.connected(cid):
                self.forget(cid)
                continue
            if not entry.who and entry.identify is not None:
                self._identify(entry)
            # the tab's own key (its row survives a reload or a restart), unless another
            # page here already has it (a tab duplicated with its storage)
            key = f"{TAB_KEY}{entry.who}" if entry.who else ""
            if not key or key in keys:
                key = f"{self.source}:{cid}"
            keys.add(key)
            row = student_row(key, entry)
            if entry.who and row.name:  # a reload served here finds the name again
                named[entry.who] = row.name
            out.append(row)
        if named:
            with self._lock:  # once a reading, the newest names last
                for who, name in named.items():
                    self._names.pop(who, None)
                    self._names[who] = name
                while len(self._names) > MAX_NAMES:
                    del self._names[next(iter(self._names))]
        return out[::-1]  # in order of arrival

    def _identify(self, entry: Student) -> None:
        """Ask a page's identity again (its handshake was not readable when it arrived):
        its tab key, and its name when its box is still empty."""
        entry.tries += 1
        identify = entry.identify
        if identify is None or entry.tries > IDENTIFY_TRIES:
            entry.identify = None
            return
        key, kept = identify()
        if not key:
            return
        entry.who, entry.identify = key, None
        with self._lock:
            name = kept or self._names.get(key, "")
        field = entry.field
        if field is None:
            return
        if name and not clean_name(field.value):
            set_value(field, name)
        if clean_name(field.value):  # known now (the page's script may have filled it
            field.order = NAME_ORDER  # from its storage before the key came): last

    def tick(self) -> None:
        """Read the students and publish them (never raises: the board is not worth a
        session)."""
        try:
            with self._lock:
                wants = bool(self._teachers)
            self.hub.publish([to_wire(r) for r in self.rows()], wants, self._load())
        except Exception:
            if not self._failed:  # once: the next ticks would say the same
                self._failed = True
                log.exception("the class board could not be read")

    def _load(self) -> dict[str, Any] | None:
        """What this process's sessions cost: measured live once a session runs, else
        the start-up measure (None: neither yet)."""
        live = self.load()
        if live.sessions > 0 and live.frames > 0:
            return live.wire()
        first = self.first
        if first is None:
            return None
        return replace(first, fps=live.fps, saturated=live.saturated).wire()

    # -- challenges ------------------------------------------------------------------------
    def announce(self, run: Run) -> None:
        """A teacher's page started or stopped a challenge: to the class's hub (every
        process hears it back through :meth:`receive`)."""
        try:
            self.hub.announce(run)
        except Exception:
            log.exception("the challenge could not be announced")

    def _give(self, student: Student, run: Run) -> None:
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
        self._first_students(board)

    def _first_students(self, board: Board) -> None:
        """The teacher pages waiting for the class are told once it lists a student."""
        if not any(r.connected for r in board.rows):
            return
        with self._lock:
            waiting, self._waiting = list(self._waiting.values()), {}
        for arrived in waiting:
            try:
                arrived()
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
        """Stop reading, and the first estimate's measure if it still runs (a process
        that exits while a thread steps MuJoCo may crash on its way out)."""
        self._stop.set()
        self._wake.set()
        for cleanup in self.cleanups:
            cleanup()
        if self._thread is not None:
            self._thread.join(2.0)
