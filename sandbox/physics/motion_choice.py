"""How a simulation computes its motion: the scene's imposed input motion, exactly, or the
free simulation (:class:`MotionChoice`, a part of
:class:`~sandbox.physics.simulation.Simulation`).

An imposed motion (:mod:`sandbox.physics.imposed`) is evaluated where the simulation
would step: at the end of each ``step`` call, for a drawn state at any time
(:meth:`MotionChoice.put_at`), and for a restored state (:meth:`MotionChoice.restore`,
from its own anchor and acceleration). Switching keeps the input's position and speed.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterable
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import BadOption, Diverged, shown
from sandbox.french import shown_value
from sandbox.mechanics.imposed import Anchor
from sandbox.physics import readouts as generic
from sandbox.physics.imposed import FREE, IMPOSED, MOTIONS, ImposedMotion
from sandbox.physics.spec import Scene


class MotionChoice:
    """The imposed-or-free part of a simulation. What it uses of the simulation is
    declared below; :class:`~sandbox.physics.simulation.Simulation` provides it."""

    scene: Scene | None
    values: dict[str, float]
    model: mujoco.MjModel
    data: mujoco.MjData
    lock: threading.RLock
    _timestep: float | None
    _wants_imposed: bool
    _imposed: ImposedMotion | None
    _fresh: tuple[object, ...] | None
    _warnings: int

    @property
    def label(self) -> str:
        raise NotImplementedError

    @property
    def timestep(self) -> float:
        raise NotImplementedError

    def _emit(self, kind: str, **fields: Any) -> None:
        raise NotImplementedError

    def _apply_drive(self) -> None:
        raise NotImplementedError

    def _warning_count(self) -> int:
        raise NotImplementedError

    @property
    def motions(self) -> tuple[str, ...]:
        """The ways this simulation can compute its motion: ``("imposed", "free")`` for a
        scene that declares an imposed motion (:attr:`Scene.imposed`), else ``("free",)``."""
        spec = self.scene.imposed if self.scene is not None else None
        return MOTIONS if spec is not None else (FREE,)

    @property
    def motion(self) -> str:
        """``"imposed"`` while the imposed motion is computed exactly, else ``"free"``."""
        return IMPOSED if self._imposed is not None else FREE

    @property
    def imposed(self) -> ImposedMotion | None:
        """The imposed motion in force (None: the motion is simulated)."""
        return self._imposed

    def check_motion(self, name: object) -> str:
        """``name`` checked as a way to compute the motion at the current values.

        Raises:
            BadOption: an unknown name, a scene without imposed motion, or values at which
                it cannot be imposed (a torque command...); English and, as ``french``,
                the page's words.
        """
        if name not in MOTIONS:
            raise BadOption(
                f"unknown motion {shown(name)}; choose one of: imposed, free",
                french=f"Mouvement « {shown_value(name)} » inconnu : imposé ou libre.",
            )
        if name == FREE:
            return FREE
        spec = self.scene.imposed if self.scene is not None else None
        if spec is None:
            raise BadOption(
                f"{shown(self.label)} has no imposed motion (its motion is what the simulation "
                "finds); use --motion free",
                french="Cette scène n'a pas de mouvement imposé : son mouvement est simulé.",
            )
        refusal = spec.refusal(self.values)
        if refusal is not None:
            english, french = refusal
            raise BadOption(f"{english}; use --motion free", french=french)
        return IMPOSED

    def set_motion(self, name: object) -> None:
        """Switch between the imposed motion and the free simulation, keeping the input's
        position and speed (and every other joint's, on the loop) continuous.

        Raises:
            BadOption: see :meth:`check_motion`.
        """
        wanted = self.check_motion(name)
        with self.lock:
            self._wants_imposed = wanted == IMPOSED
            if wanted == self.motion:
                return
            if wanted == IMPOSED:
                self._start_imposed()
            else:
                self._stop_imposed()
        self._emit("motion", value=wanted)

    def _imposed_allowed(self) -> bool:
        spec = self.scene.imposed if self.scene is not None else None
        return self._wants_imposed and spec is not None and spec.refusal(self.values) is None

    def _start_imposed(self, anchor: Anchor | None = None) -> None:
        """Compute the motion exactly from now on, from the current time, input position
        and speed (``anchor``: where to start from instead)."""
        assert self.scene is not None and self.scene.imposed is not None
        if self._imposed is None:
            self._imposed = ImposedMotion(self.scene.imposed, self.model)
        else:
            self._imposed.bind(self.model)
        self._imposed.start(self.data, anchor)
        self._put(float(self.data.time))

    def _stop_imposed(self) -> None:
        """Simulate from the current exact state on (its loops closed, its speeds on them;
        its acceleration stays as the solver's warm start), at the timestep the scene's
        default gives this motion (an imposed motion's only samples time: it does not
        follow the state)."""
        self._imposed = None
        self._fresh = None
        dt = self.timestep
        if self._timestep is None and self.scene is not None:
            dt = self.scene.default_timestep(self.values, self.data)
        if dt != self.timestep:
            self.model.opt.timestep = dt
            self._apply_drive()
            self._emit("timestep", value=dt)
        mujoco.mj_forward(self.model, self.data)
        self._warnings = self._warning_count()

    def _put(self, t: float, *, forces: bool = True) -> None:
        """The imposed state at time ``t`` in the simulation's data, with its forces
        (``forces`` False: positions, speeds, accelerations and poses only; the forces
        are computed when something reads them, :meth:`_prepare`)."""
        assert self._imposed is not None
        self._imposed.put(self.model, self.data, self.values, t, forces=forces)
        self._fresh = self._key(self.data) if forces else None

    def _key(self, data: mujoco.MjData) -> tuple[object, ...]:
        return (
            id(self.model), id(data), float(data.time), data.qpos.tobytes(),
            data.qvel.tobytes(), data.qacc_warmstart.tobytes(),
        )  # fmt: skip

    def _prepare(self, data: mujoco.MjData, names: Iterable[str], *, forces: bool = False) -> None:
        """Bring ``data``'s derived quantities up to date for the readouts ``names``: a
        forward pass of the free simulation, or the imposed motion's inverse dynamics
        (from the state's own acceleration; skipped when it is the state just computed)."""
        if self._imposed is None:
            generic.prepare(self.model, data, list(names), forces=forces)
            return
        key = self._key(data)
        if key != self._fresh:
            self._imposed.forces(self.model, data, self.values)
            self._fresh = key

    def put_at(self, data: mujoco.MjData, t: float, *, forces: bool = True) -> bool:
        """The imposed state at time ``t`` in ``data`` (another ``MjData`` of this model:
        the drawn state), with its forces (``forces`` False: positions and poses only);
        False (nothing done) when the motion is simulated."""
        with self.lock:
            if self._imposed is None:
                return False
            self._imposed.put(self.model, data, self.values, t, forces=forces)
            return True

    def restore(self, state: Any) -> None:
        """Set the simulation's data to a recorded integration state (``mjSTATE_INTEGRATION``)
        and bring its derived quantities up to date in the current way of computing the
        motion (an imposed state carries its acceleration, see :mod:`.imposed`)."""
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        with self.lock:
            mujoco.mj_setState(self.model, self.data, np.asarray(state, dtype=float), spec)
            if self._imposed is None:
                mujoco.mj_forward(self.model, self.data)
            else:
                self._prepare(self.data, ())

    def _step_imposed(self, nstep: int) -> None:
        """Advance the time by ``nstep`` timesteps and evaluate the imposed motion there:
        nothing is integrated, so the cost hardly depends on ``nstep`` and nothing
        drifts. The time is summed step by step as ``mj_step`` does, so that it is the
        same whatever the steps are grouped into, and after a restored state."""
        t, dt = float(self.data.time), self.timestep
        for _ in range(nstep):
            t += dt
        # placed only: a web frame draws another instant (the display's own exact state)
        # and reads the forces there; whatever reads this one's forces computes them then
        self._put(t, forces=False)
        d = self.data
        acc = d.qacc_warmstart
        if not math.isfinite(float(d.qpos.sum()) + float(d.qvel.sum()) + float(acc.sum())):
            raise Diverged(float(d.time), "NaN or Inf in the imposed motion")
