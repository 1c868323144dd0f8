"""Real-time pacing of one session's simulation: stepping so that simulated time follows
wall time × speed within a CPU budget, a "Pas" spread over frames, and the state drawn
between two physics steps.

:class:`Pacing` is the clock side of the :class:`~sandbox.web.loop.controller.Controller`
(which adds the requests' dispatch and the recording); it knows nothing about viser.
"""

from __future__ import annotations

import logging
import math
import queue
import time
from collections.abc import Callable, Collection

from sandbox.errors import Diverged, SandboxError
from sandbox.physics.display import DisplayState
from sandbox.physics.simulation import Simulation
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.strobe import Held
from sandbox.web.loop.frame import FPS, Notice
from sandbox.web.loop.probe import Probe
from sandbox.web.loop.refusals import Refused, divergence_message, french_message
from sandbox.web.loop.requests import Command, Reset

log = logging.getLogger(__name__)

MAX_LAG = 0.5
"""Wall-clock lag [s] beyond which pacing re-syncs instead of catching up (a laptop that
slept, a clock that jumped). A loaded server draws fewer frames (the governor lowers them
to 15 a second, :mod:`~sandbox.web.loop.governor`) but keeps simulated time real: a frame
comes well within this."""

SLOW_HOLD = 3.0
"""Seconds the status keeps saying "plus lent que le temps réel" after the step budget last
held the motion back: on a machine that only just keeps up, the note would otherwise come
and go every second, and the buttons under the status line jump with it."""

STEP_BUDGET = 0.005
"""CPU seconds of stepping one frame at 60 frames/s may spend (5 ms: 30 % of a core). A
longer frame (the governor lowered the rate) may spend in proportion
(:data:`STEP_SHARE` of its wall time), so that the same motion keeps real time at any
frame rate. A timestep too small for real time on this machine makes the motion run
slower than real time (the status line says so) instead of taking a whole core."""

STEP_SHARE = STEP_BUDGET * FPS
"""Share of a core one session's stepping may take (0.3), whatever its frame rate."""

LONGEST_FRAME = 0.1
"""Wall seconds of a frame counted at most for its step budget (a frame after a pause of
the loop does not get a second of stepping at once)."""

MAX_FRAME_STEPS = 5000
"""Most timesteps one frame runs, whatever the measured cost (the budget before any
measure, and a bound the clock cannot move)."""

MAX_ADVANCE_STEPS = 20000
"""Most timesteps one "Pas" in time or angle may run (a longer one is refused)."""

RESTART_AFTER = 1.0
"""Wall seconds a finished run stays in view before it starts again."""

SNAP = 0.1
"""While playing, a display time ahead of the physics by less than this fraction of a
frame's simulated advance (speed / :data:`FPS`) is drawn at the physics time itself: a
timing error no eye sees (a tenth of a frame), which spares carrying the state forward
and closing its loops. Slow motion and "Pas" still draw between two steps."""


