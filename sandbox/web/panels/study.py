"""Folder "Étude paramétrique": a readout measured over a range of a parameter, one
simulation per point, run in the background, dots appearing as runs finish, the course's
closed form dashed through them.

The page builds a :class:`~sandbox.sweep.Study` from its fields (the other parameters at
the session's current values), checks it with French refusals, and hands it to the
server's :class:`~sandbox.web.loop.study_queue.StudyQueue`, below the live sessions. The
scene's presets (:attr:`~sandbox.physics.page.Page.study_presets`) fill the fields with a
study that shows one of the course's laws.
"""

from __future__ import annotations

import decimal
import math
import threading
from collections.abc import Sequence
from typing import Any

import viser

from sandbox.errors import SandboxError
from sandbox.physics.presets import StudyPreset
from sandbox.physics.spec import Param
from sandbox.sweep import MAX_RUNS, Measure, Study, Vary, check
from sandbox.web.client.fields import param_label
from sandbox.web.client.text import number
from sandbox.web.loop import Refused, as_number, french_message
from sandbox.web.loop.state import SessionState
from sandbox.web.loop.study_queue import StudyJob, StudyQueue, progress_words
from sandbox.web.panels.folder import Folder
from sandbox.web.panels.preset_picker import PresetPicker
from sandbox.web.panels.study_chart import STAT_LABELS, StudyChart
from sandbox.web.panels.xy_data import Axis

FOLDER = "Étude paramétrique"
NONE = "— aucune —"
RUN = "Lancer l'étude"
CANCEL = "Annuler l'étude"
MAX_POINTS = 50
"""Points of one parameter in the page (a family: at most :data:`MAX_CURVES` curves)."""
MAX_CURVES = 5


def _step(p: Param) -> float:
    """The step of a bound's field: the parameter's slider step, else a thousandth of its
    range (the field shows as many decimals as its step has)."""
    return float(p.step) if p.step else (p.max - p.min) / 1000.0 or 0.001


def _set_step(fields: Sequence[viser.GuiNumberHandle[float]], p: Param) -> None:
    """Give the bound ``fields`` parameter ``p``'s step, and the decimals it needs: a
    field keeps the decimals of the step it was made with (a speed's 50 tr/min showed a
    rod length of 0,04 m as « 0 »)."""
    step = _step(p)
    exponent = decimal.Decimal(repr(step)).normalize().as_tuple().exponent
    digits = max(0, -exponent) if isinstance(exponent, int) else 3
    for field in fields:
        field.step = step
        field.precision = digits


