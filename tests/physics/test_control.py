"""A scene's per-step control (``Scene.control``): called before every ``mj_step`` for
the scenes that define one, never for the others (one batched ``mj_step`` call).

The model is a driven oscillator (inline MJCF): a mass m on a spring k and a damper c,
pushed by F(t) = F₀ sin(ω t) through an actuator whose ``ctrl`` the control sets. Its
motion from rest has a closed form, which the simulation must follow.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from sandbox.physics import simulation as simulation_module
from sandbox.physics.model import Source
from sandbox.physics.simulation import Simulation, step_model

M, K, C = 2.0, 200.0, 0.8  # kg, N/m, N·s/m: ω₀ = 10 rad/s, ζ = 0.02
F0, OMEGA = 3.0, 7.0  # N, rad/s
DT = 1e-3

MJCF = f"""
<mujoco model="driven_oscillator">
  <option timestep="{DT}" integrator="RK4" gravity="0 0 0"/>
  <worldbody>
    <body name="mass">
      <joint name="x" type="slide" axis="1 0 0" stiffness="{K}" damping="{C}"/>
      <inertial pos="0 0 0" mass="{M}" diaginertia="1 1 1"/>
      <geom type="box" size="0.1 0.1 0.1" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
  <actuator><motor name="push" joint="x" gear="1"/></actuator>
</mujoco>
"""


class _Effects:
    def disable_flags(self) -> int:
        return int(mujoco.mjtDisableBit.mjDSBL_GRAVITY | mujoco.mjtDisableBit.mjDSBL_CONTACT)


def push(model: mujoco.MjModel, data: mujoco.MjData, values: Mapping[str, float]) -> None:
    """F(t) = F₀ sin(ω t) at the middle of the coming step (a pure function of the time)."""
    data.ctrl[0] = F0 * math.sin(OMEGA * (data.time + 0.5 * model.opt.timestep))


@dataclass(frozen=True)
class _Spec:
    """The smallest scene spec physics accepts (see ``Scene``)."""

    control: Callable[..., None] | None = None
    name: str = "driven"
    mjcf: str = "driven.xml"
    integrator: str = "rk4"
    timestep: float = DT
    max_timestep: float = math.inf
    timestep_for: Callable[..., float] | None = None
    readouts: tuple[Any, ...] = ()
    edit: Callable[..., None] | None = None
    drive: Callable[..., None] | None = None
    initial_state: Callable[..., None] | None = None
    reference: Callable[..., dict[str, float]] | None = None
    imposed: Any = None

    @property
    def effects(self) -> _Effects:
        return _Effects()

    def effects_at(self, values: Any = None) -> _Effects:
        return _Effects()

    def control_at(self, values: Any) -> Callable[..., None] | None:
        return self.control

    def defaults(self) -> dict[str, float]:
        return {}

    def param(self, name: str) -> Any:
        raise KeyError(name)

    def default_timestep(self, values: Any = None, data: Any = None) -> float:
        return self.timestep


def _sim(tmp_path: Path, control: Callable[..., None] | None) -> Simulation:
    path = tmp_path / "driven.xml"
    path.write_text(MJCF)
    return Simulation(Source(_Spec(control=control), path))  # type: ignore[arg-type]


def closed_form(t: np.ndarray) -> np.ndarray:
    """x(t) of m ẍ + c ẋ + k x = F₀ sin(ω t) from rest: the steady oscillation X sin(ω t − φ)
    plus the free motion e^{−σ t}(A cos ω_d t + B sin ω_d t) that starts it at rest."""
    w0 = math.sqrt(K / M)
    sigma = C / (2 * M)
    wd = math.sqrt(w0**2 - sigma**2)
    x_amp = F0 / M / math.hypot(w0**2 - OMEGA**2, 2 * sigma * OMEGA)
    phi = math.atan2(2 * sigma * OMEGA, w0**2 - OMEGA**2)
    a = x_amp * math.sin(phi)
    b = (sigma * a - x_amp * OMEGA * math.cos(phi)) / wd
    steady = x_amp * np.sin(OMEGA * t - phi)
    return steady + np.exp(-sigma * t) * (a * np.cos(wd * t) + b * np.sin(wd * t))


def test_a_control_drives_the_oscillator_along_its_closed_form(tmp_path):
    """10 s (16 periods of the push, the transient down to e⁻² of its start): the position
    follows the closed form within 1e-5 of its amplitude (X = 29.4 mm at ω = 7 rad/s)."""
    sim = _sim(tmp_path, push)
    times, xs = [], []
    for _ in range(100):
        sim.step(100)
        times.append(sim.data.time)
        xs.append(float(sim.data.qpos[0]))
    ref = closed_form(np.array(times))
    x_amp = F0 / M / math.hypot(K / M - OMEGA**2, C / M * OMEGA)
    assert x_amp == pytest.approx(0.02937, rel=1e-3)
    assert np.max(np.abs(np.array(xs) - ref)) < 1e-5 * x_amp
    # without the control the motor stays at 0 and the mass at rest
    still = _sim(tmp_path, None)
    still.step(1000)
    assert still.data.qpos[0] == 0.0


def test_a_scene_without_control_steps_in_one_batched_call(tmp_path, monkeypatch):
    """The fake mj_step counts calls: no control, one call of 250 steps; with a control,
    250 calls of one step, the control called before each at the time of that step (and
    after the last, so that the state left carries its command)."""
    calls: list[tuple[int, ...]] = []
    real = mujoco.mj_step

    def counting(model: mujoco.MjModel, data: mujoco.MjData, *nstep: int) -> None:
        calls.append(tuple(nstep))
        real(model, data, *nstep)

    monkeypatch.setattr(simulation_module.mujoco, "mj_step", counting)
    plain = _sim(tmp_path, None)
    plain.step(250)
    assert calls == [(250,)]
    assert plain.data.time == pytest.approx(250 * DT)

    seen: list[float] = []

    def spy(model: mujoco.MjModel, data: mujoco.MjData, values: Mapping[str, float]) -> None:
        seen.append(float(data.time))
        push(model, data, values)

    driven = _sim(tmp_path, spy)
    seen.clear()  # the reset applies the control once at t = 0 (the state shown carries it)
    calls.clear()
    driven.step(250)
    assert calls == [()] * 250
    # before each step at its time, and once at the end for the state left (as at a reset)
    assert seen == pytest.approx([i * DT for i in range(251)], abs=1e-12)


def test_the_control_is_applied_at_reset_and_replays_bit_for_bit(tmp_path):
    """A pure control: after a reset the same steps give the same state, bit for bit;
    ``step_model`` (the loop every stepping place shares) gives it too."""
    sim = _sim(tmp_path, push)
    assert sim.data.ctrl[0] == pytest.approx(F0 * math.sin(OMEGA * 0.5 * DT))
    sim.step(1234)
    first = (sim.data.qpos.copy(), sim.data.qvel.copy(), sim.data.time)
    sim.reset()
    sim.step(1000)
    sim.step(234)
    assert np.array_equal(sim.data.qpos, first[0]) and np.array_equal(sim.data.qvel, first[1])
    assert sim.data.time == first[2]
    other = _sim(tmp_path, push)
    step_model(other.model, other.data, 1234, push, {})
    assert np.array_equal(other.data.qpos, first[0])
