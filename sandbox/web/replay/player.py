"""``sandbox replay``: a recording played in the browser with a timeline.

Each browser gets its own :class:`ReplayController` (its own position on the timeline)
over the shared, read-only :class:`~sandbox.recording.Recording`. The 3D view, arrows,
tables and plots are the live app's (:class:`~sandbox.web.views.browser.WebView`); only the top
panel differs: a time scrubber, play/pause, frame stepping and a speed factor.
"""

from __future__ import annotations

import math
import queue
import sys
import time
from collections.abc import Callable, Collection, Mapping
from typing import Any

import numpy as np
import viser

from sandbox.errors import SandboxError
from sandbox.physics.snapshot import Snapshot
from sandbox.recording import Recording
from sandbox.replay import ModelChoice, open_replay, set_values
from sandbox.web.client.fields import param_label, set_value
from sandbox.web.client.text import number, plain, table_row
from sandbox.web.loop import (
    Notice,
    Refused,
    Session,
    as_number,
    check_speed,
    french_message,
    merged,
    pending,
    step_count,
)
from sandbox.web.loop.requests import Command, Pause, Play, Seek, Speed, Steps, Toggle, words
from sandbox.web.loop.secret import Secret
from sandbox.web.panels.controls import bounds, command, speed_slider
from sandbox.web.serving.server import App, open_server, serve_until_stopped
from sandbox.web.views.browser import WebView
from sandbox.written import date_words, time_words


class ReplayController:
    """Position, speed and play state of one browser's replay.

    It has the attributes the live view reads (``sim``, ``playing``, ``speed``,
    ``diverged``, ``generation``) so the same panels draw it.

    Args:
        rec: The recording.
        clock: Wall clock [s].
    """

    def __init__(self, rec: Recording, *, clock: Callable[[], float] = time.perf_counter) -> None:
        self.rec = rec
        self.clock = clock
        self.model: ModelChoice  # which model replays it: the scene's or the recording's
        self.sim, self.model = open_replay(rec)
        self.requests: queue.Queue[Command] = queue.Queue()
        self.playing = True
        self.speed = 1.0
        self.diverged: str | None = None
        self.generation = 0
        self.index = 0
        self.timeline = rec.timeline
        self.position = 0.0
        self._last = clock()
        self.cleanups: list[Callable[[], None]] = []  # run when its session ends
        self._show(0)

    # -- what a session reads (sandbox.web.loop.frame.Source) ---------------------------
    secret: Secret | None = None  # a replay has no challenge
    step_cpu_total = 0.0  # nor stepping cost

    @property
    def drawn_time(self) -> float:
        """Simulated time drawn [s]: the recorded frame's."""
        return float(self.sim.data.time)

    def drawn(self, names: Collection[str] = (), *, forces: bool = False) -> Snapshot:
        """The recorded frame's state, its forces brought up to date when asked."""
        return self.sim.snapshot(names, forces=forces)

    def held(self) -> Snapshot | None:
        """None: a replay writes its recorded rows as they are."""
        return None

    def shown_readouts(
        self, names: Collection[str], *, snapshot: Snapshot | None = None
    ) -> dict[str, float]:
        """The recorded row of the frame shown (all of it, whatever is asked)."""
        return self.values()

    def readouts(self, names: Collection[str]) -> dict[str, float]:
        """The recorded row of the frame shown."""
        return self.values()

    def readouts_due(self) -> bool:
        """A replay records nothing."""
        return False

    def record(self, values: Mapping[str, float] | None = None) -> None:
        """A replay records nothing."""

    def stop_recording(self) -> None:
        """A replay records nothing."""

    # -- requests ------------------------------------------------------------------------
    def submit(self, request: Command) -> None:
        """Queue a request (``play``, ``pause``, ``toggle``, ``step``, ``seek``, ``speed``)."""
        self.requests.put(request)

    def frame(self, now: float | None = None, *, record: bool = True) -> list[Notice]:
        """Apply requests, move along the timeline, load the frame's state (``record``:
        unused, a replay records nothing)."""
        now = self.clock() if now is None else now
        notices: list[Notice] = []
        for request in merged(list(pending(self.requests))):
            try:
                self._apply(request)
            except SandboxError as exc:  # a bad value never stops the replay
                notice = Notice("error", "Valeur refusée", french_message(exc))
                if notice not in notices:
                    notices.append(notice)
            except Exception as exc:
                notice = Notice(
                    "error",
                    "Erreur interne",
                    f"La commande « {words(request)} » a échoué ({type(exc).__name__}).",
                )
                if notice not in notices:
                    notices.append(notice)
        if self.playing:
            self.position += (now - self._last) * self.speed
            if self.position >= self.timeline[-1]:
                self.position = float(self.timeline[-1])
                self.playing = False
            self._show(self._index_at(self.position))
        self._last = now
        return notices

    def _apply(self, request: Command) -> None:
        """Do what ``request`` asks, as the live controller reads it; what only a live
        simulation does is refused."""
        match request:
            case Play() | Pause() | Toggle() as cmd:
                self.playing = {Play: True, Pause: False}.get(type(cmd), not self.playing)
                if self.playing and self.index >= len(self.rec.times) - 1:
                    self._seek_index(0)
            case Steps(value):
                back = isinstance(value, int | float) and not isinstance(value, bool) and value < 0
                count = step_count(-value if back else value)  # type: ignore[operator]
                self.playing = False
                self._seek_index(self.index - count if back else self.index + count)
            case Seek(value):
                self._seek_index(self._index_at(as_number(value, "Temps")))
            case Speed(value):
                self.speed = check_speed(value)
            case _:
                raise Refused(
                    f"Une relecture n'a pas la commande « {words(request)} » : utilisez la "
                    "ligne de temps."
                )

    # -- timeline ------------------------------------------------------------------------
    def _index_at(self, t: float) -> int:
        i = int(np.searchsorted(self.timeline, t + 1e-12, side="right")) - 1
        return min(max(i, 0), len(self.timeline) - 1)

    def _seek_index(self, index: int) -> None:
        index = min(max(index, 0), len(self.rec.times) - 1)
        if index < self.index:
            self.generation += 1  # plots restart
        self.position = float(self.timeline[index])
        self._show(index)

    def _show(self, index: int) -> None:
        """Load frame ``index``: parameters in force then (a binary search in the
        recording's timeline of values; at most one rebuild), and its full state."""
        sim = self.sim
        with sim.lock:
            changes = [
                (name, value)
                for name, value in self.rec.values_at(index).items()
                if sim.values.get(name) != value
            ]
            if changes:
                set_values(sim, changes)
            motion = self.rec.motion_at(index)
            if motion != sim.motion:
                sim.set_motion(motion)
            sim.restore(self.rec.states[index])
        self.index = index

    def values(self) -> dict[str, float]:
        """Readouts shown at the current frame: the recorded ones, else computed."""
        shown = self.rec.readouts_of_frame(self.index)
        return shown if shown else self.sim.readouts()


