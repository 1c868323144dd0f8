"""Simulation: MjData stepping in C, parameter changes, divergence guard, readouts."""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

import mujoco

from sandbox.errors import BadOption, Diverged, UnknownParameter, shown
from sandbox.french import number, shown_value
from sandbox.mechanics.imposed import Anchor
from sandbox.physics import readouts as generic
from sandbox.physics.imposed import IMPOSED, ImposedMotion
from sandbox.physics.limits import MAX_TIMESTEP, MIN_TIMESTEP, check_timestep
from sandbox.physics.model import (
    Source,
    build,
    check_integrator,
    integrator_name,
    model_xml,
    resolve,
)
from sandbox.physics.motion_choice import MotionChoice
from sandbox.physics.readouts import ReadoutInfo
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import Scene
from sandbox.physics.stepping import finite as finite  # re-exported
from sandbox.physics.stepping import step_model

ENERGIES = frozenset({"T", "P_ext", "P_int", "P_acc"})
"""Generic readouts a scene's ``mechanism`` may correct."""

SETTLE_STEPS = 50
"""Steps at the fine timestep before a state-dependent default may grow again (ten of
the compressor's closure time constants)."""

_BAD_WARNINGS = (
    (mujoco.mjtWarning.mjWARN_BADQACC, "bad acceleration (BADQACC)"),
    (mujoco.mjtWarning.mjWARN_BADQVEL, "bad velocity (BADQVEL)"),
    (mujoco.mjtWarning.mjWARN_BADQPOS, "bad position (BADQPOS)"),
)
_BAD_CODES = tuple(int(w) for w, _ in _BAD_WARNINGS)


