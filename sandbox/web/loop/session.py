"""One browser's session: the frames of its :class:`~sandbox.web.loop.controller.Controller`
(requests, stepping, recording) handed to its :class:`~sandbox.web.loop.frame.View`.

:class:`Session` builds one :class:`~sandbox.web.loop.frame.Frame` a tick and asks the
view (the viser panels, or anything with the same methods) to draw it; the process's
:class:`~sandbox.web.loop.scheduler.Scheduler` runs the ticks.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Mapping
from dataclasses import replace

from sandbox.errors import SandboxError
from sandbox.physics.picture import Picture, picture
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.strobe import HELD_ANGLE
from sandbox.web.loop.frame import FPS, Frame, Notice, Source, View
from sandbox.web.loop.refusals import french_message
from sandbox.web.loop.scheduler import Scheduler
from sandbox.web.loop.secret import Secret

log = logging.getLogger(__name__)

ALIVE_CHECK = 0.5
"""Seconds between checks that the session's browser is still connected."""

NOTICE_QUIET = 5.0
"""Seconds a message must stay away before it is shown again: a value refused on every
frame, or a failure that repeats, is shown once."""


class Session:
    """A browser's own simulation, whose frames the process's :class:`Scheduler` runs.

    Args:
        controller: What the session shows: a live controller (owns the simulation) or a
            replay (:class:`~sandbox.web.loop.frame.Source`).
        view: Display called at up to ``fps`` frames per second.
        fps: Frame rate [Hz].
        alive: Returns False once the session's browser has gone (checked every
            :data:`ALIVE_CHECK` seconds; the session then stops by itself).
        scheduler: The loop running the frames (default: the process's own).
        drive: Step the controller's simulation and own its recording; False for a
            view of a simulation that another session drives (a class following the
            teacher, the teacher's own panels).
    """

    def __init__(
        self,
        controller: Source,
        view: View,
        *,
        fps: float = FPS,
        alive: Callable[[], bool] | None = None,
        scheduler: Scheduler | None = None,
        drive: bool = True,
    ) -> None:
        self.controller: Source = controller
        self.drive = drive
        self.view = view
        self.period = 1.0 / fps
        self.alive = alive
        self.scheduler = scheduler or Scheduler.shared()
        self._stop = threading.Event()
        self._ended = threading.Event()
        self._started = False
        self._closed = threading.Lock()
        self._recording_closed = False
        self._next_check = 0.0
        self._pictured: tuple[int, float, int] | None = None  # key of the last picture
        self._held_key: tuple[int, int, int] | None = None  # of the held arrows
        self._held_picture: Picture | None = None  # a fast rotation's arrows, held
        self._seen: dict[tuple[str, str, str], float] = {}  # error notices: last seen
        self.held = 0  # frames not drawn because the browser's sender still held frames
        self._faults: dict[tuple[str, str, str], float] = {}  # frame failures: last seen

    def start(self) -> None:
        """Hand the session to the scheduler: its frames start at once."""
        self._started = True
        self.scheduler.add(self)

    def request_stop(self) -> None:
        """Ask the loop to drop this session at its next turn (returns at once)."""
        self._stop.set()
        self.scheduler.wake()

    def stop(self, timeout: float = 2.0) -> None:
        """Drop the session, wait for a frame in progress, then close any recording."""
        self.request_stop()
        if self._started and not self.scheduler.in_loop():
            if not self.scheduler.threaded:
                self.scheduler.run_due()  # the caller runs the frames: drop it now
            self._ended.wait(timeout)
        self._close_recording()

    def _close_recording(self) -> None:
        """Close the recording once, whoever stops the session first."""
        with self._closed:
            if self._recording_closed:
                return
            self._recording_closed = True
        ctl = self.controller
        if self.drive:
            with ctl.sim.lock:
                ctl.stop_recording()

    @property
    def stepping_cpu(self) -> float:
        """CPU seconds this session spent stepping its simulation so far (0 for a view
        of a simulation another session steps, or a replay)."""
        return self.controller.step_cpu_total if self.drive else 0.0

    @property
    def stopping(self) -> bool:
        """True once the session was asked to stop (the scheduler drops it next turn)."""
        return self._stop.is_set()

    @property
    def running(self) -> bool:
        """True from :meth:`start` until the session is dropped."""
        return self._started and not self._ended.is_set()

    @property
    def finished(self) -> bool:
        """True once the session was started and has ended (stopped, or its browser left)."""
        return self._started and self._ended.is_set()

    def run_once(self, now: float | None = None) -> None:
        """One frame: requests, stepping, one :class:`Frame`, drawing and recording; any
        error is shown, never raised."""
        ctl = self.controller
        now = ctl.clock() if now is None else now
        try:
            frame = self.build_frame(now)
        except Exception as exc:  # keep serving: the user sees the problem, once
            self._fault(exc, now, "frame")
            return
        for notice in frame.notices:
            self.notify(notice, now)
        try:
            self.view.render(frame)
        except Exception as exc:
            self._fault(exc, now, "render")

    def notify(self, notice: Notice, now: float) -> None:
        """Show ``notice`` unless the same error was seen less than :data:`NOTICE_QUIET`
        seconds ago (a value refused on every frame is shown once)."""
        if notice.level in ("error", "diverged"):
            key = (notice.level, notice.title, notice.text)
            last = self._seen.get(key)
            self._seen[key] = now
            if len(self._seen) > 64:  # forget the quiet ones
                self._seen = {k: t for k, t in self._seen.items() if now - t < NOTICE_QUIET}
            if last is not None and now - last < NOTICE_QUIET:
                return
        try:
            self.view.notify(notice)
        except Exception as exc:  # the browser may be gone
            if not self._stop.is_set():
                log.warning("cannot show a message: %s: %s", type(exc).__name__, exc)

    def _fault(self, exc: Exception, now: float, where: str) -> None:
        """A failed frame: logged (with its traceback) and shown once while it repeats."""
        if self._stop.is_set():
            return
        if isinstance(exc, SandboxError):
            notice = Notice("error", "Valeur refusée", french_message(exc))
        else:
            key = (where, type(exc).__name__, str(exc)[:200])
            last = self._faults.get(key)
            self._faults[key] = now
            if len(self._faults) > 64:
                self._faults = {k: t for k, t in self._faults.items() if now - t < NOTICE_QUIET}
            if last is None or now - last >= NOTICE_QUIET:
                log.error("session %s failed", where, exc_info=exc)
            notice = Notice(
                "error",
                "Erreur interne",
                f"L'image n'a pas pu être calculée ({type(exc).__name__}) ; la simulation "
                "continue. Si cela se répète, signalez-le à l'enseignant.",
            )
        self.notify(notice, now)

    def build_frame(self, now: float) -> Frame:
        """Step (when driving), then compute once what the view and the recorder need at
        this tick from one state: the picture when the drawn state changed and the view
        draws, the readouts it asks for (sharing the picture's forces), and record."""
        ctl = self.controller
        notices: list[Notice] = []
        if self.drive:
            notices = ctl.frame(now, record=False)  # recorded below, once the state is read
        draws = self.view.draws
        holding = not draws and bool(getattr(self.view, "holding", False))
        if holding:
            self.held += 1  # the governor counts these: the sending, not the loop, is short
        # a browser still holding frames keeps its last picture: its panels keep that
        # picture's instant too (and its link is spared their messages)
        wanted = None if holding else self.view.wants(now)
        every = wanted is not None and "*" in wanted
        names = set() if wanted is None or every else set(wanted)
        recording = self.drive and ctl.readouts_due()
        values: Mapping[str, float] | None = None  # the physics state's, for the recorder
        shown: Mapping[str, float] | None = None  # the drawn state's, for the view
        read = (every or bool(names)) and not ctl.diverged
        if recording and not ctl.diverged:
            values = ctl.readouts(())
        sim = ctl.sim
        drawn_at = ctl.drawn_time
        generation = int(ctl.generation)
        drawing: Picture | None = None
        snap: Snapshot | None = None
        secret: Secret | None = ctl.secret  # a replay has none
        key = (id(sim.model), drawn_at, generation)
        picturing = draws and not ctl.diverged and key != self._pictured
        # a fast rotation read at one angle: its numbers and its arrows at that instant
        strobe = getattr(self.view, "strobe", True)
        still = ctl.held() if strobe and (read or picturing) else None
        held = self._held_arrows(still, secret) if still is not None else None
        if picturing:
            scene = sim.scene
            arrows = scene.page.arrows if scene is not None else ()
            trail = scene.page.trail if scene is not None else None
            with sim.lock:
                # held: the arrows and the numbers are the held state's, poses only here
                forces = still is None and (bool(arrows) or (read and values is None))
                snap = ctl.drawn(forces=forces)
                twin = secret.twin(sim) if secret is not None else None
                drawing = picture(snap, arrows if held is None else (), trail=trail, shown=twin)
            if held is not None:  # the poses move on; the arrows stay at the held angle
                drawing = replace(
                    drawing, arrows=held.arrows, vectors=held.vectors, magnitudes=held.magnitudes
                )
            self._pictured = key
        state: Snapshot | None = None  # what the panels read besides the readouts
        if still is not None and read:  # every number of the frame at the held instant
            if names and HELD_ANGLE in sim.readout_names():
                names.add(HELD_ANGLE)  # the overlay says which angle
            with sim.lock:
                shown = ctl.shown_readouts(() if every else names, snapshot=still)
            state = still
        elif read:
            if values is not None:  # while recording, tables step with the physics
                shown = values
            else:
                with sim.lock:
                    if snap is None:  # nothing drawn this tick: the drawn state all the same
                        snap = ctl.drawn(forces=True)
                    shown = ctl.shown_readouts(() if every else names, snapshot=snap)
                state = snap
        if self.drive:
            ctl.record(values if recording else None)
        if secret is not None and shown is not None:
            shown = secret.hide(shown)
        return Frame(
            now=now,
            time=drawn_at,
            generation=generation,
            model_id=id(sim.model),
            playing=bool(ctl.playing),
            diverged=ctl.diverged,
            notices=tuple(notices),
            readouts=shown if wanted is not None else None,
            picture=drawing,
            state=state if wanted is not None else None,
            held=held if wanted is not None else None,
        )

    def _held_arrows(self, still: Snapshot, secret: Secret | None) -> Picture:
        """The arrows of a fast rotation's held state (:meth:`Source.held`), evaluated
        once a state: it is the same every turn."""
        ctl = self.controller
        sim = ctl.sim
        with sim.lock:
            twin = secret.twin(sim) if secret is not None else None
            key = (id(still), getattr(ctl, "held_generation", 0), id(twin))
            if key != self._held_key or self._held_picture is None:
                scene = sim.scene
                arrows = scene.page.arrows if scene is not None else ()
                self._held_picture = picture(still, arrows, shown=twin)
                self._held_key = key
            return self._held_picture

    def _turn(self, now: float) -> bool:
        """The scheduler's call: one frame unless the session must end; False to drop it."""
        if self._stop.is_set():
            return False
        if self.alive is not None and now >= self._next_check:
            self._next_check = now + ALIVE_CHECK
            if not self._still_alive():
                log.info("session stops: its browser is gone")
                self._stop.set()
                return False
        self.run_once()
        return not self._stop.is_set()

    def _end(self) -> None:
        """Called by the scheduler once the session is dropped."""
        self._ended.set()
        if self.drive:
            for cleanup in self.controller.cleanups:  # e.g. a study running for the page
                try:
                    cleanup()
                except Exception:
                    log.exception("a session's cleanup failed")
        if self.alive is not None and self._stop.is_set():
            self._close_recording()

    def _still_alive(self) -> bool:
        try:
            return bool(self.alive()) if self.alive is not None else True
        except Exception:  # a failing probe must not keep a dead session running
            log.exception("session liveness check failed")
            return False