TIMELINE_LABEL = "Temps [s]"


def seconds(t: float) -> str:
    """A time on the timeline, to the hundredth of a second: ``5,80`` (as every view
    writes a time: :func:`sandbox.written.time_words`)."""
    return time_words(float(t))


def timeline_scale(duration: float, frames: int) -> tuple[float, float]:
    """The time slider's step and end [s], both to the hundredth: viser writes the box
    with as many decimals as its step, bounds and value have (a step of 13,46/137 s wrote
    « 13,4600000 »), and the status line writes times to the hundredth."""
    step = max(round(duration / max(frames - 1, 1), 2), 0.01)
    return step, math.ceil(max(duration, step) * 100.0 - 1e-9) / 100.0


class ReplayPanel:
    """Folder "Relecture": status, time scrubber, play/pause, frame steps, speed."""

    COMMANDS = ("Lecture/Pause", "Image précédente", "Image suivante", "Début")

    def __init__(self, gui: viser.GuiApi, controller: ReplayController) -> None:
        self.controller = controller
        rec = controller.rec
        submit = controller.submit
        step, top = timeline_scale(float(controller.timeline[-1]), len(rec.times))
        with gui.add_folder("Relecture"):
            # The header comes from a file students exchange: shown as text, never HTML.
            lesson = rec.header.get("lesson")
            self.title = gui.add_markdown(
                f"**{plain(rec.header.get('target'))}** · enregistré le "
                f"{plain(date_words(rec.header.get('created')))}"
                + (f" · leçon {plain(lesson)}" if lesson else "")
            )
            self.status = gui.add_markdown("")
            self.commands = gui.add_button_group(
                "Commandes",
                self.COMMANDS,
                hint="Lecture ou pause, une image en arrière ou en avant, retour au début",
            )
            self.commands.on_click(lambda event: self._command(event.target.value))
            self.time = gui.add_slider(
                TIMELINE_LABEL,
                min=0.0,
                max=top,
                step=step,
                initial_value=0.0,
                marks=bounds(0.0, top),
                hint="Position dans l'enregistrement : faites glisser pour y aller",
            )
            self.speed = speed_slider(gui, "Temps relu divisé par le temps réel (1 : temps réel)")
        self.params: viser.GuiMarkdownHandle | None = None
        scene = controller.sim.scene
        self.scene_params = scene.params if scene is not None else ()
        if self.scene_params:
            with gui.add_folder("Paramètres enregistrés"):
                self.params = gui.add_markdown("")

        @self.time.on_update
        def _(event: viser.GuiEvent[viser.GuiSliderHandle[float]]) -> None:
            if event.client is not None:
                submit(Seek(event.target.value))

        @self.speed.on_update
        def _(event: viser.GuiEvent[viser.GuiSliderHandle[float]]) -> None:
            if event.client is not None:
                submit(Speed(event.target.value))

    COMMAND_KINDS: Mapping[str, Command] = {
        "Lecture/Pause": Toggle(),
        "Image précédente": Steps(-1),
        "Image suivante": Steps(),
        "Début": Seek(0.0),
    }

    def _command(self, label: object) -> None:
        self.controller.submit(command(self.COMMAND_KINDS, label))

    def refresh(self, time: float | None = None) -> None:
        """Follow the timeline (the scrubber moves while playing); ``time`` is unused (a
        replay shows its recorded rows, one instant each)."""
        ctl = self.controller
        t = float(ctl.rec.times[ctl.index])
        pos = float(ctl.timeline[ctl.index])
        state = "lecture" if ctl.playing else "pause"
        status = (
            f"t = {seconds(t)} s · {seconds(pos)} s lues sur {seconds(ctl.timeline[-1])} s · "
            f"image {ctl.index + 1} sur {len(ctl.rec.times)} · vitesse ×{number(ctl.speed, 3)}"
            f" · **{state}**"
        )
        if self.status.content != status:
            self.status.content = status
        shown = round(pos, 2)  # to the hundredth, as its box writes it
        if not abs(self.time.value - shown) <= 1e-9:  # also a NaN a browser sent
            set_value(self.time, shown)
        if not self.speed.value == ctl.speed:
            set_value(self.speed, ctl.speed)  # a refused speed: the value in force
        if self.params is not None:
            sim = ctl.sim
            rows = [
                table_row(plain(param_label(p)), number(sim.values[p.name]))
                for p in self.scene_params
            ]
            content = "\n".join([table_row("Paramètre", "Valeur"), "|:--|--:|", *rows])
            if self.params.content != content:
                self.params.content = content

    def sync(self) -> None:
        """Nothing to put back: the replay refuses nothing the user can type."""


def start_replay(
    rec: Recording, *, host: str = "127.0.0.1", port: int = 8080, open_message: bool = True
) -> App:
    """Serve ``rec`` in background threads and return at once."""
    _, model = open_replay(rec)  # fails early with a clear message
    if model.warning and open_message:
        print(f"sandbox: warning: {model.warning}", file=sys.stderr, flush=True)
    server = open_server(host, port, "Relecture — Dynamique des solides")

    def session(client: viser.ClientHandle) -> Session:
        ctl = ReplayController(rec)
        view = WebView(client, ctl, controls=lambda gui: ReplayPanel(gui, ctl))
        return Session(ctl, view)

    app = App(server, host, session)
    if open_message:
        print(f"sandbox: replay of {rec.path} at {app.url} (Ctrl-C to stop)", flush=True)
    return app


def serve_replay(rec: Recording, **options: Any) -> None:
    """Serve ``rec`` until Ctrl-C (keyword arguments as for :func:`start_replay`)."""
    serve_until_stopped(lambda: start_replay(rec, **options))
