"""Frozen dataclasses describing a scene: parameters, effects, readouts, arrows, reference.

A scene is one MJCF file in the top-level ``scenes/`` folder plus a :class:`Scene` spec.
The spec is the single source of truth used by the CLI (``describe``, ``--set``), the web
UI (sliders, panels), the lessons and the tests. These records are plain data of the
physics layer: physics takes a :class:`Scene` as it is (no protocol to cast it back
from), and each scene module of :mod:`sandbox.scenes` fills one.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from sandbox import french
from sandbox.errors import BadParameter, UnknownParameter, choices, shown
from sandbox.physics.imposed import Imposed
from sandbox.physics.page import Page
from sandbox.physics.units import display_unit

if TYPE_CHECKING:
    from sandbox.physics.snapshot import Snapshot

Values = Mapping[str, float]

TIMESTEP_MANTISSAS = (1.0, 1.5, 2.0, 3.0, 5.0, 7.0)
"""Leading digits of the timesteps :func:`per_revolution_timestep` picks (readable values
that whole-millisecond sampling intervals mostly divide)."""


def per_revolution_timestep(angle: float, omega: float, *, largest: float) -> float:
    """Largest readable timestep [s] that turns by at most ``angle`` [rad] per step at
    ``omega`` [rad/s], and at most ``largest`` [s].

    For a scene whose error depends on the angle turned per step (ω dt) rather than on dt,
    the accuracy per revolution is then at least the one measured at the speed that
    defines ``angle``. The value is rounded down to a mantissa of
    :data:`TIMESTEP_MANTISSAS` (e.g. 5.67e-4 s -> 5e-4 s).
    """
    if omega == 0 or not math.isfinite(omega) or angle / abs(omega) >= largest:
        return float(largest)
    dt = angle / abs(omega) * (1.0 + 1e-9)  # ω_max dt_ref itself gives dt_ref back
    exponent = math.floor(math.log10(dt))
    mantissa = dt / 10.0**exponent
    digit = max([m for m in TIMESTEP_MANTISSAS if m <= mantissa * (1.0 + 1e-12)] or [1.0])
    return float(f"{digit:g}e{exponent}")


@dataclass(frozen=True)
class Param:
    """One scene parameter: a number with a unit, a default and an allowed range.

    Attributes:
        name: Contract name used by ``--set NAME=VALUE``, the UI and lessons.
        unit: Unit shown to the user ("" when dimensionless).
        default: Default value, inside ``[min, max]``.
        min: Smallest allowed value (inclusive).
        max: Largest allowed value (inclusive).
        doc: One sentence saying what the parameter is.
        live: True when a change needs no model rebuild (e.g. a motor set point).
        step: Suggested slider step in the web UI (0 means range/200).
        label: What the web page shows: French words with the course's symbol, e.g.
            "Vitesse de rotation ω" (the unit is added by the page; "" shows ``name``).
        hint: French tooltip of the web page: one sentence ("" shows ``doc``).
        group: French name of the folder the web page files it under (e.g. "Géométrie"):
            folders in the order of their first parameter, parameters in their order.
        advanced: Rarely changed (inertias, a drawing length): the page folds it away.
        log: The range spans decades (e.g. 1e-6 to 2e-2 kg·m²): a linear slider cannot
            reach the useful values, so the page offers a number box in engineering
            notation instead.
        choices: French names of the values 0, 1, 2... of a parameter that picks one of
            a few options (a preset, on/off): the page shows a dropdown or a checkbox.
        hypothesis: A modelling hypothesis this parameter sets, in French, with ``{}``
            where its value goes (with its unit): « Hypothèses de modélisation » lists it,
            so that a parameter folded away that changes a headline number (the motor
            rotor's inertia in T and P_ext) is in sight ("": none).
    """

    name: str
    unit: str
    default: float
    min: float
    max: float
    doc: str
    live: bool = False
    step: float = 0.0
    label: str = ""
    hint: str = ""
    group: str = ""
    advanced: bool = False
    log: bool = False
    choices: tuple[str, ...] = ()
    hypothesis: str = ""

    @property
    def display_unit(self) -> str:
        """The unit as the web page shows it ("tr/min" for "rpm", "°" for "deg")."""
        return display_unit(self.unit)

    @property
    def integer(self) -> bool:
        """Whole values only: one of a few options (``choices``). A count with gaps (the
        engine's 1, 2 or 4 cylinders) is checked by its scene, which names the values."""
        return bool(self.choices)

    @property
    def words(self) -> str:
        """The parameter as the page names it: its French label, else its name."""
        return self.label or self.name

    def _allowed(self) -> str:
        if self.choices:
            first = ", ".join(str(i) for i in range(len(self.choices) - 1))
            return f"{first} or {len(self.choices) - 1} (see 'sandbox describe')"
        return f"a value between {self.min:g} and {self.max:g} {self.display_unit}".rstrip()

    def _french(self, value: object) -> str:
        """The refusal of ``value`` in the page's words (one sentence, decimal comma)."""
        unit = self.display_unit
        unit = unit if unit in ("", "°") else f" {unit}"
        numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
        shown = french.shown_number(value)
        given = f"{shown}{unit}" if numeric and math.isfinite(value) else f"« {shown} »"  # type: ignore[arg-type]
        if self.choices:
            options = " ; ".join(f"{i} ({c})" for i, c in enumerate(self.choices))
            return f"{self.words} : {given} refusé, choisissez parmi {options}."
        low, high = french.number(self.min, 6), french.number(self.max, 6)
        return f"{self.words} : {given} refusé, choisissez entre {low} et {high}{unit}."

    def check(self, value: object) -> float:
        """Validate ``value`` (number or numeric string) and return it as a float.

        A string must be written in ASCII digits (Python's float() would also read
        fullwidth or Arabic-Indic digits, underscores and "nan") and be short (a browser
        may send a megabyte); a whole-valued parameter (:attr:`integer`) refuses fractions
        rather than rounding them. The one check of a value, for the command line and the
        page alike: the refusal speaks English and, as ``french``, the page's words.

        Raises:
            BadParameter: if it is not a finite number, lies outside ``[min, max]``, or
                is a fraction of a whole-valued parameter; the message names the
                allowed values.
        """
        text = value.strip() if isinstance(value, str) else None
        try:
            if isinstance(value, bool) or (
                text is not None and (not text.isascii() or "_" in text or len(text) > 64)
            ):
                raise ValueError(value)
            number = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError, OverflowError):
            raise BadParameter(
                f"parameter {self.name!r} needs a number written with the digits 0-9, "
                f"got {_said(value)}; give {self._allowed()}",
                french=self._french(value),
            ) from None
        if not math.isfinite(number) or not (self.min <= number <= self.max):
            span = f"{self.min:g} to {self.max:g} {self.display_unit}".rstrip()
            raise BadParameter(
                f"parameter {self.name!r} = {_said(value)} is out of range; "
                f"allowed: {self._allowed() if self.choices else span}",
                french=self._french(value),
            )
        if self.integer and number != int(number):
            raise BadParameter(
                f"parameter {self.name!r} takes whole values, got {_said(value)}; "
                f"give {self._allowed()}",
                french=self._french(value),
            )
        return number


def _said(value: object) -> str:
    """``repr`` of a value in an English refusal, cut when a browser sent a long text."""
    return shown(value) if isinstance(value, str) else repr(value)


@dataclass(frozen=True)
class Effects:
    """The physical effects a scene calls for; every other one is switched off in MuJoCo.

    Each False field sets the matching ``mjDSBL_*`` flag so that MuJoCo neither computes
    nor applies the effect (e.g. no contact -> no collision detection at all).
    """

    gravity: bool = False
    contacts: bool = False
    equality: bool = False
    limits: bool = False
    joint_damping: bool = False
    joint_friction: bool = False
    springs: bool = False
    actuation: bool = True

    def disable_flags(self) -> int:
        """Bit mask of MuJoCo disable flags for the effects not called for, and for
        island discovery (a speed-up of large models' solver, pure overhead for the
        course's mechanisms: the compressor steps 15 % faster without it)."""
        off = {
            "gravity": mujoco.mjtDisableBit.mjDSBL_GRAVITY,
            "contacts": mujoco.mjtDisableBit.mjDSBL_CONTACT,
            "equality": mujoco.mjtDisableBit.mjDSBL_EQUALITY,
            "limits": mujoco.mjtDisableBit.mjDSBL_LIMIT,
            "joint_damping": mujoco.mjtDisableBit.mjDSBL_DAMPER,
            "joint_friction": mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS,
            "springs": mujoco.mjtDisableBit.mjDSBL_SPRING,
            "actuation": mujoco.mjtDisableBit.mjDSBL_ACTUATION,
        }
        mask = int(mujoco.mjtDisableBit.mjDSBL_ISLAND)
        for name, bit in off.items():
            if not getattr(self, name):
                mask |= int(bit)
        return mask

    def simulated(self) -> tuple[str, ...]:
        """Names of the effects that are on."""
        return tuple(k for k, v in self.__dict__.items() if v)

    def hypotheses(self) -> tuple[str, ...]:
        """The modelling hypotheses in the course's words (French), one line each."""
        lines = []
        lines.append("Pesanteur prise en compte" if self.gravity else WEIGHT_NEGLECTED)
        lines.append("Contacts simulés (lois de Coulomb)" if self.contacts else NO_CONTACT)
        if self.equality:
            lines.append("Fermeture de chaîne par contrainte d'égalité raide")
        if self.joint_damping:
            lines.append("Frottement visqueux dans certaines liaisons (voir les paramètres)")
        elif not self.joint_friction:
            lines.append("Liaisons parfaites")
        if self.joint_friction:
            lines.append("Frottement sec dans les paliers : couple Cf selon leur charge")
        if self.springs:
            lines.append("Ressorts dans les liaisons")
        lines.append(GALILEAN)
        return tuple(lines)


WEIGHT_NEGLECTED = "Poids négligé"
NO_CONTACT = "Pas de contact entre solides"
GALILEAN = "Référentiel terrestre supposé galiléen"


def file_hypotheses(model: mujoco.MjModel) -> tuple[str, ...]:
    """The modelling hypotheses of a user's MJCF file (its own options kept), in the same
    words as a scene's (:meth:`Effects.hypotheses`)."""
    flags = int(model.opt.disableflags)
    off = mujoco.mjtDisableBit
    g = float(np.linalg.norm(model.opt.gravity))
    weightless = bool(flags & off.mjDSBL_GRAVITY) or g == 0
    return (
        "Fichier MJCF : options du fichier conservées",
        WEIGHT_NEGLECTED
        if weightless
        else f"Pesanteur prise en compte (g = {french.number(g, 3)} m/s²)",
        NO_CONTACT
        if flags & off.mjDSBL_CONTACT
        else "Contacts simulés si les géométries se touchent",
        GALILEAN,
    )


@dataclass(frozen=True)
class SceneReadout:
    """A readout specific to a scene: a pure function of a :class:`Snapshot`.

    Attributes:
        name: Contract name (CSV column, UI label).
        unit: Unit of the value.
        doc: One sentence saying what it measures.
        fn: Computes the value from a snapshot of the simulation.
        label: What the web page shows: French words with the course's symbol, e.g.
            "Effort du palier A" ("" shows ``name``).
        hint: French tooltip of the web page: one sentence ("" shows ``doc``).
        imposed_label: The label while the motion is imposed, when the readout then
            means something else in words (a motor's torque becomes the torque it must
            give: « Couple nécessaire »); "" keeps ``label``.
        imposed_hint: The tooltip while the motion is imposed ("" keeps ``hint``).
    """

    name: str
    unit: str
    doc: str
    fn: Callable[[Snapshot], float]
    label: str = ""
    hint: str = ""
    imposed_label: str = ""
    imposed_hint: str = ""

    @property
    def display_unit(self) -> str:
        """The unit as the web page shows it ("tr/min" for "rpm", "°" for "deg")."""
        return display_unit(self.unit)


Series = Mapping[str, np.ndarray]
"""Readouts sampled during a benchmark run: name -> values over time."""


@dataclass(frozen=True)
class Accuracy:
    """How ``sandbox bench`` measures a scene against the course.

    Attributes:
        key: The key quantity compared with the closed form (a readout name).
        readouts: Readouts sampled during a run (``time`` is always added).
        duration: Simulated time of one run [s].
        error: Relative error of the key quantity against the course's closed form.
        invariant: What the scene conserves, in words (e.g. "T + V").
        drift: Relative drift of that invariant over the run (or the energy-theorem
            residual relative to the peak power).
        constraint: Largest constraint violation [m] over the run, where there is one.
        values: Parameter values of the benchmark (defaults otherwise).
        rate: Samples per simulated second.
        timesteps: The grid's timesteps [s] (two decades, the default among them);
            empty means 0.1, 0.3, 1, 3 and 10 times the default.
        settle: Samples before this time [s] are ignored (start-up transient).
        drift_tol: Runs whose drift exceeds this are not admissible on the Pareto front
            (e.g. a closure that drains the energy theorem).
        constraint_tol: Same for the constraint violation [m].
        same_angle: The default timestep is an angle of the input per step (the crank's:
            the errors depend on ω·dt alone), so a setting is measured on the test at the
            same angle per step as on the page (the page's 500 µs at 3000 tr/min is the
            test's 100 µs at 17,000 tr/min), not at the same timestep.
    """

    key: str
    readouts: tuple[str, ...]
    duration: float
    error: Callable[[Series, Values], float]
    invariant: str
    drift: Callable[[Series, Values], float]
    constraint: Callable[[Series, Values], float] | None = None
    values: Mapping[str, float] = field(default_factory=dict)
    rate: float = 200.0
    timesteps: tuple[float, ...] = ()
    settle: float = 0.0
    drift_tol: float = math.inf
    constraint_tol: float = math.inf
    same_angle: bool = False


@dataclass(frozen=True)
class Scene:
    """A registered scene: MJCF file plus everything the course says about it.

    Attributes:
        name: Registry key (``sandbox run NAME``).
        title: Title shown to users.
        summary: Two or three sentences on what the scene shows.
        mjcf: File name inside the top-level ``scenes/`` folder.
        params: Parameters in display order.
        effects: Effects simulated; all others are switched off. With ``effects_for``,
            every effect the scene may call for (their union).
        effects_for: The effects at given parameter values when a variant calls for fewer
            (the wheel balancer's rigid bearings need no springs, its soft bench does);
            None: always ``effects``. What it returns must be within ``effects``.
        readouts: Scene readouts, added to the generic ones.
        edit: Applies the non-live parameters to the MjSpec before compiling.
        drive: Applies live parameters (motor set points) to ``data.ctrl``.
        control: Per-step command, called before every ``mj_step`` (and after ``drive``,
            ``initial_state`` and the last step of a ``Simulation.step`` call, so that the
            state shown carries the command of its own time) for a command that varies
            in time (a back-and-forth move, a sinusoidal torque). It must be a pure
            function of (model, data, values): ``data.time`` and the state (``qpos``,
            ``qvel``, ``act``; derived quantities may be stale), no Python state
            of its own, so that a reset, a replay or a recording re-simulates the same
            motion. A scene with a control is stepped in a Python loop, one ``mj_step`` per
            timestep; every other scene in one batched ``mj_step(model, data, nstep)``.
        control_when: The parameter values at which the control acts (None: always);
            elsewhere the scene is stepped in one batched call, as without a control
            (the bearings' friction, off by default, costs nothing while it is off).
        initial_state: Sets a consistent initial qpos/qvel after reset.
        reference: Closed-form values of some readouts from the course.
        mechanism: Turns the generic energy readouts the simulation computed (``T``,
            ``P_ext``, ``P_int``, ``P_acc``: those present in the dict it is given, changed
            in place) into the mechanism's, where the model stands in for it another way
            (the robot axis simulates its reducer's efficiency by scaling the motor's side:
            its true T does not depend on the efficiency, its P_int has the loss). Called
            with the snapshot the values were read from. None: the model is the mechanism.
        integrator: Default integrator name.
        timestep: Default timestep [s] (at the default parameters when ``timestep_for``
            is given).
        timestep_for: Default timestep [s] as a function of the parameters and, when
            given, of the current state (``data``; None: the state the parameters start
            from), for scenes whose accuracy is set per revolution (e.g. the compressor:
            dt shrinks as the speed grows, and stays small while a crank still turning
            faster than a new, lower set point slows down). A
            :class:`~sandbox.physics.simulation.Simulation` applies it at construction,
            after every parameter change and after every call of ``step`` (a smaller step
            at once, a larger one after 50 steps of settled motion), unless the user chose
            a timestep (``--timestep``, the web app's field), which always overrides it.
        sections: Course sections the scene illustrates.
        solutions: Exercise solutions a lesson step names as ``@name``: parameter values
            -> the values that solve it (e.g. the rotor's balancing masses).
        accuracy: What ``sandbox bench`` compares with the course, and the invariant.
        run_ended: The run is over (the rolling cylinder past the plane's end): the web
            page starts it again a moment later, so that an open page keeps showing the
            motion (a pure function of the model, the state and the values).
        max_timestep: Larger timesteps are refused: they stay stable but silently lose the
            accuracy the scene promises (e.g. a contact that softens).
        cycle: Curves over one cycle (e.g. a crank revolution): "angle_deg" and readouts
            simulated over the cycle, plus their "<name>_ref" course values.
        zero: Round-off of the scene by unit (contract unit -> absolute value in that
            unit): the page shows a number whose magnitude is at most this as 0 (e.g. a
            bearing force of 6e-12 N where the course says 0). Far below anything the
            scene computes on purpose (a closure error of 1e-8 m stays visible).
        page: What the page shows of the scene (:class:`~sandbox.physics.page.Page`:
            plots, arrows, camera, names, presets, diagrams); the simulation reads none
            of it.
        imposed: The input motion the course imposes (a crank at constant speed, a
            speed profile), computed exactly by the closure equations and inverse
            dynamics instead of simulated (:class:`~sandbox.physics.imposed.Imposed`);
            None: the motion is always simulated.
    """

    name: str
    title: str
    summary: str
    mjcf: str
    params: tuple[Param, ...]
    effects: Effects
    readouts: tuple[SceneReadout, ...] = ()
    edit: Callable[[mujoco.MjSpec, Values], None] | None = None
    drive: Callable[[mujoco.MjModel, mujoco.MjData, Values], None] | None = None
    control: Callable[[mujoco.MjModel, mujoco.MjData, Values], None] | None = None
    control_when: Callable[[Values], bool] | None = None
    initial_state: Callable[[mujoco.MjModel, mujoco.MjData, Values], None] | None = None
    reference: Callable[[Values], dict[str, float]] | None = None
    mechanism: Callable[[Snapshot, dict[str, float]], None] | None = None
    integrator: str = "rk4"
    timestep: float = 1e-3
    timestep_for: Callable[[Values, mujoco.MjData | None], float] | None = None
    sections: str = ""
    solutions: Mapping[str, Callable[[Values], Mapping[str, float]]] = field(default_factory=dict)
    accuracy: Accuracy | None = None
    max_timestep: float = math.inf
    run_ended: Callable[[mujoco.MjModel, mujoco.MjData, Values], bool] | None = None
    cycle: Callable[[Snapshot], Mapping[str, np.ndarray]] | None = None
    zero: Mapping[str, float] = field(default_factory=dict)
    effects_for: Callable[[Values], Effects] | None = None
    page: Page = field(default_factory=Page)
    imposed: Imposed | None = None

    def control_at(
        self, values: Values
    ) -> Callable[[mujoco.MjModel, mujoco.MjData, Values], None] | None:
        """The per-step control at ``values`` (None: batched stepping)."""
        if self.control is None or (
            self.control_when is not None and not self.control_when(values)
        ):
            return None
        return self.control

    def effects_at(self, values: Values | None = None) -> Effects:
        """The effects simulated at ``values`` (missing ones at their defaults)."""
        if self.effects_for is None:
            return self.effects
        return self.effects_for({**self.defaults(), **(values or {})})

    def zero_for(self, unit: str) -> float:
        """Round-off [``unit``] below which the page shows 0 (0.0: every digit shown)."""
        return float(self.zero.get(unit, 0.0))

    def param(self, name: object) -> Param:
        """The parameter called ``name``.

        Raises:
            UnknownParameter: naming the valid parameters.
        """
        for p in self.params:
            if p.name == name:
                return p
        valid = choices(p.name for p in self.params) or "none (this model has no parameters)"
        among = " ; ".join(p.words for p in self.params)
        raise UnknownParameter(
            f"scene {self.name!r} has no parameter {shown(name)}; valid parameters: {valid}",
            french=f"Paramètre « {french.shown_value(name)} » inconnu (parmi : {among}).",
        )

    def defaults(self) -> dict[str, float]:
        """Default value of every parameter (a new dict: the caller may change it)."""
        return dict(self._defaults)

    @functools.cached_property
    def _defaults(self) -> dict[str, float]:
        """The defaults, built once (a session asks for them after every frame's steps)."""
        return {p.name: p.default for p in self.params}

    def default_timestep(
        self, values: Values | None = None, data: mujoco.MjData | None = None
    ) -> float:
        """Default timestep [s] for ``values`` (missing ones at their defaults) and, if
        given, the current state ``data``."""
        if self.timestep_for is None:
            return self.timestep
        return float(self.timestep_for({**self._defaults, **(values or {})}, data))