class Pacing:
    """The stepping of one session's simulation in real time, and the state it draws.

    Args:
        sim: The session's own simulation.
        clock: Wall clock [s] (monotonic), replaceable in tests.
    """

    def __init__(self, sim: Simulation, *, clock: Callable[[], float] = time.perf_counter) -> None:
        self.sim = sim
        self.clock = clock
        self.step_cpu = 0.0  # CPU seconds spent stepping (this thread), decayed
        self.step_sim = 0.0  # simulated seconds stepped, decayed alike
        self.step_count = 0.0  # timesteps run, decayed alike
        self.step_cpu_total = 0.0  # CPU seconds spent stepping so far (never decayed)
        self.requests: queue.Queue[Command] = queue.Queue()
        scene = sim.scene
        self.playing = not (scene is not None and scene.page.start_paused)
        self.speed = 1.0
        self.diverged: str | None = None
        self.refusals = 0  # requests refused so far (the panels then show the real values)
        self.slow_until = -math.inf  # wall clock until which the status says "slower"
        self._limited = 0  # consecutive frames the step budget held back
        self._spent = 0.0  # CPU seconds of stepping in the current frame
        self._budget = STEP_BUDGET  # CPU seconds of stepping the current frame may spend
        self._last_frame: float | None = None  # wall clock of the previous frame
        self._owed = 0  # timesteps of a "Pas" still to run, a budget's worth a frame
        self._owed_target: float | None = None  # display time once they are run
        self.display_time = float(sim.data.time)  # time drawn, ahead of the physics < dt
        self._ended_at: float | None = None  # wall clock the scene's run ended at
        self.display = DisplayState(sim)
        self._held = Held(sim)
        self.probe = Probe()  # readouts sampled between frames (a "Tracé X–Y")
        self._resync(clock())

    # -- called from GUI callbacks (any thread) ------------------------------------------
    def submit(self, request: Command) -> None:
        """Queue a request; the loop thread applies it before its next frame."""
        self.requests.put(request)

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

    def held(self) -> Snapshot | None:
        """While playing a fast imposed rotation, the state its numbers are read at: the
        last instant before the drawn one at which the input passed its scene's angle
        (:mod:`sandbox.physics.strobe`); None otherwise (paused, simulated, slow)."""
        if not self.playing or self.diverged:
            return None
        return self._held.snapshot(self.drawn_time, self.speed)

    @property
    def held_generation(self) -> int:
        """Changes when :meth:`held` places a new state (what was drawn from the old one
        is stale)."""
        return self._held.generation

    def drawn(self, names: Collection[str] = (), *, forces: bool = False) -> Snapshot:
        """The state to draw: the physics carried forward to :attr:`drawn_time` (never
        the physics ``MjData`` itself, which it leaves untouched).

        Args:
            names: Readouts evaluated on it; empty: poses only.
            forces: The arrows' and scene readouts' forces are read on it.
        """
        return self.display.snapshot(self.drawn_time, names, forces=forces)

    def advance(self, now: float | None = None) -> list[Notice]:
        """Step so that simulated time follows wall time × speed (in C, one call).

        When the simulation falls more than :data:`MAX_LAG` behind (slow machine,
        huge speed) or runs ahead (time jumped), pacing re-syncs rather than racing.
        A frame steps at most :meth:`frame_steps` times (:data:`STEP_BUDGET`): a timestep
        too small for real time makes the motion slower (:meth:`slowed`), never a busy
        core. A timestep that is not a positive number pauses, said once.
        """
        now = self.clock() if now is None else now
        self._frame_budget(now)
        if self._owed and not self.diverged:
            return self._run_owed(now)
        if not self.playing or self.diverged:
            self._resync(now)
            return []
        dt = self.sim.timestep
        if not (math.isfinite(dt) and dt > 0):  # e.g. a file with timestep="0"
            self.playing = False
            self.refusals += 1
            return [Notice("error", "Pas de temps invalide", _timestep_refusal(self.sim, dt))]
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
                self.slow_until = now + SLOW_HOLD
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
        """A scene whose run ends (:attr:`~sandbox.physics.spec.Scene.run_ended`) starts
        again :data:`RESTART_AFTER` s of wall time after the end (a reset request, applied
        by this frame's drain)."""
        scene = self.sim.scene
        ended = scene.run_ended if scene is not None else None
        if ended is None or not ended(self.sim.model, self.sim.data, self.sim.values):
            self._ended_at = None
        elif self._ended_at is None:
            self._ended_at = now
        elif now - self._ended_at >= RESTART_AFTER:
            self._ended_at = None
            self.submit(Reset())

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

    def _frame_budget(self, now: float) -> None:
        """This frame's step budget: :data:`STEP_SHARE` of the wall time since the
        previous frame (5 ms at 60 frames/s, 20 ms at 15), within
        [:data:`STEP_BUDGET`, :data:`STEP_SHARE` × :data:`LONGEST_FRAME`]; only
        :data:`STEP_BUDGET` while the motion is slower than real time anyway (a timestep
        this machine cannot keep up with, a flood of « Pas »): such a session does not
        take a larger share of the loop because the class's frames were slowed."""
        last, self._last_frame = self._last_frame, now
        wall = (now - last) if last is not None else 1.0 / FPS
        if self.slowed(now):
            self._budget = STEP_BUDGET
            return
        self._budget = STEP_SHARE * min(max(wall, 1.0 / FPS), LONGEST_FRAME)

    @property
    def stepping(self) -> bool:
        """True while a "Pas" is being run over several frames."""
        return self._owed > 0

    def frame_steps(self) -> int:
        """Timesteps the rest of this frame may run: what is left of its step budget
        (:data:`STEP_BUDGET` at 60 frames/s, in proportion to a longer frame) at the
        measured cost of a step, at least 1, at most :data:`MAX_FRAME_STEPS`."""
        left = self._budget - self._spent
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
        self.step_cpu_total += cpu
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


def _timestep_refusal(sim: Simulation, dt: float) -> str:
    """What the page says of a timestep that is not a positive number: the simulation's
    own refusal of it (the range it accepts), or, were it to take it, that it is none."""
    try:
        sim.check_timestep(dt)
    except SandboxError as exc:
        return french_message(exc)
    return "Le pas de temps du modèle n'est pas un nombre positif."
