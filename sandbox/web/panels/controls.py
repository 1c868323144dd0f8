"""GUI folders of a session: simulation controls, parameters, hypotheses.

Callbacks only queue typed commands (:data:`~sandbox.web.loop.requests.Command`); the loop thread
applies them. Refresh methods are called by the view from the loop thread. Values
set programmatically (event.client is None) are never sent back as requests.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping, Sequence
from typing import Any

import viser

from sandbox.physics.imposed import IMPOSED, MOTION_WORDS
from sandbox.physics.limits import MIN_TIMESTEP
from sandbox.physics.model import INTEGRATORS, integrator_words
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.spec import Param, file_hypotheses
from sandbox.web.client.fields import (
    Mirror,
    advanced,
    choices,
    engineering,
    integrator_name,
    on_user,
    param_hint,
    parse_number,
    typed,
)
from sandbox.web.client.fields import (
    param_label as param_label,
)
from sandbox.web.client.fields import (
    set_value as set_value,
)
from sandbox.web.client.text import number, plain, with_unit
from sandbox.web.loop import SPEEDS
from sandbox.web.loop.requests import (
    Button,
    Command,
    Integrator,
    Motion,
    Pause,
    Play,
    Record,
    Reset,
    SetValue,
    Speed,
    Steps,
    StopRecord,
    Timestep,
)
from sandbox.web.loop.state import SessionState
from sandbox.web.panels import tables
from sandbox.web.panels.folder import Folder
from sandbox.written import time_words

COMMANDS_PLAYING = ("Pause", "Pas", "Réinitialiser")
COMMANDS_PAUSED = ("Lecture", "Pas", "Réinitialiser")
COMMAND_KINDS: Mapping[str, Command] = {
    "Pause": Pause(),
    "Lecture": Play(),
    "Pas": Steps(),
    "Réinitialiser": Reset(),
}
"""Buttons of the time bar and the command each one queues."""

RECORD_IDLE = ("Enregistrer",)
RECORD_BUSY = ("Arrêter l'enregistrement",)
RECORD_KINDS: Mapping[str, Command] = {RECORD_IDLE[0]: Record(), RECORD_BUSY[0]: StopRecord()}

INTEGRATOR_HINT = "Schéma qui calcule le mouvement d'un pas de temps au suivant"
EXACT_HINT = (
    "Sans objet en mouvement imposé : le calcul est exact à chaque instant. Passez en "
    "mouvement libre pour choisir un intégrateur et un pas de temps."
)
SPEED_LABEL = "Vitesse ×"
MOTION_LABEL = "Mouvement"
MOTION_HINT = (
    "Imposé : le moteur impose exactement le mouvement d'entrée (la manivelle tourne à la "
    "vitesse demandée) ; positions, vitesses et accélérations viennent des équations de "
    "fermeture, les efforts de la dynamique inverse, comme dans le cours. Libre : MuJoCo "
    "calcule le mouvement pas à pas, le moteur asservi en vitesse."
)
INTEGRATOR_LABEL = "Intégrateur"
TIMESTEP_LABEL = "Pas de temps dt [s]"
PARAMS_FOLDER = "Paramètres"
ADVANCED_FOLDER = "Réglages avancés"
NUMERICS_FOLDER = "Méthode numérique"
CHALLENGE_LOCKED = "Réglage fixé par le défi en cours."

_on_user = on_user  # kept for modules importing it from here


def command(kinds: Mapping[str, Command], label: object) -> Command:
    """The command of a button labelled ``label`` (a browser may send any label: an
    unknown one becomes a :class:`Button` that the loop refuses once, in French)."""
    found = kinds.get(label) if isinstance(label, str) else None
    return found if found is not None else Button(label)


def bounds(low: float, high: float) -> tuple[tuple[float, str], ...]:
    """A slider's end marks, written with a decimal comma (viser writes ``0.005``)."""
    return ((low, number(low)), (high, number(high)))


def param_step(p: Param) -> float:
    """Slider step: the scene's own, else 1/200 of the range."""
    return p.step if p.step > 0 else (p.max - p.min) / 200.0


IMPOSED_HYPOTHESIS = (
    "Mouvement d'entrée imposé par le moteur : positions, vitesses et accélérations par "
    "les équations de fermeture, efforts par la dynamique inverse (rien n'est intégré)"
)
CLOSURE_HYPOTHESIS = "Fermeture de chaîne par contrainte d'égalité raide"
"""A free simulation's closure, which the imposed motion does not need (its loops are
closed by the closure equations themselves)."""


