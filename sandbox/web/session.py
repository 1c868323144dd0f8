"""One browser's simulation: a request queue, real-time pacing and the frame loop.

:class:`Controller` owns the :class:`~sandbox.physics.simulation.Simulation` and the
queue; it knows nothing about viser, so tests drive it directly. :class:`Session`
runs the loop thread that drains the queue, steps in real time and asks a
:class:`View` (the viser panels, or anything with the same two methods) to draw.
"""

from __future__ import annotations

import heapq
import logging
import math
import queue
import threading
import time
from collections.abc import Callable, Collection, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from sandbox.errors import (
    BadModel,
    BadOption,
    BadParameter,
    Diverged,
    SandboxError,
    UnknownParameter,
)
from sandbox.physics.display import DisplayState, rotation_speed
from sandbox.physics.limits import MAX_TIMESTEP, MIN_TIMESTEP
from sandbox.physics.model import INTEGRATORS
from sandbox.physics.picture import FORCES, Picture, picture
from sandbox.physics.simulation import Simulation
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.units import display_unit
from sandbox.recording import Recorder, create_unique
from sandbox.scenes.base import Param, as_scene
from sandbox.web import text
from sandbox.web.probe import Probe
from sandbox.web.rewind import Rewind
from sandbox.web.secret import Secret

log = logging.getLogger(__name__)

RECORD_READOUTS = 10.0
"""Readouts stored per simulated second in a recording (the panels' refresh rate)."""

FPS = 60.0
"""Frame rate of pose updates sent to the browser [Hz]."""

MAX_LAG = 0.25
"""Wall-clock lag [s] beyond which pacing re-syncs instead of catching up. A loaded
server draws fewer frames (4 a second at worst) but keeps simulated time real."""

IDLE_EXIT = 5.0
"""Seconds without any session after which the scheduler's thread ends."""

ALIVE_CHECK = 0.5
"""Seconds between checks that the session's browser is still connected."""

SPEEDS = (0.01, 4.0)
"""Allowed speed factors (slowest, fastest): ×0.01 ("Ralenti") makes a 6000 rpm rotor
turn 6° between two frames at 60 frames per second."""

STEP_BUDGET = 0.005
"""CPU seconds of stepping one frame may spend (5 ms: 30 % of a core at 60 frames/s).
A timestep too small for real time on this machine then makes the motion run slower
than real time (the status line says so) instead of taking a whole core."""

MAX_FRAME_STEPS = 5000
"""Most timesteps one frame runs, whatever the measured cost (the budget before any
measure, and a bound the clock cannot move)."""

MAX_STEP_REQUEST = 1000
"""Most timesteps one "Pas" request may ask for."""

MAX_ADVANCE = 10.0
"""Longest "Pas" in time [s] (or its angle converted at the current speed)."""

MAX_ADVANCE_STEPS = 20000
"""Most timesteps one "Pas" in time or angle may run (a longer one is refused)."""

MAX_REQUESTS = 64
"""Requests applied in one frame once repeated settings are merged (the last value of a
slider, the timestep, the speed or the integrator wins); the rest are dropped."""

REQUEST_BUDGET = 0.005
"""CPU seconds the requests of one frame may spend (model rebuilds); those left wait for
the next frame, so a flood of settings slows its own session only."""

RESTART_AFTER = 1.0
"""Wall seconds a finished run stays in view before it starts again."""

SNAP = 0.1
"""While playing, a display time ahead of the physics by less than this fraction of a
frame's simulated advance (speed / :data:`FPS`) is drawn at the physics time itself: a
timing error no eye sees (a tenth of a frame), which spares carrying the state forward
and closing its loops. Slow motion and "Pas" still draw between two steps."""

NOTICE_QUIET = 5.0
"""Seconds a message must stay away before it is shown again: a value refused on every
frame, or a failure that repeats, is shown once."""


@dataclass(frozen=True)
class Request:
    """Something a GUI callback asks of the simulation loop.

    Attributes:
        kind: ``set_value``, ``play``, ``pause``, ``toggle``, ``step`` (timesteps),
            ``advance`` (a "Pas" in time or angle), ``reset``, ``speed``,
            ``integrator`` or ``timestep``; ``challenge`` (a
            :class:`~sandbox.web.secret.Secret`, or None to end it: built by the server,
            no control sends it).
        name: Parameter name for ``set_value``; ``s`` or ``deg`` for ``advance`` (the
            unit of ``value``: seconds, or degrees of the main rotating joint).
        value: The new value, unvalidated.
    """

    kind: str
    value: Any = None
    name: str = ""


@dataclass(frozen=True)
class Notice:
    """A message for the user: ``level`` is ``error``, ``diverged``, ``info`` or ``file``
    (``text`` is then the path of a file to offer for download)."""

    level: str
    title: str
    text: str


EVERY = frozenset({"*"})
"""What a view wants when it needs every readout (an open lesson may check any)."""


@dataclass(frozen=True)
class Frame:
    """What one display tick shows, built once by the session loop and handed to every
    consumer (the browser's view, the recorder).

    Attributes:
        now: Wall clock of the tick [s].
        time: Simulated time drawn [s] (the display time, between two physics steps).
        generation: Bumped on every reset (plots restart).
        model_id: Identity of the compiled model (a new one rebuilds the 3D nodes).
        playing: The simulation runs.
        diverged: The divergence message, or None.
        notices: Messages raised since the previous tick.
        readouts: Values of the readouts asked for this tick (computed once, only the
            names a consumer needs); None on ticks that refresh no panel.
        picture: What the 3D view draws (poses, arrows), computed once when the drawn
            state changed and a view draws; None otherwise (nothing moved: nothing sent).
    """

    now: float
    time: float
    generation: int
    model_id: int
    playing: bool
    diverged: str | None
    notices: tuple[Notice, ...] = ()
    readouts: Mapping[str, float] | None = None
    picture: Picture | None = None

    @property
    def key(self) -> tuple[int, float, int]:
        """Changes whenever the drawn state changes (model, time, reset)."""
        return (self.model_id, self.time, self.generation)


