"""GUI folders of a session: controls, parameters, readouts, torsors, energy, hypotheses.

Callbacks only queue :class:`~sandbox.web.session.Request` objects; the loop thread
applies them. Refresh methods are called by the view from the loop thread. Values
set programmatically (event.client is None) are never sent back as requests.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np
import viser

from sandbox.physics.limits import MIN_TIMESTEP
from sandbox.physics.model import INTEGRATORS
from sandbox.physics.simulation import Simulation
from sandbox.scenes.base import Param, as_scene
from sandbox.web import tables
from sandbox.web.session import SPEEDS, Controller, Request, max_timestep
from sandbox.web.text import plain

COMMANDS_PLAYING = ("Pause", "Pas", "Réinitialiser")
COMMANDS_PAUSED = ("Lecture", "Pas", "Réinitialiser")
COMMAND_KINDS = {"Pause": "pause", "Lecture": "play", "Pas": "step", "Réinitialiser": "reset"}
"""Buttons of the time bar and the request each one queues."""

RECORD_IDLE = ("● Enregistrer",)
RECORD_BUSY = ("■ Arrêter l'enregistrement",)
RECORD_KINDS = {RECORD_IDLE[0]: "record", RECORD_BUSY[0]: "stop_record"}


def _on_user(handle: viser.GuiInputHandle[Any], action: Callable[[Any], None]) -> None:
    """Run ``action(value)`` when the user (not the server) changes ``handle``."""

    @handle.on_update
    def _(event: viser.GuiEvent[Any]) -> None:
        if event.client is not None:
            action(event.target.value)


def set_value(handle: viser.GuiInputHandle[Any], value: object) -> None:
    """Show ``value`` in an input (sent to the browser).

    viser declares ``value`` as a property on one base class and as a plain field on
    the props class it also inherits, which mypy reads as read-only: assigned here once.
    """
    handle.value = value  # type: ignore[misc]


def command(kinds: dict[str, str], label: object) -> Request:
    """The request of a button labelled ``label`` (a browser may send any label: an
    unknown one becomes a request that the loop refuses once, in French)."""
    kind = kinds.get(label) if isinstance(label, str) else None
    return Request(kind) if kind is not None else Request("button", label)


def param_label(p: Param) -> str:
    """Slider label: the contract name and its unit."""
    return f"{p.name} [{p.unit}]" if p.unit else p.name


def param_step(p: Param) -> float:
    """Slider step: the scene's own, else 1/200 of the range."""
    return p.step if p.step > 0 else (p.max - p.min) / 200.0


def hypotheses(sim: Simulation) -> tuple[str, ...]:
    """Modelling hypotheses: the scene's effects, or what a user's file switches on."""
    scene = as_scene(sim.scene)
    if scene is not None:
        return tuple(scene.effects.hypotheses())
    flags = int(sim.model.opt.disableflags)
    dsbl = mujoco.mjtDisableBit
    g = float(np.linalg.norm(sim.model.opt.gravity))
    lines = ["Fichier MJCF : options du fichier conservées"]
    lines.append(
        "Poids négligé"
        if flags & dsbl.mjDSBL_GRAVITY or g == 0
        else f"Pesanteur prise en compte (g = {g:.3g} m/s²)"
    )
    lines.append(
        "Pas de contact entre solides"
        if flags & dsbl.mjDSBL_CONTACT
        else "Contacts simulés si les géométries se touchent"
    )
    lines.append("Référentiel terrestre supposé galiléen")
    return tuple(lines)