def parameter_hypotheses(params: Sequence[Param], values: Mapping[str, float]) -> list[str]:
    """The hypotheses the parameters set (:attr:`~sandbox.physics.spec.Param.hypothesis`),
    their values written as the page writes them; one whose value is 0 sets none."""
    lines = []
    for p in params:
        value = values.get(p.name, p.default)
        if p.hypothesis and value != 0:
            lines.append(p.hypothesis.format(with_unit(number(value, 4), p.display_unit)))
    return lines


def hypotheses(sim: ReadOnlySimulation) -> tuple[str, ...]:
    """Modelling hypotheses: the scene's effects, or what a user's file switches on."""
    scene = sim.scene
    if scene is not None:
        effects = scene.effects_at(sim.values).hypotheses()
        if sim.motion == IMPOSED:
            effects = (IMPOSED_HYPOTHESIS, *(h for h in effects if h != CLOSURE_HYPOTHESIS))
        return (*effects, *parameter_hypotheses(scene.params, sim.values))
    return file_hypotheses(sim.model)


def _seconds(t: float) -> str:
    """Simulated time as every view writes it (:func:`sandbox.written.time_words`)."""
    return time_words(t)


def speed_slider(gui: viser.GuiApi, hint: str) -> viser.GuiSliderHandle[float]:
    """The speed slider (×0,01 to ×4, 1: real time) of a live session or a replay."""
    return gui.add_slider(
        SPEED_LABEL,
        min=SPEEDS[0],
        max=SPEEDS[1],
        step=min(0.1, SPEEDS[0]),
        initial_value=1.0,
        marks=bounds(*SPEEDS),
        hint=hint,
    )


HYPOTHESES_FOLDER = "Hypothèses de modélisation"
"""The title of the folder of the modelling hypotheses."""


