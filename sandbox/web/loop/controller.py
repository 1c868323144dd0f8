"""One browser's simulation and the requests waiting for it.

:class:`Controller` owns the :class:`~sandbox.physics.simulation.Simulation` and the
queue: it paces the stepping (:class:`~sandbox.web.loop.pacing.Pacing`), applies the
requests and records; it knows nothing about viser, so tests drive it directly.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Collection, Mapping
from pathlib import Path

from sandbox.errors import Diverged, SandboxError
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, create_unique
from sandbox.web.client import text
from sandbox.web.loop.frame import Notice
from sandbox.web.loop.pacing import MAX_ADVANCE_STEPS, Pacing
from sandbox.web.loop.refusals import (
    Refused,
    advance_seconds,
    check_speed,
    check_timestep,
    french_message,
    shown_value,
    step_count,
)
from sandbox.web.loop.requests import (
    Advance,
    Button,
    Challenge,
    Command,
    Integrator,
    Motion,
    Pause,
    Play,
    Record,
    Reset,
    Seek,
    SetValue,
    Speed,
    Steps,
    StopRecord,
    Timestep,
    Toggle,
    merged,
    pending,
    words,
)
from sandbox.web.loop.rewind import Rewind
from sandbox.web.loop.secret import Secret

log = logging.getLogger(__name__)

RECORD_READOUTS = 10.0
"""Readouts stored per simulated second in a recording (the panels' refresh rate)."""

MAX_REQUESTS = 64
"""Requests applied in one frame once repeated settings are merged (the last value of a
slider, the timestep, the speed or the integrator wins); the rest are dropped."""

REQUEST_BUDGET = 0.005
"""CPU seconds the requests of one frame may spend (model rebuilds); those left wait for
the next frame, so a flood of settings slows its own session only."""


class Controller(Pacing):
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
        super().__init__(sim, clock=clock)
        self.record_dir = Path(record_dir or Path.cwd() / "recordings")
        self.recorder: Recorder | None = None
        self.later: list[Notice] = []  # notices of the recorder, given by the next drain()
        self.lesson: str | None = None  # lesson being followed (recorded with the session)
        self.lesson_step: int | None = None  # its step on the page (a recording starts with it)
        self._recorded_t = -math.inf
        self._readouts_t = -math.inf
        self.generation = 0  # bumped on reset: plots restart
        self._backlog: list[Command] = []  # requests past a frame's REQUEST_BUDGET
        self.secret: Secret | None = None  # a challenge's, kept from the page
        self.cleanups: list[Callable[[], None]] = []  # run when its session ends
        self.rewind = Rewind()  # the last seconds, for « Exporter une vidéo »

    # -- what its panels may do (:class:`~sandbox.web.loop.state.SessionState`) --------
    def pending(self) -> bool:
        """Requests wait for the loop (a control may be ahead of the simulation)."""
        return not self.requests.empty()

    def on_close(self, cleanup: Callable[[], None]) -> None:
        """Run ``cleanup`` when the session ends."""
        self.cleanups.append(cleanup)

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
        if self.lesson_step is not None and (lesson is None or lesson == self.lesson):
            # the step shown when recording starts, not the lesson's first
            self.recorder.event("lesson", step=self.lesson_step)
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
                notice = self._do(request)
            except Diverged as exc:
                notice = self._diverge(exc)
            except SandboxError as exc:
                self.refusals += 1
                notice = Notice("error", "Valeur refusée", french_message(exc))
            except Exception as exc:  # a bug must not kill the session
                self.refusals += 1
                log.warning("command %s failed: %s: %s", request, type(exc).__name__, exc)
                notice = Notice(
                    "error",
                    "Erreur interne",
                    f"La commande « {words(request)} » a échoué "
                    f"({type(exc).__name__}) ; rien n'a été modifié.",
                )
            if notice is not None and notice not in notices:
                notices.append(notice)
            self._resync(now)
        return notices

    def _do(self, cmd: Command) -> Notice | None:
        """Apply one typed request; a refusal raises (French), a message returns."""
        sim = self.sim
        match cmd:
            case Reset():
                sim.reset()
                self._owed, self._owed_target = 0, None
                self.display_time = float(sim.data.time)
                self.diverged = None
                self.generation += 1
                return None
            case Play():
                return self._play(True)
            case Pause():
                return self._play(False)
            case Toggle():
                return self._play(not self.playing)
            case Steps(value):
                if self.diverged:
                    return _reset_first()
                count = step_count(value)
                self._owe(count, None)
                return None
            case Advance(value, unit):
                if self.diverged:
                    return _reset_first()
                seconds = advance_seconds(sim, value, unit)
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
            case Speed(value):
                self.speed = check_speed(value)
                return None
            case SetValue(name, value):
                if self.secret is not None and name in self.secret.locked:
                    raise Refused("Ce réglage est caché pendant le défi : il reste tel quel.")
                sim.set_value(name, value)
                return None
            case Challenge(secret):  # built by the server only (no control sends it)
                return self._challenge(secret)
            case Record():
                if self.secret is not None:
                    raise Refused(
                        "Pas d'enregistrement pendant un défi : le fichier contiendrait la "
                        "solution. Enregistrez après la fin du défi."
                    )
                path = self.start_recording()
                return Notice("info", "Enregistrement", f"Enregistrement en cours dans {path.name}")
            case StopRecord():
                closed = self.stop_recording()
                if closed is None:
                    return None
                return Notice("file", "Enregistrement terminé", str(closed))
            case Integrator(value):
                sim.set_integrator(value)
                return None
            case Timestep(value):
                sim.set_timestep(check_timestep(sim, value))
                return None
            case Motion(value):
                sim.set_motion(value)
                return None
            case Seek():  # a replay's scrubber: a live simulation has no timeline
                raise Refused(
                    "Une simulation en direct n'a pas de ligne de temps : rien n'a changé."
                )
            case Button(value):  # a label no button has (only a crafted message sends it)
                raise Refused(f"Bouton « {shown_value(value)} » inconnu : rien n'a changé.")

    def _play(self, want: bool) -> Notice | None:
        """Play (``want``) or pause; a diverged simulation must be reset first."""
        if want and self.diverged:
            return _reset_first()
        self.playing = want
        if want:  # playing takes over from a "Pas" in progress
            self._owed, self._owed_target = 0, None
        return None

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
        self._do(Reset())
        self.playing = True
        if closed is not None:
            return Notice("file", "Enregistrement terminé", str(closed))
        return None


def _reset_first() -> Notice:
    return Notice("error", "Simulation divergée", "Réinitialisez d'abord la simulation.")