class Simulation(MotionChoice):
    """One MuJoCo simulation of a scene or MJCF file.

    Args:
        target: A scene's spec, an already resolved :class:`Source`, or an MJCF path (a
            scene's *name* is resolved above physics: :func:`sandbox.scenes.resolve`).
        values: Parameter values overriding the scene's defaults (validated).
        integrator: Integrator name overriding the scene's or file's own.
        timestep: Timestep [s] overriding the scene's or file's own.
        motion: ``"imposed"``: the scene's imposed input motion computed exactly
            (closure equations and inverse dynamics, nothing integrated); ``"free"``: the
            motion simulated by MuJoCo; None: the scene's default (:attr:`motions`).

    ``lock`` serialises access when a web session steps while a GUI callback queues.
    """

    def __init__(
        self,
        target: Scene | Source | str | Path,
        *,
        values: Mapping[str, object] | None = None,
        integrator: str | None = None,
        timestep: float | None = None,
        motion: str | None = None,
    ) -> None:
        self.source = (
            target
            if isinstance(target, Source)
            else Source.of_scene(target)
            if isinstance(target, Scene)
            else resolve(target)
        )
        self.scene = self.source.scene
        self.values: dict[str, float] = self.scene.defaults() if self.scene else {}
        for name, value in (values or {}).items():
            self.values[name] = self.check_value(name, value)
        self._integrator = None if integrator is None else check_integrator(integrator)
        self._timestep = None if timestep is None else self.check_timestep(timestep)
        self.lock = threading.RLock()
        self._settled_at: float | None = None  # see _follow_state
        spec = self.scene.imposed if self.scene is not None else None
        self._wants_imposed = motion == IMPOSED or (
            motion is None and spec is not None and spec.default
        )
        if motion is not None:
            self.check_motion(motion)
        self._imposed: ImposedMotion | None = None
        self._fresh: tuple[object, ...] | None = None  # the imposed state last evaluated
        self.observers: list[Callable[[str, dict[str, Any]], None]] = []
        """Called with (kind, fields) after a reset or a change (recordings use it)."""
        self.model = self._compile()
        self.data = mujoco.MjData(self.model)
        self.reset()

    # -- construction -------------------------------------------------------------------
    def check_value(self, name: object, value: object) -> float:
        """``value`` checked for parameter ``name``, nothing changed: what
        :meth:`set_value` would take (a link or a study checks its values before use).

        Raises:
            UnknownParameter, BadParameter: in English and, as ``french``, the page's words.
        """
        if self.scene is None:
            raise UnknownParameter(
                f"{shown(self.source.label)} is an MJCF file and has no parameter {shown(name)}; "
                "parameters exist only for registered scenes (see 'sandbox list')",
                french=f"Paramètre « {shown_value(name)} » inconnu (un fichier MJCF n'en a aucun).",
            )
        return self.scene.param(name).check(value)

    def _compile(self) -> mujoco.MjModel:
        model = build(self.source, self.values, own_timestep=self._timestep is None)
        if self._integrator is not None:
            model.opt.integrator = self._integrator
        if self._timestep is not None:
            model.opt.timestep = self._timestep
        return model

    @property
    def label(self) -> str:
        """Scene name or file name."""
        return self.source.label

    @property
    def integrator(self) -> str:
        """Current integrator name."""
        return integrator_name(self.model)

    @property
    def timestep(self) -> float:
        """Current timestep [s]."""
        return float(self.model.opt.timestep)

    @property
    def timestep_chosen(self) -> bool:
        """True once a timestep was asked for (constructor or :meth:`set_timestep`); False
        while the scene's default for the parameters is in force."""
        return self._timestep is not None

    # -- state --------------------------------------------------------------------------
    def reset(self) -> None:
        """Back to the initial state: scene initial state, else the file's first keyframe."""
        with self.lock:
            mujoco.mj_resetData(self.model, self.data)
            if self.scene is None and self.model.nkey > 0:
                mujoco.mj_resetDataKeyframe(self.model, self.data, 0)
            self._apply_drive()
            if self.scene is not None and self.scene.initial_state is not None:
                self.scene.initial_state(self.model, self.data, self.values)
                self._apply_control()  # the command of the initial state
            mujoco.mj_forward(self.model, self.data)
            self._warnings = self._warning_count()
            if self._imposed_allowed():
                self._start_imposed()
            else:
                self._imposed = None
        self._emit("reset")

    def _emit(self, kind: str, **fields: Any) -> None:
        for observer in list(self.observers):
            observer(kind, fields)

    def mjcf(self) -> str:
        """MJCF text of the current model (a file's own text, or the edited scene)."""
        return model_xml(self.source, self.values)

    def _apply_drive(self) -> None:
        if self.scene is not None and self.scene.drive is not None:
            self.scene.drive(self.model, self.data, self.values)
        self._apply_control()

    def _apply_control(self) -> None:
        """The scene's per-step command at the current state (readouts between two steps
        then show the command the next step applies)."""
        control = self.scene.control_at(self.values) if self.scene is not None else None
        if control is not None:
            control(self.model, self.data, self.values)

    def set_value(self, name: str, value: object) -> float:
        """Change a parameter; non-live ones rebuild the model and keep the motion going.

        A scene whose default timestep depends on the parameters (``Scene.timestep_for``,
        e.g. the compressor's speed) gets its new default at once, unless the user chose a
        timestep; observers then also see a ``timestep`` change (a replay repeats it).

        Returns:
            The validated value.

        Raises:
            UnknownParameter, BadParameter: the change is refused, nothing is modified.
        """
        number = self.check_value(name, value)
        with self.lock:
            old, old_dt = self.values[name], self.timestep
            was = self.motion
            before = None
            if self._imposed is not None:
                before = Anchor(float(self.data.time), *self._imposed.input(self.data))
            self.values[name] = number
            if self.scene is not None and self.scene.param(name).live:
                self.model.opt.timestep = self._next_dt(old_dt)
                self._apply_drive()  # after the timestep: a drive may tune gains to it
            else:
                try:
                    model = self._compile()
                except Exception:
                    self.values[name] = old
                    raise
                self._swap_model(model)
                if self._next_dt(old_dt) != self.timestep:  # the running motion's step
                    self.model.opt.timestep = self._next_dt(old_dt)
                    self._apply_drive()
            if self._imposed_allowed():
                self._start_imposed(before)  # the law from here, with the new values
            elif self._imposed is not None:
                self._stop_imposed()  # these values cannot be imposed: simulated from here
        self._emit("set", name=name, value=number)
        if self.timestep != old_dt:
            self._emit("timestep", value=self.timestep)
        if self.motion != was:
            self._emit("motion", value=self.motion)
        return number

    def _next_dt(self, old_dt: float) -> float:
        """Timestep after a parameter change: the user's if any; else a scene default that
        follows the parameters shrinks at once and grows only later, in :meth:`step`, once
        the motion has settled (:meth:`_follow_state`); else the model's own."""
        if self._timestep is not None:
            return self._timestep
        if self.scene is None or self.scene.timestep_for is None:
            return self.timestep
        if self._imposed is not None:  # exact at any step: the new values' own, at once
            return self.scene.default_timestep(self.values)
        return min(old_dt, self.scene.default_timestep(self.values, self.data))

    def _follow_state(self) -> None:
        """Re-apply a state-dependent default timestep after stepping: it shrinks as soon as
        the motion needs it, and grows back only once the motion has been the one the
        parameters ask for during :data:`SETTLE_STEPS` steps (a crank braked to a lower set
        point within a few steps leaves a loop violation behind: a step growing at once
        lets it open 6x wider than at the fine step)."""
        if self._timestep is not None or self.scene is None or self.scene.timestep_for is None:
            return
        now = float(self.model.opt.timestep)
        dt = self.scene.default_timestep(self.values, self.data)
        if dt > now:
            t = float(self.data.time)
            if dt != self.scene.default_timestep(self.values):
                self._settled_at = None  # still faster than asked
                return
            if self._settled_at is None:
                self._settled_at = t
            if t - self._settled_at < SETTLE_STEPS * now * (1 - 1e-9):
                return
        self._settled_at = None
        if dt != now:
            self.model.opt.timestep = dt
            self._apply_drive()
            self._emit("timestep", value=dt)

    def _swap_model(self, model: mujoco.MjModel) -> None:
        old_model, old = self.model, self.data
        data = mujoco.MjData(model)
        data.time = old.time
        if model.nq == old_model.nq and model.nv == old_model.nv:
            data.qpos[:] = old.qpos
            data.qvel[:] = old.qvel
            data.act[: min(model.na, old_model.na)] = old.act[: min(model.na, old_model.na)]
            n = min(model.nuserdata, old_model.nuserdata)  # a scene's stored state
            data.userdata[:n] = old.userdata[:n]
        self.model, self.data = model, data
        self._apply_drive()
        mujoco.mj_forward(model, data)
        self._warnings = self._warning_count()

    def set_integrator(self, name: object) -> None:
        """Switch integrator live (no rebuild); BadOption naming the valid ones."""
        code = check_integrator(name)
        with self.lock:
            self._integrator = code
            self.model.opt.integrator = code
            self._apply_drive()  # a drive may tune gains to the integrator
        self._emit("integrator", value=name)

    @property
    def max_timestep(self) -> float:
        """Largest timestep [s] this simulation accepts (the scene's own bound, if any)."""
        limit = self.scene.max_timestep if self.scene is not None else math.inf
        return min(MAX_TIMESTEP, limit)

    def _timestep_words(self, value: object) -> str:
        given = number(value, 3) if isinstance(value, float) else shown_value(value)
        return (
            f"Pas de temps dt = {given} s refusé : choisissez un pas entre "
            f"{number(MIN_TIMESTEP, 3)} s et {number(self.max_timestep, 3)} s."
        )

    def check_timestep(self, value: object) -> float:
        """``value`` checked as this simulation's timestep [s], nothing changed.

        Raises:
            BadOption: in English and, as ``french``, the page's words (the range).
        """
        try:
            dt = check_timestep(value)  # type: ignore[arg-type]
        except BadOption as exc:
            raise BadOption(str(exc), french=self._timestep_words(value)) from None
        if dt > self.max_timestep:
            raise BadOption(
                f"timestep {value!r} s is too large for {self.scene.name!r} (max "  # type: ignore[union-attr]
                f"{self.max_timestep:g} s: beyond it the results drift from the course); try "
                f"--timestep {self.scene.timestep:g}",  # type: ignore[union-attr]
                french=self._timestep_words(value),
            )
        return dt

    def set_timestep(self, value: float) -> None:
        """Switch timestep live (no rebuild)."""
        dt = self.check_timestep(value)
        with self.lock:
            self._timestep = dt
            self.model.opt.timestep = dt
            self._apply_drive()  # a drive may tune gains to the timestep
        self._emit("timestep", value=dt)

    # -- stepping -----------------------------------------------------------------------
    def _warning_count(self) -> int:
        warning = self.data.warning
        return sum([warning[w].number for w in _BAD_CODES])

    def step(self, nstep: int = 1) -> None:
        """Advance ``nstep`` timesteps, then check for divergence.

        One batched ``mj_step`` call in C, or for a scene with a per-step ``control`` a
        Python loop calling it before each ``mj_step`` (:func:`step_model`).

        Raises:
            Diverged: NaN/Inf in the state or a MuJoCo bad-state warning.
        """
        if nstep <= 0:
            return
        with self.lock:
            if self._imposed is not None:
                self._step_imposed(nstep)
                return
            control = self.scene.control_at(self.values) if self.scene is not None else None
            step_model(self.model, self.data, nstep, control, self.values)
            self._guard()
            self._follow_state()

    def _guard(self) -> None:
        d = self.data
        if self._warning_count() > self._warnings:
            for w, text in _BAD_WARNINGS:
                if d.warning[w].number:
                    raise Diverged(float(d.time), text)
        # one sum each: NaN and infinities carry through it (a finite state summing past
        # 1e308 would be diverged anyway)
        if not math.isfinite(float(d.qpos.sum()) + float(d.qvel.sum())):
            raise Diverged(float(d.time), "NaN or Inf in the state")

    def advance(self, duration: float) -> None:
        """Step for ``duration`` seconds (rounded to whole timesteps).

        Raises:
            BadOption: ``duration`` is not a finite number of seconds, zero or more.
        """
        if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration >= 0):
            raise BadOption(f"a duration must be a finite number of seconds >= 0, got {duration!r}")
        self.step(int(round(duration / self.timestep)))

    # -- readouts -----------------------------------------------------------------------
    def readout_infos(self) -> list[ReadoutInfo]:
        """Every readout available: the generic ones, then the scene's."""
        return list(self._readout_table()[0])

    def readout_names(self) -> list[str]:
        """Names of :meth:`readout_infos`, in column order."""
        return list(self._readout_table()[1])

    def _readout_table(
        self,
    ) -> tuple[tuple[ReadoutInfo, ...], tuple[str, ...], dict[str, Callable[[Snapshot], float]]]:
        """(infos, names, scene functions by name): fixed for a simulation, built once."""
        imposed = self._imposed is not None
        tables = self.__dict__.setdefault("_tables", {})
        table = tables.get(imposed)
        if table is None:
            infos = [
                ReadoutInfo(r.name, r.unit, r.doc, r.label, r.hint)
                for r in generic.GENERIC_READOUTS
            ]
            fns: dict[str, Callable[[Snapshot], float]] = {}
            if self.scene is not None:
                infos += [
                    ReadoutInfo(
                        r.name,
                        r.unit,
                        r.doc,
                        (getattr(r, "imposed_label", "") if imposed else "") or r.label,
                        (getattr(r, "imposed_hint", "") if imposed else "") or r.hint,
                    )
                    for r in self.scene.readouts
                ]
                fns = {r.name: r.fn for r in self.scene.readouts}
            table = tables[imposed] = (tuple(infos), tuple(i.name for i in infos), fns)
        return table

    def snapshot(
        self, names: Iterable[str] = generic.GENERIC_NAMES, *, forces: bool = False
    ) -> Snapshot:
        """Bring derived quantities up to date for ``names`` (and the forces, when
        ``forces`` is set: what arrows and scene readouts read) and wrap them in a
        snapshot.

        The solver warm start is restored afterwards, so reading never changes the
        trajectory (a replay re-simulates bit for bit whatever the display rate).
        """
        if self._imposed is not None:
            self._prepare(self.data, names, forces=forces)
            return Snapshot(self.model, self.data, self.values, imposed=self._imposed)
        warm = self.data.qacc_warmstart.copy()
        generic.prepare(self.model, self.data, list(names), forces=forces)
        self.data.qacc_warmstart[:] = warm
        return Snapshot(self.model, self.data, self.values)

    def readouts(
        self,
        names: Iterable[str] | None = None,
        *,
        data: mujoco.MjData | None = None,
        snapshot: Snapshot | None = None,
    ) -> dict[str, float]:
        """Values of the requested readouts (all when ``names`` is None).

        Args:
            names: Readout names (None: every readout).
            data: Another state of this model to read instead of the simulation's own
                (the web page's display state, between two physics steps); its derived
                quantities are brought up to date here.
            snapshot: A state already brought up to date for these readouts (and for
                the forces, ``forces=True``, when scene readouts are asked): read
                as it is, sharing its cached torsors with whatever else read it (a drawn
                frame's arrows).

        Raises:
            KeyError: an unknown name (the message lists the valid ones).
        """
        _, all_names, scene_fns = self._readout_table()
        wanted = list(all_names) if names is None else list(names)
        known = generic.GENERIC_SET
        unknown = [n for n in wanted if n not in scene_fns and n not in known]
        if unknown:
            raise KeyError(
                f"unknown readout {unknown[0]!r}; valid: {', '.join(self.readout_names())}"
            )
        with self.lock:
            needs = [n for n in wanted if n in known]
            forces = len(needs) < len(wanted)  # scene readouts may use any torsor
            if snapshot is not None:
                snap = snapshot
            elif data is None:
                snap = self.snapshot(needs, forces=forces)
            else:
                self._prepare(data, needs, forces=forces)
                snap = Snapshot(self.model, data, self.values, imposed=self._imposed)
            out = generic.compute(
                self.model, snap.data, [n for n in wanted if n not in scene_fns], snap.cache
            )
            mechanism = getattr(self.scene, "mechanism", None)
            if mechanism is not None and not ENERGIES.isdisjoint(out):
                mechanism(snap, out)
            for name in wanted:
                if name in scene_fns:
                    out[name] = float(scene_fns[name](snap))
        return {name: out[name] for name in wanted}

    def reference(self) -> dict[str, float]:
        """Closed-form values from the course for the current parameters ({} if none)."""
        if self.scene is None or self.scene.reference is None:
            return {}
        return self.scene.reference(self.values)