class ControlPanel:
    """Folders "Simulation" and "Paramètres", plus the divergence alert.

    Args:
        gui: A viser ``GuiApi`` (``client.gui``).
        controller: The session's controller (requests go to its queue).
    """

    def __init__(self, gui: viser.GuiApi, controller: Controller) -> None:
        self.controller = controller
        self._shown: dict[str, float] = {}
        self._refusals = 0
        sim = controller.sim
        scene = as_scene(sim.scene)
        submit = controller.submit
        with gui.add_folder("Alerte", visible=False) as self.alert:
            self.alert_text = gui.add_markdown("")
            reset2 = gui.add_button("Réinitialiser", color="red")
        reset2.on_click(lambda _: submit(Request("reset")))
        with gui.add_folder("Simulation"):
            self.title = gui.add_markdown(f"**{plain(scene.title if scene else sim.label)}**")
            self.status = gui.add_markdown("")
            self.commands = gui.add_button_group(
                "Temps", COMMANDS_PLAYING, hint="Pause/Lecture, un pas dt, état initial"
            )
            self.commands.on_click(lambda event: submit(command(COMMAND_KINDS, event.target.value)))
            self.speed = gui.add_slider(
                "Vitesse ×",
                min=SPEEDS[0],
                max=SPEEDS[1],
                step=0.1,
                initial_value=1.0,
                hint="Temps simulé / temps réel",
            )
            _on_user(self.speed, lambda v: submit(Request("speed", v)))
            self.integrator = gui.add_dropdown(
                "Intégrateur", tuple(INTEGRATORS), initial_value=_known(sim.integrator)
            )
            _on_user(self.integrator, lambda v: submit(Request("integrator", v)))
            self.timestep = gui.add_number(
                "dt [s]",
                initial_value=sim.timestep,
                step=1e-5,
                hint=f"Pas de temps (de {MIN_TIMESTEP:g} s à {max_timestep(sim):g} s)",
            )
            _on_user(self.timestep, lambda v: submit(Request("timestep", v)))
            self.record = gui.add_button_group(
                "Enregistrer",
                RECORD_IDLE,
                hint="Enregistre la séance pour « sandbox replay » (fichier .sbx)",
            )
            self.record.on_click(lambda event: submit(command(RECORD_KINDS, event.target.value)))
        self.sliders: dict[str, viser.GuiSliderHandle[float]] = {}
        if scene is not None and scene.params:
            with gui.add_folder("Paramètres"):
                for p in scene.params:
                    slider = gui.add_slider(
                        param_label(p),
                        min=p.min,
                        max=p.max,
                        step=param_step(p),
                        initial_value=sim.values[p.name],
                        hint=p.doc,
                    )
                    _on_user(slider, _setter(submit, p.name))
                    self.sliders[p.name] = slider
        self._playing: bool | None = None
        self._recording = False

    def refresh(self) -> None:
        """Status line and play/pause label."""
        ctl = self.controller
        state = "divergée" if ctl.diverged else ("en cours" if ctl.playing else "en pause")
        status = f"t = {ctl.sim.data.time:.3f} s · vitesse ×{ctl.speed:g} · **{state}**"
        if ctl.playing and not ctl.diverged and ctl.slowed():
            status += " · plus lent que le temps réel (pas de temps trop petit pour ce poste)"
        recorder = ctl.recorder
        recording = recorder is not None
        if recorder is not None:
            status += f" · ● enregistrement ({recorder.frames} images)"
        if self.status.content != status:
            self.status.content = status
        if ctl.refusals != self._refusals:  # a refused value: the controls show the real ones
            self._refusals = ctl.refusals
            self.sync()
        if recording != self._recording:
            self.record.options = RECORD_BUSY if recording else RECORD_IDLE
            self._recording = recording
        if ctl.playing != self._playing:
            self.commands.options = COMMANDS_PLAYING if ctl.playing else COMMANDS_PAUSED
            self._playing = ctl.playing
        if bool(ctl.diverged) != self.alert.visible:
            self.alert.visible = bool(ctl.diverged)
            self.alert_text.content = ctl.diverged or ""
        self._follow_simulation()

    def _follow_simulation(self) -> None:
        """Controls show what the simulation really uses, whoever changed it (a lesson
        preset, the teacher's settings, a timestep that follows the speed)."""
        sim = self.controller.sim
        for name, slider in self.sliders.items():
            value = sim.values.get(name)
            if value is not None and self._shown.get(name) != value:
                self._shown[name] = value
                if slider.value != value:
                    set_value(slider, value)
        if self._shown.get("<dt>") != sim.timestep:
            self._shown["<dt>"] = sim.timestep
            if self.timestep.value != sim.timestep:
                set_value(self.timestep, sim.timestep)

    def sync(self) -> None:
        """Put every control back to the simulation's actual values (after a refusal)."""
        sim = self.controller.sim
        for name, slider in self.sliders.items():
            set_value(slider, sim.values[name])
        set_value(self.speed, self.controller.speed)
        set_value(self.integrator, _known(sim.integrator))
        set_value(self.timestep, sim.timestep)


def _known(name: str) -> str:
    return name if name in INTEGRATORS else "euler"


def _setter(submit: Callable[[Request], None], name: str) -> Callable[[Any], None]:
    return lambda value: submit(Request("set_value", value, name=name))


class HypothesesPanel:
    """Folder "Hypothèses de modélisation": effects simulated and numerical method."""

    def __init__(self, gui: viser.GuiApi, sim: Simulation) -> None:
        self.sim = sim
        with gui.add_folder("Hypothèses de modélisation") as self.folder:
            self.text = gui.add_markdown(self._content())

    def _content(self) -> str:
        s = self.sim
        return tables.hypotheses_markdown(
            hypotheses(s), integrator=s.integrator, timestep=s.timestep
        )

    def refresh(self) -> None:
        """Follow integrator and timestep changes."""
        content = self._content()
        if content != self.text.content:
            self.text.content = content