class ControlPanel:
    """Folders "Simulation" and "Paramètres", plus the divergence alert.

    Every control is a :class:`~sandbox.web.client.fields.Mirror` of the value in force:
    whatever changed it (the user, a lesson preset or step, a refusal, a reset, the
    teacher's settings), each refresh puts the controls back on the simulation's values.

    Args:
        gui: A viser ``GuiApi`` (``client.gui``).
        controller: The session's controller (requests go to its queue).
    """

    def __init__(self, gui: viser.GuiApi, controller: SessionState) -> None:
        self.controller = controller
        self._refusals = 0
        sim = controller.sim
        scene = sim.scene
        submit = controller.submit
        with gui.add_folder("Alerte", visible=False) as self.alert:
            self.alert_text = gui.add_markdown("")
            reset2 = gui.add_button("Réinitialiser", color="red")
        reset2.on_click(lambda _: submit(Reset()))
        with gui.add_folder("Simulation") as self.folder:
            self.title = gui.add_markdown(f"**{plain(scene.title if scene else sim.label)}**")
            self.status = gui.add_markdown("")
            self.commands = gui.add_button_group(
                "Temps",
                COMMANDS_PLAYING,
                hint="Pause ou lecture, un pas de temps dt, retour à l'état initial",
            )
            self.commands.on_click(lambda event: submit(command(COMMAND_KINDS, event.target.value)))
            self.speed = speed_slider(gui, "Temps simulé divisé par le temps réel (1 : temps réel)")
            on_user(self.speed, lambda v: submit(Speed(v)))
            self.record = gui.add_button_group(
                "Enregistrer",
                RECORD_IDLE,
                hint="Enregistre la séance pour la relire avec « sandbox replay » (fichier .sbx)",
            )
            self.record.on_click(lambda event: submit(command(RECORD_KINDS, event.target.value)))
            with gui.add_folder(NUMERICS_FOLDER, expand_by_default=False):
                self.motion: viser.GuiDropdownHandle[str] | None = None
                if len(sim.motions) > 1:
                    words = tuple(MOTION_WORDS[m] for m in sim.motions)
                    self.motion = gui.add_dropdown(
                        MOTION_LABEL,
                        words,
                        initial_value=MOTION_WORDS[sim.motion],
                        hint=MOTION_HINT,
                    )
                    on_user(self.motion, lambda v: submit(Motion(_motion_name(v))))
                labels = tuple(integrator_words(n) for n in INTEGRATORS)
                self.integrator = gui.add_dropdown(
                    INTEGRATOR_LABEL,
                    labels,
                    initial_value=integrator_words(_known(sim.integrator)),
                    hint=INTEGRATOR_HINT,
                )
                on_user(self.integrator, lambda v: submit(Integrator(integrator_name(v))))
                self._dt_hint = (
                    f"Pas de temps du calcul (de {number(MIN_TIMESTEP)} s à "
                    f"{number(sim.max_timestep)} s)"
                )
                self.timestep = gui.add_number(
                    TIMESTEP_LABEL, initial_value=sim.timestep, step=1e-5, hint=self._dt_hint
                )
                on_user(self.timestep, lambda v: submit(Timestep(v)))
        busy = self._busy
        self.mirrors: dict[str, Mirror] = {
            "<speed>": Mirror(self.speed, lambda: controller.speed, busy=busy),
            "<integrator>": Mirror(
                self.integrator, lambda: integrator_words(_known(sim.integrator)), busy=busy
            ),
            "<dt>": Mirror(self.timestep, lambda: sim.timestep, busy=busy),
        }
        if self.motion is not None:
            self.mirrors["<motion>"] = Mirror(
                self.motion, lambda: MOTION_WORDS[sim.motion], busy=busy
            )
        self.sliders: dict[str, viser.GuiInputHandle[Any]] = {}
        params = scene.params if scene is not None else ()
        self._params = {p.name: p for p in params}
        if params:
            with gui.add_folder(PARAMS_FOLDER) as self.params_folder:
                for p in params:
                    if not advanced(p):
                        self._control(gui, p)
                rare = [p for p in params if advanced(p)]
                if rare:
                    with gui.add_folder(ADVANCED_FOLDER, expand_by_default=False):
                        for p in rare:
                            self._control(gui, p)
        self._playing: bool | None = None
        self._exact: bool | None = None  # the motion imposed (integrator and dt disabled)
        self._recording = False
        self._concealed: dict[str, Mirror | None] = {}  # a challenge's controls, put aside

    def _busy(self) -> bool:
        """True while the user's requests wait for the loop (controls may be ahead)."""
        return self.controller.pending()

    def _control(self, gui: viser.GuiApi, p: Param) -> None:
        """A dropdown for a choice, a box for a typed number, else a slider."""
        if choices(p):
            self._choice(gui, p)
        elif typed(p):
            self._box(gui, p)
        else:
            self._slider(gui, p)

    def _choice(self, gui: viser.GuiApi, p: Param) -> None:
        """A parameter picking one of a few options: the dropdown shows their names and
        sends the option's number."""
        sim, submit = self.controller.sim, self.controller.submit
        names = choices(p)
        read = _reader(sim, p.name)

        def shown() -> str:
            index = int(round(read()))
            return names[index] if 0 <= index < len(names) else names[0]

        dropdown = gui.add_dropdown(
            param_label(p), names, initial_value=shown(), hint=param_hint(p)
        )
        name = p.name
        on_user(
            dropdown,
            lambda v: submit(SetValue(name, float(names.index(v)) if v in names else v)),
        )
        self.sliders[p.name] = dropdown
        self.mirrors[p.name] = Mirror(dropdown, shown, busy=self._busy)

    def _slider(self, gui: viser.GuiApi, p: Param) -> None:
        sim, submit = self.controller.sim, self.controller.submit
        slider = gui.add_slider(
            param_label(p),
            min=p.min,
            max=p.max,
            step=param_step(p),
            initial_value=sim.values[p.name],
            marks=bounds(p.min, p.max),
            hint=param_hint(p),
        )
        on_user(slider, _setter(submit, p.name))
        self.sliders[p.name] = slider
        self.mirrors[p.name] = Mirror(slider, _reader(sim, p.name), busy=self._busy)

    def _box(self, gui: viser.GuiApi, p: Param) -> None:
        """A rarely changed parameter: a text box in engineering notation (``2×10⁻⁴``),
        which takes any value of its range (a slider's steps cannot reach 0,0002)."""
        sim, submit = self.controller.sim, self.controller.submit
        box = gui.add_text(
            param_label(p),
            engineering(sim.values[p.name]),
            hint=param_hint(p) + " Écrivez par exemple 0,0002 ou 2e-4.",
        )
        name = p.name
        on_user(box, lambda v: submit(SetValue(name, parse_number(v))))
        self.sliders[p.name] = box
        read = _reader(sim, name)
        self.mirrors[p.name] = Mirror(box, lambda: engineering(float(read())), busy=self._busy)

    def refresh(self, time: float | None = None) -> None:
        """Status line, play/pause label, and every control on the value in force.

        Args:
            time: Simulated time of the instant the panels show (the drawn frame's);
                None: the physics state's.
        """
        ctl = self.controller
        state = "divergée" if ctl.diverged else ("en cours" if ctl.playing else "en pause")
        shown = ctl.sim.data.time if time is None else time
        status = f"t = {_seconds(shown)} s · vitesse ×{number(ctl.speed, 3)} · **{state}**"
        if ctl.playing and not ctl.diverged and ctl.slowed():
            status += " · plus lent que le temps réel (pas de temps trop petit pour ce poste)"
        recorder = ctl.recorder
        recording = recorder is not None
        if recorder is not None:
            status += f" · enregistrement en cours ({recorder.frames} images)"
        if self.status.content != status:
            self.status.content = status
        refused = ctl.refusals != self._refusals
        self._refusals = ctl.refusals
        if recording != self._recording:
            self.record.options = RECORD_BUSY if recording else RECORD_IDLE
            self._recording = recording
        if ctl.playing != self._playing:
            self.commands.options = COMMANDS_PLAYING if ctl.playing else COMMANDS_PAUSED
            self._playing = ctl.playing
        if bool(ctl.diverged) != self.alert.visible:
            self.alert.visible = bool(ctl.diverged)
            self.alert_text.content = ctl.diverged or ""
        for mirror in self.mirrors.values():
            mirror.refresh(force=refused)  # a refused value: the controls show the real ones
        exact = ctl.sim.motion == IMPOSED
        if exact != self._exact:  # nothing to integrate: the numerical method waits
            self._exact = exact
            for handle, hint in (
                (self.integrator, INTEGRATOR_HINT),
                (self.timestep, self._dt_hint),
            ):
                handle.disabled = exact
                handle.hint = EXACT_HINT if exact else hint

    def sync(self) -> None:
        """Put every control back to the simulation's actual values at once."""
        for mirror in self.mirrors.values():
            mirror.refresh(force=True)

    def conceal(self, hidden: Mapping[str, float], locked: Collection[str]) -> None:
        """A challenge: the controls of ``hidden`` parameters removed from the page and
        set to their stand-in value (a hidden control's value still reaches the browser:
        never the secret one), those of ``locked`` ones shown but disabled."""
        for name in {*hidden, *locked}:
            handle = self.sliders.get(name)
            if handle is None or name in self._concealed:
                continue
            self._concealed[name] = self.mirrors.pop(name, None)
            handle.disabled = True
            if name in hidden:
                handle.visible = False
                set_value(handle, float(hidden[name]))
            else:
                handle.hint = CHALLENGE_LOCKED

    def reveal(self) -> None:
        """The challenge is over: every control back, showing the values in force (the
        secret ones included: they are the solution)."""
        concealed, self._concealed = self._concealed, {}
        for name, mirror in concealed.items():
            handle = self.sliders[name]
            handle.disabled = False
            handle.visible = True
            p = self._params.get(name)
            if p is not None:
                handle.hint = param_hint(p)
            if mirror is not None:
                self.mirrors[name] = mirror
                mirror.refresh(force=True)