class StudyPanel:
    """The folder, its form, its chart and the study running.

    Args:
        gui: A viser ``GuiApi``.
        controller: The live session (its parameter values fix the others).
        queue: The server's queue (default: this process's shared one).
    """

    def __init__(
        self, gui: viser.GuiApi, controller: SessionState, queue: StudyQueue | None = None
    ) -> None:
        self.gui = gui
        self.controller = controller
        self.queue = queue
        sim = controller.sim
        scene = sim.scene
        self.params: dict[str, Param] = {
            p.name: p for p in (scene.params if scene else ()) if not p.choices
        }
        self.param_words = {param_label(p): n for n, p in self.params.items()}
        self.readouts = {
            f"{i.label or i.name} [{Axis.of(i.name, '', i.unit).shown}]".replace(" []", ""): i.name
            for i in sim.readout_infos()
            if i.name != "time"
        }
        self.infos = {i.name: i for i in sim.readout_infos()}
        self.presets: dict[str, StudyPreset] = {
            p.label: p for p in (scene.page.study_presets if scene else ())
        }
        self.job: StudyJob | None = None
        self.received = False  # the job shown is the teacher's (follow mode)
        self._bounds_of: dict[str, str] = {}  # parameter whose range the fields hold
        self.preset_used: StudyPreset | None = None
        self._lock = threading.Lock()
        self._pending: dict[str, Any] = {}
        self._shown_done = -1
        self.folder: viser.GuiFolderHandle | None = None
        self.chart: StudyChart | None = None
        if not self.params:
            return
        first = next(iter(self.presets.values()), None)
        p0 = next(iter(self.params.values()))
        with gui.add_folder(FOLDER, expand_by_default=True) as self.folder:
            self.picker = PresetPicker(
                gui,
                "Étude proposée",
                tuple(self.presets),
                first=first.label if first is not None else None,
                hint="Des études qui montrent les lois du cours pour cette scène",
            )
            self.preset, self.hint = self.picker.dropdown, self.picker.hint
            self.vary = gui.add_dropdown(
                "Paramètre varié", tuple(self.param_words), initial_value=param_label(p0)
            )
            self.start = gui.add_number("De", float(p0.min), step=_step(p0))
            self.stop = gui.add_number("À", float(p0.max), step=_step(p0))
            self.count = gui.add_number("Nombre de points", 11, min=2, max=MAX_POINTS, step=1)
            self.family = gui.add_dropdown(
                "Famille de courbes (second paramètre)",
                (NONE, *self.param_words),
                initial_value=NONE,
                hint="Une courbe par valeur d'un second paramètre (facultatif)",
            )
            self.family_start = gui.add_number("De (famille)", 0.0, step=0.001, visible=False)
            self.family_stop = gui.add_number("À (famille)", 1.0, step=0.001, visible=False)
            self.family_count = gui.add_number(
                "Nombre de courbes", 3, min=2, max=MAX_CURVES, step=1, visible=False
            )
            self.measure = gui.add_dropdown("Grandeur mesurée", tuple(self.readouts))
            self.statistic = gui.add_dropdown(
                "Ce qu'on en retient",
                tuple(STAT_LABELS.values()),
                hint="Ce que l'on garde de chaque simulation",
            )
            self.duration = gui.add_number(
                "Durée de chaque simulation [s]", 1.0, min=0.0, step=0.01
            )
            self.settle = gui.add_number(
                "Mesure à partir de [s]",
                0.0,
                min=0.0,
                step=0.01,
                hint="Temps laissé au régime pour s'établir avant de mesurer",
            )
            self.button = gui.add_button(RUN)
            self.progress = gui.add_progress_bar(0.0, visible=False)
            self.status = gui.add_markdown("")
        self.chart = StudyChart(gui, self.folder, sim)
        with self.folder:
            self.csv = gui.add_button("Télécharger l'étude (CSV)", color="gray", disabled=True)
            self.png = gui.add_button("Télécharger l'étude (PNG)", color="gray", disabled=True)
        if first is not None:
            self.fill(first)
        self._connect()
        controller.on_close(self.close)

    def close(self) -> None:
        """The browser left: its study stops (runs not started are dropped)."""
        job = self.job
        if job is not None and not job.finished and not self.received:
            (self.queue or StudyQueue.shared()).cancel(job)

    # -- the form ------------------------------------------------------------------------
    def fill(self, preset: StudyPreset) -> None:
        """Put ``preset`` in the form (and remember its horizontal axis)."""
        self.preset_used = preset
        name, start, stop, count = preset.vary
        self._bounds_of[self.vary.label] = name
        self.vary.value = param_label(self.params[name])  # type: ignore[misc]
        _set_step((self.start, self.stop), self.params[name])
        self.start.value, self.stop.value = start, stop  # type: ignore[misc]
        self.count.value = count  # type: ignore[misc]
        if preset.family is not None:
            f, a, b, n = preset.family
            self._bounds_of[self.family.label] = f
            self.family.value = param_label(self.params[f])  # type: ignore[misc]
            _set_step((self.family_start, self.family_stop), self.params[f])
            self.family_start.value, self.family_stop.value = a, b  # type: ignore[misc]
            self.family_count.value = n  # type: ignore[misc]
        else:
            self.family.value = NONE  # type: ignore[misc]
        self._show_family()
        words = {n: t for t, n in self.readouts.items()}
        self.measure.value = words[preset.measure]  # type: ignore[misc]
        self.statistic.value = STAT_LABELS[preset.statistic]  # type: ignore[misc]
        self.duration.value, self.settle.value = preset.duration, preset.settle  # type: ignore[misc]
        self.picker.show(preset.hint)

    def _show_family(self) -> None:
        on = str(self.family.value) != NONE
        for handle in (self.family_start, self.family_stop, self.family_count):
            handle.visible = on

    def study(self) -> Study:
        """The study the form describes, checked (French refusals).

        Raises:
            Refused: a bound outside the parameter's range, too many points or steps, a
                settling time past the duration, a second parameter equal to the first.
        """
        sim = self.controller.sim
        name = self.param_words.get(str(self.vary.value))
        if name is None:
            raise Refused("Choisissez le paramètre à faire varier.")
        varies = [self._vary(name, self.start.value, self.stop.value, self.count.value, 2)]
        family = self.param_words.get(str(self.family.value))
        if family is not None:
            if family == name:
                raise Refused("Le second paramètre doit différer du premier.")
            varies.append(
                self._vary(
                    family,
                    self.family_start.value,
                    self.family_stop.value,
                    self.family_count.value,
                    MAX_CURVES,
                )
            )
        readout = self.readouts.get(str(self.measure.value))
        statistics = {w: s for s, w in STAT_LABELS.items()}
        statistic = statistics.get(str(self.statistic.value), "final")
        duration = as_number(self.duration.value, "Durée de chaque simulation")
        settle = as_number(self.settle.value, "Mesure à partir de")
        if not (math.isfinite(duration) and 0 < duration <= 60):
            raise Refused("Durée de chaque simulation : choisissez entre 0 et 60 s.")
        if not (math.isfinite(settle) and 0 <= settle < duration):
            raise Refused(
                "La mesure doit commencer avant la fin de la simulation : choisissez un "
                f"temps entre 0 et {number(duration, 3)} s."
            )
        if readout is None:
            raise Refused("Choisissez la grandeur à mesurer.")
        chosen = {v.name for v in varies}
        fixed = tuple((n, repr(float(v))) for n, v in sim.values.items() if n not in chosen)
        preset = self.preset_used
        course = preset.course if preset is not None and preset.measure == readout else None
        study = Study(
            sim.scene.name if sim.scene is not None else "",
            tuple(varies),
            Measure(readout, statistic),
            duration,
            settle,
            fixed=fixed,
            motion=sim.motion,
            course=course,
        )
        try:
            check(study)
        except SandboxError as exc:
            raise Refused(
                "Étude refusée : trop de calcul pour le serveur (au plus "
                f"{MAX_RUNS} simulations et 10⁷ pas en tout). Réduisez la durée ou le nombre "
                "de points."
                if "steps" in str(exc) or "runs" in str(exc)
                else french_message(exc)
            ) from None
        return study

    def _vary(self, name: str, start: object, stop: object, count: object, most: int) -> Vary:
        sim = self.controller.sim
        try:
            a, b = sim.check_value(name, start), sim.check_value(name, stop)
        except SandboxError as exc:  # the slider's own check and words
            raise Refused(french_message(exc)) from None
        if a == b:
            raise Refused(f"{param_label(self.params[name])} : donnez deux bornes différentes.")
        most = MAX_POINTS if most == 2 else most
        n = as_number(count, "Nombre de points")
        if not (2 <= n <= most and n == int(n)):
            raise Refused(f"Nombre de points : choisissez entre 2 et {most}.")
        return Vary(name, a, b, int(n))

    # -- callbacks (viser's threads) -----------------------------------------------------
    def _connect(self) -> None:
        def later(key: str, value: Any = True) -> None:
            with self._lock:
                self._pending[key] = value

        self.preset.on_update(
            lambda e: later("preset", str(e.target.value)) if e.client is not None else None
        )
        self.family.on_update(lambda e: later("family") if e.client is not None else None)
        for handle in (
            self.vary,
            self.start,
            self.stop,
            self.count,
            self.family_start,
            self.family_stop,
            self.family_count,
            self.measure,
            self.statistic,
            self.duration,
            self.settle,
        ):
            handle.on_update(lambda e: later("edited") if e.client is not None else None)
        self.button.on_click(lambda e: self._clicked(e.client))
        self.csv.on_click(lambda e: self._download(e.client, "csv"))
        self.png.on_click(lambda e: self._download(e.client, "png"))

    def _download(self, client: viser.ClientHandle | None, kind: str) -> None:
        job = self.job
        if client is None or job is None or job.done == 0:
            return
        if self.controller.secret is not None:
            return  # a crafted click during a challenge gets nothing
        StudyChart.download(client, kind, job)

    def receive(self, job: StudyJob) -> None:
        """Show the teacher's study (follow mode): its dots as they come; the button
        still runs the student's own study (it never cancels the teacher's)."""
        self.job, self.received = job, True
        self._shown_done = -1

    def _clicked(self, client: viser.ClientHandle | None) -> None:
        job = self.job
        if job is not None and not job.finished and not self.received:
            (self.queue or StudyQueue.shared()).cancel(job)
            self._shown_done = -1
            return
        if self.controller.secret is not None:
            self._refuse(client, "Pas d'étude pendant un défi : elle révélerait le réglage caché.")
            return
        try:
            study = self.study()
            preset = self.preset_used
            x = preset.x if preset is not None and preset.vary[0] == study.varies[0].name else None
            job = StudyJob(study, study.points(), x=x)
            (self.queue or StudyQueue.shared()).submit(job)
        except Refused as exc:
            self._refuse(client, str(exc))
            return
        except OverflowError:
            self._refuse(
                client,
                "Le serveur a déjà trop d'études en attente : réessayez dans un moment, "
                "ou réduisez le nombre de points.",
            )
            return
        self.job, self.received = job, False
        self._shown_done = -1

    def _refuse(self, client: viser.ClientHandle | None, text: str) -> None:
        if client is not None:
            client.add_notification("Étude paramétrique", text, color="red", auto_close_seconds=8.0)

    # -- from the session loop -----------------------------------------------------------
    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché » (none for a scene without parameters): it
        runs simulations of its own, so a challenge closes it."""
        if self.folder is None:
            return []
        return [Folder(FOLDER, self.folder, lambda _: self.refresh())]

    def refresh(self) -> None:
        """Apply the form's changes; show the study's progress and new dots."""
        if self.folder is None:
            return
        with self._lock:
            pending, self._pending = self._pending, {}
        if "preset" in pending:
            preset = self.presets.get(pending["preset"])
            if preset is not None:
                self.fill(preset)
            else:
                self.preset_used = None
                self.picker.show("")
        elif pending.get("edited") or pending.get("family"):
            for pick, fields in (
                (self.vary, (self.start, self.stop)),
                (self.family, (self.family_start, self.family_stop)),
            ):
                chosen = self.param_words.get(str(pick.value))
                if chosen is not None and chosen != self._bounds_of.get(pick.label):
                    self._bounds_of[pick.label] = chosen  # a new parameter: its own range
                    q = self.params[chosen]
                    _set_step(fields, q)
                    for field, value in zip(fields, (q.min, q.max), strict=True):
                        field.value = float(value)  # type: ignore[misc]
            self.preset_used = None  # the form no longer is the preset's
            self.picker.free()
            self._show_family()
        job = self.job
        if job is None or job.done == self._shown_done and not job.finished:
            return
        if job.done == self._shown_done and self.button.label == RUN:
            return
        self._shown_done = job.done
        queue = self.queue or StudyQueue.shared()
        self.progress.visible = not job.finished
        self.progress.value = 100.0 * job.done / max(job.total, 1)  # type: ignore[misc]
        words = progress_words(job, queue.ahead_of(job))
        self.status.content = f"Étude du professeur. {words}" if self.received else words
        self.button.label = RUN if job.finished or self.received else CANCEL
        self.csv.disabled = self.png.disabled = job.done == 0
        if self.chart is not None:
            self.chart.draw(job)