class View(Protocol):
    """What the loop needs from a display (the viser panels implement it)."""

    @property
    def draws(self) -> bool:
        """True when :meth:`render` draws the 3D scene: each new drawn state then comes
        with a :class:`~sandbox.physics.picture.Picture`."""

    def wants(self, now: float) -> Collection[str] | None:
        """Readouts needed at this tick: names, :data:`EVERY`, or None (no panel
        refresh now)."""

    def render(self, frame: Frame) -> None:
        """Draw the tick (called at up to :data:`FPS`)."""

    def notify(self, notice: Notice) -> None:
        """Show a message to the user."""


class Refused(SandboxError):
    """A value or command from the browser that the session refuses (French message)."""


class Controller:
    """The simulation of one session and the requests waiting for it.

    Args:
        sim: The session's own simulation.
        clock: Wall clock [s] (monotonic), replaceable in tests.
    """

    def __init__(
        self,
        sim: Simulation,
        *,
        clock: Callable[[], float] = time.perf_counter,
        record_dir: Path | None = None,
    ) -> None:
        self.sim = sim
        self.clock = clock
        self.record_dir = Path(record_dir or Path.cwd() / "recordings")
        self.recorder: Recorder | None = None
        self.later: list[Notice] = []  # notices of the recorder, given by the next drain()
        self.lesson: str | None = None  # lesson being followed (recorded with the session)
        self._recorded_t = -math.inf
        self._readouts_t = -math.inf
        self.step_cpu = 0.0  # CPU seconds spent stepping (this thread), decayed
        self.step_sim = 0.0  # simulated seconds stepped, decayed alike
        self.step_count = 0.0  # timesteps run, decayed alike
        self.requests: queue.Queue[Request] = queue.Queue()
        scene = as_scene(sim.scene)
        self.playing = not (scene is not None and scene.start_paused)
        self.speed = 1.0
        self.diverged: str | None = None
        self.generation = 0  # bumped on reset: plots restart
        self.refusals = 0  # requests refused so far (the panels then show the real values)
        self.slow_until = -math.inf  # wall clock until which the status says "slower"
        self._limited = 0  # consecutive frames the step budget held back
        self._spent = 0.0  # CPU seconds of stepping in the current frame
        self._owed = 0  # timesteps of a "Pas" still to run, a budget's worth a frame
        self._owed_target: float | None = None  # display time once they are run
        self._backlog: list[Request] = []  # requests past a frame's REQUEST_BUDGET
        self.display_time = float(sim.data.time)  # time drawn, ahead of the physics < dt
        self._ended_at: float | None = None  # wall clock the scene's run ended at
        self.display = DisplayState(sim)
        self.secret: Secret | None = None  # a challenge's, kept from the page
        self.probe = Probe()  # readouts sampled between frames (a "Tracé X–Y")
        self.cleanups: list[Callable[[], None]] = []  # run when its session ends
        self.rewind = Rewind()  # the last seconds, for « Exporter une vidéo »
        self._resync(clock())

    # -- called from GUI callbacks (any thread) ------------------------------------------
    def submit(self, request: Request) -> None:
        """Queue a request; the loop thread applies it before its next frame."""
        self.requests.put(request)

    # -- called from the loop thread -----------------------------------------------------
    def frame(self, now: float | None = None, *, record: bool = True) -> list[Notice]:
        """Step to catch up with the wall clock, then apply the queued requests.

        Stepping first means a request (which re-syncs the pacing) never swallows the
        time elapsed since the previous frame.

        Args:
            now: Wall clock [s].
            record: Also record the new state (the session loop records itself, with
                the readouts of its frame).
        """
        now = self.clock() if now is None else now
        self._spent = 0.0
        notices = self.advance(now)
        notices += self.drain(now)
        notices += self._run_owed(now)  # a "Pas" just asked starts within this frame
        if record:
            self.record()
        if not self.diverged:
            self.rewind.keep(self.sim)
        return notices

    # -- what is drawn -------------------------------------------------------------------
    @property
    def drawn_time(self) -> float:
        """Simulated time drawn [s]: :attr:`display_time`, or the physics time when the
        display is not ahead of it, or ahead by less than :data:`SNAP` of a frame while
        playing."""
        t = float(self.sim.data.time)
        gap = self.display.ahead(self.display_time)
        if gap == 0.0 or (self.playing and gap <= SNAP * self.speed / FPS):
            return t
        return self.display_time

    def shown_readouts(
        self, names: Collection[str], *, snapshot: Snapshot | None = None
    ) -> dict[str, float]:
        """Readouts of the state drawn (:attr:`drawn_time`, between two physics steps),
        so that tables and plots move with the drawing in slow motion; the physics
        state's own when the display is not ahead of it (every readout if ``names`` is
        empty).

        Args:
            names: Readouts (empty: all).
            snapshot: The drawn state already prepared for them (:meth:`drawn`), read as
                it is.
        """
        wanted = list(names) if names else None
        if snapshot is not None:
            return self.sim.readouts(wanted, snapshot=snapshot)
        at = self.drawn_time
        if self.display.ahead(at) == 0.0:
            return self.sim.readouts(wanted)
        return self.sim.readouts(wanted, data=self.display.data(at))

    def drawn(self, names: Collection[str] = ()) -> Snapshot:
        """The state to draw: the physics carried forward to :attr:`drawn_time` (never
        the physics ``MjData`` itself, which it leaves untouched).

        Args:
            names: Readouts evaluated on it (the arrows' forces); empty: poses only.
        """
        return self.display.snapshot(self.drawn_time, names)

    # -- recording -----------------------------------------------------------------------
    def record(self, values: Mapping[str, float] | None = None) -> None:
        """Add the current state (and, at :data:`RECORD_READOUTS` Hz, readouts) if new.

        Args:
            values: Every readout at the current state, when the loop already computed
                them for this tick (see :meth:`readouts_due`); else computed here.
        """
        rec, sim = self.recorder, self.sim
        t = float(sim.data.time)
        if rec is None or t == self._recorded_t or self.diverged:
            return
        row = None
        if self.readouts_due():
            row = dict(values) if values is not None else sim.readouts()
            self._readouts_t = t
        rec.frame(row)
        self._recorded_t = t
        if rec.full:
            self._roll_over(rec)

    def _roll_over(self, rec: Recorder) -> None:
        """A file reached the size a recording may have: it is closed (and downloaded)
        and the recording goes on in a new file, so nothing is lost."""
        self.recorder = None
        self.later.append(Notice("file", "Enregistrement terminé", str(rec.path)))
        try:
            path = self.start_recording()
        except SandboxError as exc:
            self.later.append(Notice("error", "Enregistrement arrêté", french_message(exc)))
            return
        self.later.append(
            Notice(
                "info",
                "Enregistrement",
                f"Fichier plein : l'enregistrement continue dans {path.name}",
            )
        )

    def readouts_due(self) -> bool:
        """True when the recorder wants a row of every readout at the current state."""
        if self.recorder is None or self.diverged:
            return False
        t = float(self.sim.data.time)
        return t != self._recorded_t and not t - 1.0 / RECORD_READOUTS < self._readouts_t <= t

    def readouts(self, names: Collection[str]) -> dict[str, float]:
        """Readouts of the current state (every readout when ``names`` is empty)."""
        return self.sim.readouts(list(names) if names else None)

    def start_recording(self, lesson: str | None = None) -> Path:
        """Start writing a recording in :attr:`record_dir`; returns its path."""
        if self.recorder is not None:
            return self.recorder.path
        self.record_dir.mkdir(parents=True, exist_ok=True)
        stamp = time.strftime("%Y%m%d-%H%M%S")
        # Opened exclusively: two browsers recording in the same second get -2, -3...
        path = create_unique(self.record_dir, f"{self.sim.label.replace('.', '_')}-{stamp}")
        self.recorder = Recorder(path, self.sim, lesson=lesson or self.lesson)
        self._recorded_t = self._readouts_t = -math.inf
        self.record()
        return path

    def stop_recording(self) -> Path | None:
        """Close the recording (never lost: also called when the browser leaves)."""
        rec, self.recorder = self.recorder, None
        if rec is None:
            return None
        self._record_final(rec)
        return rec.path

    def _record_final(self, rec: Recorder) -> None:
        try:
            if float(self.sim.data.time) != self._recorded_t and not self.diverged:
                rec.frame(self.sim.readouts())
        finally:
            rec.close()

    def drain(self, now: float | None = None) -> list[Notice]:
        """Apply the queued requests; a refused one becomes one French ``error`` notice.

        Repeated settings are merged first (only the last value of each slider, of the
        speed, timestep and integrator is applied), at most :data:`MAX_REQUESTS` are
        applied, and identical notices are given once.
        """
        now = self.clock() if now is None else now
        notices, self.later = self.later, []
        requests = merged(self._backlog + list(pending(self.requests)))
        self._backlog = []
        if len(requests) > MAX_REQUESTS:
            dropped = len(requests) - MAX_REQUESTS
            requests = requests[:MAX_REQUESTS]
            self.refusals += 1
            notices.append(
                Notice(
                    "error", "Trop de commandes", f"{dropped} commandes ignorées : une à la fois."
                )
            )
        start = time.thread_time()
        for i, request in enumerate(requests):
            if i and time.thread_time() - start > REQUEST_BUDGET:
                self._backlog = requests[i:]  # the next frame goes on with them
                break
            try:
                notice = self._apply(request)
            except Diverged as exc:
                notice = self._diverge(exc)
            except SandboxError as exc:
                self.refusals += 1
                notice = Notice("error", "Valeur refusée", french_message(exc))
            except Exception as exc:  # a bug must not kill the session
                self.refusals += 1
                log.warning("request %s failed: %s: %s", request.kind, type(exc).__name__, exc)
                notice = Notice(
                    "error",
                    "Erreur interne",
                    f"La commande « {shown_value(request.kind)} » a échoué "
                    f"({type(exc).__name__}) ; rien n'a été modifié.",
                )
            if notice is not None and notice not in notices:
                notices.append(notice)
            self._resync(now)
        return notices

    def advance(self, now: float | None = None) -> list[Notice]:
        """Step so that simulated time follows wall time × speed (in C, one call).

        When the simulation falls more than :data:`MAX_LAG` behind (slow machine,
        huge speed) or runs ahead (time jumped), pacing re-syncs rather than racing.
        A frame steps at most :meth:`frame_steps` times (:data:`STEP_BUDGET`): a timestep
        too small for real time makes the motion slower (:meth:`slowed`), never a busy
        core. A timestep that is not a positive number pauses, said once.
        """
        now = self.clock() if now is None else now
        if self._owed and not self.diverged:
            return self._run_owed(now)
        if not self.playing or self.diverged:
            self._resync(now)
            return []
        dt = self.sim.timestep
        if not (math.isfinite(dt) and dt > 0):  # e.g. a file with timestep="0"
            self.playing = False
            self.refusals += 1
            return [Notice("error", "Pas de temps invalide", _timestep_range(self.sim, dt))]
        target = self._sync_sim + (now - self._sync_wall) * self.speed
        behind = target - float(self.sim.data.time)
        if behind < -MAX_LAG * self.speed:
            self.display_time = float(self.sim.data.time)
            self._resync(now)
            return []
        steps = int(min(behind / dt, 1e9)) if behind > 0 else 0
        cap = max(1, int(math.ceil(min(MAX_LAG * self.speed / dt, 1e9))))
        budget = self.frame_steps()
        n = min(steps, cap, budget)
        failed = self._step(n)
        if failed is not None:
            return [failed]
        if n < steps <= cap:  # the budget, not a stall, held it back
            self._limited += 1
            if self._limited >= 3:  # not one late frame: the timestep is too small
                self.slow_until = now + 1.0
        else:
            self._limited = 0
        t = float(self.sim.data.time)
        if steps > n:
            self.display_time = t
            self._resync(now)
        else:  # the physics stopped at the last whole step before the target: draw the target
            self.display_time = max(target, t)
        self._restart_if_ended(now)
        return []

    def _restart_if_ended(self, now: float) -> None:
        """A scene whose run ends (:attr:`~sandbox.scenes.base.Scene.run_ended`) starts
        again :data:`RESTART_AFTER` s of wall time after the end (a reset request, applied
        by this frame's drain)."""
        scene = as_scene(self.sim.scene)
        ended = scene.run_ended if scene is not None else None
        if ended is None or not ended(self.sim.model, self.sim.data, self.sim.values):
            self._ended_at = None
        elif self._ended_at is None:
            self._ended_at = now
        elif now - self._ended_at >= RESTART_AFTER:
            self._ended_at = None
            self.submit(Request("reset"))

    def _step(self, n: int) -> Notice | None:
        """Run ``n`` timesteps, counted against this frame's budget; a failure pauses and
        comes back as its notice."""
        start = time.thread_time()
        try:
            if self.probe.active:
                self._step_sampled(n)
            else:
                self.sim.step(n)
        except Diverged as exc:
            return self._diverge(exc)
        except Exception as exc:  # stepping again would fail again: pause, say it once
            self.playing = False
            log.warning("stepping failed: %s: %s", type(exc).__name__, exc)
            return Notice(
                "error",
                "Calcul impossible",
                f"Le calcul du mouvement a échoué ({type(exc).__name__}) : simulation "
                "en pause. Changez le réglage puis cliquez sur « Réinitialiser ».",
            )
        finally:
            cost = time.thread_time() - start
            self._spent += cost
            self._count(cost, n * self.sim.timestep, n)
        return None

    def _step_sampled(self, n: int) -> None:
        """Run ``n`` timesteps, stopping where the probe samples its readouts."""
        sim, probe = self.sim, self.probe
        names = list(probe.names)
        for m, sample in probe.chunks(n, sim.timestep, self.speed):
            sim.step(m)
            if sample:
                probe.add(float(sim.data.time), sim.readouts(names))

    def _run_owed(self, now: float) -> list[Notice]:
        """Run what this frame's budget allows of a "Pas" (:attr:`_owed` timesteps): a
        long one is spread over frames, the drawn state showing its progress, so that a
        session asking for many steps only slows itself."""
        if self._owed <= 0 or self.diverged:
            return []
        n = min(self._owed, self.frame_steps())
        if n <= 0:
            return []
        failed = self._step(n)
        if failed is not None:
            self._owed, self._owed_target = 0, None
            return [failed]
        self._owed -= n
        t = float(self.sim.data.time)
        if self._owed == 0:
            self.display_time = t if self._owed_target is None else max(self._owed_target, t)
            self._owed_target = None
        else:
            self.display_time = t
        self._resync(now)
        return []

    @property
    def stepping(self) -> bool:
        """True while a "Pas" is being run over several frames."""
        return self._owed > 0

    def frame_steps(self) -> int:
        """Timesteps the rest of this frame may run: what is left of :data:`STEP_BUDGET`
        at the measured cost of a step, at least 1, at most :data:`MAX_FRAME_STEPS`."""
        left = STEP_BUDGET - self._spent
        if self.step_count > 0 and self.step_cpu > 0:
            per_step = self.step_cpu / self.step_count
            return max(1, min(MAX_FRAME_STEPS, int(left / per_step)))
        return MAX_FRAME_STEPS

    def slowed(self, now: float | None = None) -> bool:
        """True while the step budget keeps the motion slower than real time × speed."""
        return (self.clock() if now is None else now) < self.slow_until

    def _count(self, cpu: float, simulated: float, steps: int = 0) -> None:
        """Keep a running cost of stepping (the last few seconds weigh most)."""
        keep = 0.98
        self.step_cpu = keep * self.step_cpu + cpu
        self.step_sim = keep * self.step_sim + simulated
        self.step_count = keep * self.step_count + steps

    @property
    def cost(self) -> float:
        """CPU seconds of stepping per simulated second (NaN before any step)."""
        return self.step_cpu / self.step_sim if self.step_sim > 0 else math.nan

    # -- internals -----------------------------------------------------------------------
    def _resync(self, now: float) -> None:
        t = float(self.sim.data.time)
        if self.display.ahead(self.display_time) == 0.0:  # not just ahead of the physics
            self.display_time = t
        self._sync_wall = now
        self._sync_sim = self.display_time

    def _owe(self, count: int, target: float | None) -> None:
        """Pause and owe ``count`` more timesteps (run by :meth:`_run_owed`), drawing
        ``target`` [s] once they are run (None: the physics time).

        Raises:
            Refused: more than :data:`MAX_ADVANCE_STEPS` would be owed (a "Pas" in
                progress plus this one).
        """
        if self._owed + count > MAX_ADVANCE_STEPS:
            raise Refused(
                f"Pas refusé : le pas en cours demande encore {self._owed} pas de calcul "
                f"(au plus {MAX_ADVANCE_STEPS} en tout). Attendez qu'il finisse."
            )
        self.playing = False
        self._owed += count
        self._owed_target = target
        if self._owed == 0 and target is not None:  # less than a step: drawn at once
            self.display_time = max(target, float(self.sim.data.time))
            self._owed_target = None

    def _diverge(self, exc: Diverged) -> Notice:
        self.playing = False
        self.diverged = divergence_message(exc)
        return Notice("diverged", "Simulation divergée", self.diverged)

    def _apply(self, request: Request) -> Notice | None:
        kind, value, sim = request.kind, request.value, self.sim
        if kind == "reset":
            sim.reset()
            self._owed, self._owed_target = 0, None
            self.display_time = float(sim.data.time)
            self.diverged = None
            self.generation += 1
            return None
        if kind in ("play", "pause", "toggle"):
            want = {"play": True, "pause": False}.get(kind, not self.playing)
            if want and self.diverged:
                return _reset_first()
            self.playing = want
            if want:  # playing takes over from a "Pas" in progress
                self._owed, self._owed_target = 0, None
            return None
        if kind == "step":
            if self.diverged:
                return _reset_first()
            count = step_count(value)
            self._owe(count, None)
            return None
        if kind == "advance":
            if self.diverged:
                return _reset_first()
            seconds = advance_seconds(sim, value, request.name)
            start = self._owed_target if self._owed_target is not None else self.display_time
            target = start + seconds
            dt = sim.timestep
            reach = float(sim.data.time) + self._owed * dt  # where the steps owed lead
            count = math.floor((target - reach) / dt * (1 + 1e-9) + 1e-9)
            if count > MAX_ADVANCE_STEPS:
                raise Refused(
                    f"Pas de {text.number(seconds, 3)} s refusé : il demanderait "
                    f"{count} pas de calcul (au plus {MAX_ADVANCE_STEPS}). Choisissez un pas "
                    "plus court."
                )
            self._owe(max(count, 0), target)
            return None
        if kind == "speed":
            self.speed = check_speed(value)
            return None
        if kind == "set_value":
            if self.secret is not None and request.name in self.secret.locked:
                raise Refused("Ce réglage est caché pendant le défi : il reste tel quel.")
            sim.set_value(request.name, check_value(sim, request.name, value))
            return None
        if kind == "challenge":  # built by the server only (no control sends it)
            return self._challenge(value)
        if kind == "record":
            if self.secret is not None:
                raise Refused(
                    "Pas d'enregistrement pendant un défi : le fichier contiendrait la "
                    "solution. Enregistrez après la fin du défi."
                )
            path = self.start_recording()
            return Notice("info", "Enregistrement", f"Enregistrement en cours dans {path.name}")
        if kind == "stop_record":
            closed = self.stop_recording()
            if closed is None:
                return None
            return Notice("file", "Enregistrement terminé", str(closed))
        if kind == "integrator":
            sim.set_integrator(check_integrator(value))
            return None
        if kind == "timestep":
            sim.set_timestep(check_timestep(sim, value))
            return None
        if kind == "button":  # a label no button has (only a crafted message sends it)
            raise Refused(f"Bouton « {shown_value(value)} » inconnu : rien n'a changé.")
        raise Refused(f"Commande inconnue « {shown_value(kind)} ».")

    def _challenge(self, secret: object) -> Notice | None:
        """Start a challenge (a :class:`Secret`: its values set, the run from its start)
        or end it (None: the values stay, the page shows them again)."""
        if secret is not None and not isinstance(secret, Secret):
            raise Refused("Défi inconnu : rien n'a changé.")
        if secret is None:
            self.secret = None
            self.generation += 1
            return None
        closed = self.stop_recording()  # kept whole: what came before the challenge
        secret.apply(self.sim)
        self.secret = secret
        self._apply(Request("reset"))
        self.playing = True
        if closed is not None:
            return Notice("file", "Enregistrement terminé", str(closed))
        return None