def _known(name: str) -> str:
    return name if name in INTEGRATORS else "euler"


def _motion_name(words: object) -> object:
    """The motion a dropdown's words name ("imposed", "free"), or the words themselves (a
    crafted value, which the simulation refuses in French)."""
    for name, text in MOTION_WORDS.items():
        if words == text:
            return name
    return words


def _reader(sim: ReadOnlySimulation, name: str) -> Callable[[], float]:
    return lambda: sim.values[name]


def _setter(submit: Callable[[Command], None], name: str) -> Callable[[Any], None]:
    return lambda value: submit(SetValue(name, value))


class HypothesesPanel:
    """Folder "Hypothèses de modélisation": effects simulated and numerical method."""

    def __init__(self, gui: viser.GuiApi, sim: ReadOnlySimulation) -> None:
        self.sim = sim
        with gui.add_folder(HYPOTHESES_FOLDER) as self.folder:
            self.text = gui.add_markdown(self._content())

    def _content(self) -> str:
        s = self.sim
        return tables.hypotheses_markdown(
            hypotheses(s),
            integrator=s.integrator,
            timestep=s.timestep,
            imposed=s.motion == IMPOSED,
        )

    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché »: the modelling words, which a challenge
        keeps (they give nothing away), refreshed even while diverged."""
        title = HYPOTHESES_FOLDER
        return [
            Folder(
                title, self.folder, lambda _: self.refresh(), secret_safe=True, needs_readouts=False
            )
        ]

    def refresh(self) -> None:
        """Follow integrator and timestep changes."""
        content = self._content()
        if content != self.text.content:
            self.text.content = content