DIVERGENCE_CAUSES = {
    "BADQACC": "accélérations démesurées",
    "BADQVEL": "vitesses démesurées",
    "BADQPOS": "positions démesurées",
    "NaN or Inf": "valeurs non numériques dans l'état",
}
"""French words for the causes a :class:`~sandbox.errors.Diverged` names."""


def divergence_message(exc: Diverged) -> str:
    """What the page says when the simulation blows up (French, decimal comma)."""
    detail = str(exc)
    cause = next((v for k, v in DIVERGENCE_CAUSES.items() if k in detail), "état non physique")
    return (
        f"La simulation a divergé à t = {text.number(exc.time, 4)} s ({cause}). "
        "Réduisez le pas de temps dt ou choisissez l'intégrateur Runge-Kutta 4 ou "
        "Implicite rapide, puis cliquez sur « Réinitialiser »."
    )


def advance_seconds(sim: Simulation, value: object, unit: object) -> float:
    """Seconds of motion of a "Pas" of ``value`` in ``unit`` (``s``, or ``deg`` of the
    mechanism's main rotating joint at its current speed).

    Raises:
        Refused: not a positive number within :data:`MAX_ADVANCE`, an unknown unit, or
            an angle while no joint turns.
    """
    if unit not in ("s", "deg"):
        raise Refused(f"Unité de pas « {shown_value(unit)} » inconnue : s ou °.")
    what = "Pas en temps" if unit == "s" else "Pas en angle"
    number = as_number(value, what)
    if unit == "s":
        if not 0 < number <= MAX_ADVANCE:
            raise Refused(
                f"Pas de {text.number(number, 3)} s refusé : choisissez entre 0 et "
                f"{text.number(MAX_ADVANCE)} s."
            )
        return number
    if not 0 < number <= 3600:
        raise Refused(f"Pas de {text.number(number, 3)}° refusé : choisissez entre 0 et 3600°.")
    w = rotation_speed(sim.model, sim.data)
    if w < 1e-6:
        raise Refused("Aucune pièce ne tourne : choisissez un pas en temps (s).")
    seconds = math.radians(number) / w
    if seconds > MAX_ADVANCE:
        raise Refused(
            f"Pas de {text.number(number, 3)}° refusé : à cette vitesse il durerait "
            f"{text.number(seconds, 3)} s (au plus {text.number(MAX_ADVANCE)} s)."
        )
    return seconds


def pending(requests: queue.Queue[Request]) -> Iterator[Request]:
    """The requests waiting in ``requests``, removed as they are yielded."""
    while True:
        try:
            yield requests.get_nowait()
        except queue.Empty:
            return


def merged(requests: list[Request]) -> list[Request]:
    """``requests`` with repeated settings merged: of several values of one slider, of
    the speed, the timestep or the integrator, only the last is kept (at its place)."""
    settings = ("set_value", "speed", "timestep", "integrator", "seek")
    last = {(r.kind, r.name): i for i, r in enumerate(requests) if r.kind in settings}
    return [
        r for i, r in enumerate(requests) if r.kind not in settings or last[(r.kind, r.name)] == i
    ]


def _reset_first() -> Notice:
    return Notice("error", "Simulation divergée", "Réinitialisez d'abord la simulation.")


def shown_value(value: object, limit: int = 40) -> str:
    """A short, one-line picture of a value from a browser (it may be 1 MB long)."""
    text = value if isinstance(value, str) else repr(value)
    text = "".join(c if c.isprintable() else " " for c in text[: limit + 1])
    return text if len(text) <= limit else text[: limit - 1] + "…"


def shown_number(value: object) -> str:
    """A value from a browser as the page writes it: a finite number with a decimal
    comma (``0,005``), anything else as :func:`shown_value` (``nan``, ``abc``)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
        return text.number(float(value), 6)
    return shown_value(value)


def french_number(x: float) -> str:
    """``x`` with 3 significant digits and a decimal comma (``0,001``, ``1×10⁻⁶``)."""
    return text.number(x, 3)


def as_number(value: object, what: str) -> float:
    """``value`` as a finite float (numbers and numeric strings; not bool or None).

    Raises:
        Refused: naming ``what``.
    """
    if isinstance(value, bool) or value is None:
        raise Refused(f"{what} : un nombre est attendu, reçu « {shown_value(value)} ».")
    if isinstance(value, str) and len(value) > 64:
        raise Refused(f"{what} : un nombre est attendu, reçu « {shown_value(value)} ».")
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise Refused(f"{what} : un nombre est attendu, reçu « {shown_value(value)} ».") from None
    if not math.isfinite(number):
        raise Refused(f"{what} : un nombre fini est attendu, reçu « {shown_value(value)} ».")
    return number


def max_timestep(sim: Simulation) -> float:
    """Largest timestep [s] the simulation accepts (the scene's own bound, if any)."""
    scene = as_scene(sim.scene)
    return min(MAX_TIMESTEP, scene.max_timestep) if scene is not None else MAX_TIMESTEP


def _timestep_range(sim: Simulation, value: object) -> str:
    shown = french_number(value) if isinstance(value, float) else shown_value(value)
    return (
        f"Pas de temps dt = {shown} s refusé : choisissez un pas entre "
        f"{french_number(MIN_TIMESTEP)} s et {french_number(max_timestep(sim))} s."
    )


def check_timestep(sim: Simulation, value: object) -> float:
    """A timestep [s] typed in the browser, between :data:`MIN_TIMESTEP` and the scene's
    maximum (Refused, giving the range, otherwise)."""
    try:
        dt = as_number(value, "Pas de temps")
    except Refused:
        raise Refused(_timestep_range(sim, value)) from None
    if not MIN_TIMESTEP <= dt <= max_timestep(sim):
        raise Refused(_timestep_range(sim, dt))
    return dt


def check_speed(value: object) -> float:
    """A speed factor within :data:`SPEEDS` (Refused otherwise)."""
    low, high = SPEEDS
    refusal = (
        f"Vitesse ×{shown_number(value)} refusée : choisissez entre ×{french_number(low)} "
        f"et ×{french_number(high)}."
    )
    try:
        speed = as_number(value, "Vitesse")
    except Refused:
        raise Refused(refusal) from None
    if not low <= speed <= high:
        raise Refused(refusal)
    return speed


def check_integrator(value: object) -> str:
    """An integrator name (Refused listing the valid ones otherwise)."""
    if not isinstance(value, str) or value not in INTEGRATORS:
        raise Refused(
            f"Intégrateur « {shown_value(value)} » inconnu : choisissez parmi "
            f"{', '.join(INTEGRATORS)}."
        )
    return value


def check_value(sim: Simulation, name: object, value: object) -> float:
    """A parameter value within its range (French refusals: unknown name, not a number,
    out of range)."""
    scene = as_scene(sim.scene)
    known = {p.name: p for p in scene.params} if scene is not None else {}
    if not isinstance(name, str) or name not in known:
        where = (
            f"parmi : {' ; '.join(param_words(p) for p in known.values())}"
            if known
            else "un fichier MJCF n'en a aucun"
        )
        raise Refused(f"Paramètre « {shown_value(name)} » inconnu ({where}).")
    p = known[name]
    unit = french_unit(p.unit)
    unit = unit if unit in ("", "°") else f" {unit}"
    is_number = isinstance(value, (int, float)) and not isinstance(value, bool)
    numeric = is_number and math.isfinite(value)  # type: ignore[arg-type]
    shown = shown_number(value)
    given = f"{shown}{unit}" if numeric else f"« {shown} »"
    refusal = (
        f"{param_words(p)} : {given} refusé, choisissez entre {text.number(p.min, 6)} et "
        f"{text.number(p.max, 6)}{unit}."
    )
    try:
        number = as_number(value, param_words(p))
    except Refused:
        raise Refused(refusal) from None
    if not p.min <= number <= p.max:
        raise Refused(refusal)
    return number


def french_unit(unit: str) -> str:
    """``unit`` as the page writes it (``rpm`` -> ``tr/min``, ``deg`` -> ``°``)."""
    return display_unit(unit)


def param_words(p: Param) -> str:
    """A parameter as the page names it: its French label, else its name."""
    return p.label or p.name


def step_count(value: object) -> int:
    """Timesteps asked by a "Pas" request: 1 by default, at most :data:`MAX_STEP_REQUEST`."""
    if value is None:
        return 1
    refusal = f"Nombre de pas « {shown_value(value)} » refusé : entre 1 et {MAX_STEP_REQUEST}."
    try:
        number = as_number(value, "Pas")
    except Refused:
        raise Refused(refusal) from None
    if number != int(number) or not 1 <= number <= MAX_STEP_REQUEST:
        raise Refused(refusal)
    return int(number)


FRENCH_REFUSALS: tuple[tuple[type[SandboxError], str], ...] = (
    (UnknownParameter, "Ce paramètre n'existe pas pour cette scène : rien n'a changé."),
    (BadParameter, "Cette valeur de paramètre est hors de son domaine : rien n'a changé."),
    (
        BadOption,
        "Réglage refusé (pas de temps dt ou intégrateur hors de ce que la scène accepte) : "
        "rien n'a changé.",
    ),
    (BadModel, "Le modèle ne se construit pas avec cette valeur : rien n'a changé."),
    (Diverged, "Le calcul diverge avec ce réglage : rien n'a changé."),
)
"""French words for the refusals of the lower layers, whose messages are English (they
speak to the command line); the English detail goes to the server's log only."""


def french_message(exc: SandboxError) -> str:
    """The message of a refusal for a French page: a :class:`Refused` is French already;
    an English one from a lower layer is said in French by its kind (its detail is
    logged)."""
    if isinstance(exc, Refused):
        return str(exc)
    log.info("refused: %s", shown_value(str(exc), 300))
    for kind, words in FRENCH_REFUSALS:
        if isinstance(exc, kind):
            return words
    return "Modification refusée : rien n'a changé."


class Session:
    """A browser's own simulation, whose frames the process's :class:`Scheduler` runs.

    Args:
        controller: The session's controller (owns the simulation).
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
        controller: Controller,
        view: View,
        *,
        fps: float = FPS,
        alive: Callable[[], bool] | None = None,
        scheduler: Scheduler | None = None,
        drive: bool = True,
    ) -> None:
        self.controller = controller
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
        self._seen: dict[tuple[str, str, str], float] = {}  # error notices: last seen
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
        stop_recording = getattr(self.controller, "stop_recording", None)
        if stop_recording is not None and self.drive:
            with self.controller.sim.lock:
                stop_recording()

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
            notices = ctl.frame(now, record=False) if _records(ctl) else ctl.frame(now)
        wanted = self.view.wants(now)
        every = wanted is not None and "*" in wanted
        names = set() if wanted is None or every else set(wanted)
        recording = self.drive and _records(ctl) and ctl.readouts_due()
        values: Mapping[str, float] | None = None  # the physics state's, for the recorder
        shown: Mapping[str, float] | None = None  # the drawn state's, for the view
        read = (every or bool(names)) and not ctl.diverged
        if recording and not ctl.diverged:
            values = _readouts(ctl, ())
        sim = ctl.sim
        drawn_at = float(getattr(ctl, "drawn_time", sim.data.time))
        generation = int(getattr(ctl, "generation", 0))
        drawing: Picture | None = None
        snap: Snapshot | None = None
        secret: Secret | None = getattr(ctl, "secret", None)  # a replay has none
        key = (id(sim.model), drawn_at, generation)
        if self.view.draws and not ctl.diverged and key != self._pictured:
            scene = as_scene(sim.scene)
            arrows = scene.arrows if scene is not None else ()
            trail = scene.trail if scene is not None else None
            with sim.lock:
                snap = drawn_snapshot(ctl, FORCES if arrows or (read and values is None) else ())
                twin = secret.twin(sim) if secret is not None else None
                drawing = picture(snap, arrows, trail=trail, shown=twin)
            self._pictured = key
        if read:
            if values is not None:  # while recording, tables step with the physics
                shown = values
            elif snap is not None and hasattr(ctl, "shown_readouts"):
                with sim.lock:
                    shown = ctl.shown_readouts(() if every else names, snapshot=snap)
            else:
                shown = _shown_readouts(ctl, () if every else names, None)
        if recording:
            ctl.record(values)
        elif self.drive and _records(ctl):
            ctl.record()
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
        )

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


def tick(now: float, period: float) -> float:
    """The first instant at or after ``now`` that is a whole number of ``period``: every
    session of one rate shares the same ticks, so the scheduler runs their frames in one
    burst per tick and sleeps between bursts (a core woken for every frame spends more
    on waking than on the frame: 1.4 ms instead of 0.13 ms measured for a rotor's)."""
    if not (period > 0 and math.isfinite(now)):
        return now
    return math.ceil(now / period - 1e-9) * period


class Scheduler:
    """One thread that runs the frames of every session of the process, earliest due first.

    One thread instead of one per browser: with thirty browsers, thirty threads waking
    sixty times a second spend more time handing the interpreter lock to each other
    than drawing. When the frames cost more than the machine has, every session slows
    down evenly (each is served in turn), and none starves.

    Args:
        clock: Wall clock [s] (monotonic) deciding when frames are due.
        threaded: Run the frames in the scheduler's own thread; False leaves it to
            :meth:`run_due` (tests drive it with a fake clock, without sleeping).
    """

    _shared: Scheduler | None = None
    _shared_lock = threading.Lock()

    def __init__(
        self, *, clock: Callable[[], float] = time.perf_counter, threaded: bool = True
    ) -> None:
        self.clock = clock
        self.threaded = threaded
        self._cond = threading.Condition()
        self._heap: list[tuple[float, int, Session]] = []
        self._seq = 0
        self._thread: threading.Thread | None = None

    @classmethod
    def shared(cls) -> Scheduler:
        """The process's scheduler (made on first use)."""
        with cls._shared_lock:
            if cls._shared is None:
                cls._shared = cls()
            return cls._shared

    def add(self, session: Session) -> None:
        """Run ``session``'s frames from now on."""
        with self._cond:
            self._seq += 1
            heapq.heappush(self._heap, (tick(self.clock(), session.period), self._seq, session))
            if not self.threaded:
                return
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(
                    target=self._run, name="sandbox-sessions", daemon=True
                )
                self._thread.start()
            self._cond.notify()

    def wake(self) -> None:
        """Let the loop look at its sessions now (one was asked to stop)."""
        with self._cond:
            for i, (due, seq, session) in enumerate(self._heap):
                if session._stop.is_set() and due > 0:
                    self._heap[i] = (0.0, seq, session)
            heapq.heapify(self._heap)
            self._cond.notify()

    def in_loop(self) -> bool:
        """True when called from the scheduler's own thread."""
        return threading.current_thread() is self._thread

    @property
    def sessions(self) -> int:
        """Sessions being served."""
        with self._cond:
            return len(self._heap)

    def run_due(self) -> int:
        """Run, in the calling thread, every frame due by :attr:`clock` (each session at
        most once); returns how many ran. For a scheduler made with ``threaded=False``."""
        with self._cond:
            due_now = self._pop_due()
        self._burst(due_now)
        return len(due_now)

    def _pop_due(self) -> list[tuple[float, int, Session]]:
        """Every entry due by now, earliest first (the caller holds the condition)."""
        now = self.clock()
        due_now = []
        while self._heap and self._heap[0][0] <= now:
            due_now.append(heapq.heappop(self._heap))
        return due_now

    def _burst(self, due_now: list[tuple[float, int, Session]]) -> None:
        """Serve the sessions due at one tick, in turn. (Holding every browser's messages
        until the last frame of the burst was measured: viser's sending thread, woken
        only between bursts, then coalesced frames and the class got fewer of them.)"""
        for due, seq, session in due_now:
            self._serve(due, seq, session)

    def _run(self) -> None:
        while True:
            with self._cond:
                while True:
                    if not self._heap:
                        if not self._cond.wait(IDLE_EXIT):
                            self._thread = None  # idle: the thread ends, add() restarts it
                            return
                        continue
                    delay = self._heap[0][0] - self.clock()
                    if delay <= 0:
                        due_now = self._pop_due()
                        break
                    self._cond.wait(delay)
            self._burst(due_now)

    def _serve(self, due: float, seq: int, session: Session) -> None:
        """One turn of ``session``, then its next frame is due one period later."""
        now = self.clock()
        try:
            keep = session._turn(now)
        except Exception:  # never lose the loop to one session
            log.exception("session turn failed")
            keep = True
        if not keep:
            try:
                session._end()
            except Exception:  # the loop serves every other page: it outlives this one
                log.exception("session end failed")
            return
        after = self.clock()
        following = due + session.period
        if following < after:  # late: the next tick of its rate, behind those waiting
            following = tick(after, session.period)
        with self._cond:
            heapq.heappush(self._heap, (following, seq, session))


def drawn_snapshot(ctl: Any, names: Collection[str] = ()) -> Snapshot:
    """The state a view draws: a live controller's display state (:meth:`Controller.drawn`,
    between physics steps), else its simulation's own state (a replay)."""
    drawn = getattr(ctl, "drawn", None)
    return drawn(names) if drawn is not None else ctl.sim.snapshot(names)


def _shown_readouts(
    ctl: Any, names: Collection[str], physics: Mapping[str, float] | None
) -> Mapping[str, float]:
    """The readouts a view shows: those of the drawn state when the controller draws
    between physics steps (:meth:`Controller.shown_readouts`); while recording, the
    recorder's row of the physics state (``physics``: one computation a tick serves
    both, so tables step with the physics while a recording runs)."""
    if physics is not None:
        return physics
    fn = getattr(ctl, "shown_readouts", None)
    return fn(names) if fn is not None else _readouts(ctl, names)


def _records(ctl: Any) -> bool:
    """True for a live controller (it records); a replay's controller does not."""
    return hasattr(ctl, "readouts_due")


def _readouts(ctl: Any, names: Collection[str]) -> Mapping[str, float]:
    """The controller's readouts (a replay's come from its recording, all at once)."""
    fn = getattr(ctl, "readouts", None)
    return fn(names) if fn is not None else ctl.values()
