"""Every registered scene compiles, steps, stays finite and switches off unneeded effects."""

from __future__ import annotations

import math
import re

import mujoco
import numpy as np
import pytest

from sandbox.errors import BadParameter
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene, resolve


@pytest.mark.parametrize("name", sorted(SCENES))
def test_scene_compiles_steps_and_stays_finite(name):
    sim = Simulation(resolve(name))
    sim.advance(0.2)
    values = sim.readouts()
    assert all(math.isfinite(v) for v in values.values())
    assert set(sim.readout_names()) >= {r.name for r in SCENES[name].readouts}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_effects_not_called_for_are_off(name):
    scene = SCENES[name]
    flags = Simulation(resolve(name)).model.opt.disableflags
    assert bool(flags & mujoco.mjtDisableBit.mjDSBL_GRAVITY) == (not scene.effects.gravity)
    assert bool(flags & mujoco.mjtDisableBit.mjDSBL_CONTACT) == (not scene.effects.contacts)
    assert flags & mujoco.mjtDisableBit.mjDSBL_AUTORESET


UNITS = {
    "",  # dimensionless: a ratio (μ), a flag or a preset number
    "g", "kg", "m", "s", "deg", "rad", "rpm", "rad/s", "m/s", "m/s²",
    "N", "N·m", "W", "kg·m", "kg·m²", "kg·m²/s", "N·m·s/rad",
    "J", "N/m", "N·s/m", "Hz", "Pa", "kg/m³", "mm",
}  # fmt: skip
"""Units the scenes speak (course notation: middle dot, superscripts): a typo such as
"Nm", "kg.m2" or "rpm " fails here."""

SUFFIX_UNITS = {"_rpm": "rpm", "_deg": "deg", "_g": "g", "_s": "s"}
"""A parameter whose name ends with a unit carries that unit."""


def _check_doc(doc: str, what: str) -> None:
    """One sentence: non-empty, on one line, no stray spaces, ends with a period."""
    assert len(doc) >= 12 and doc == doc.strip() and "\n" not in doc, what
    assert doc.endswith("."), what


@pytest.mark.parametrize("name", sorted(SCENES))
def test_parameter_spec_is_consistent(name):
    """Every parameter: a usable contract name, a known unit (the one its name says), a
    one-sentence doc, a finite range holding its default with a slider step inside it,
    and a ``check`` that admits exactly that range."""
    params = SCENES[name].params
    names = [p.name for p in params]
    assert len(set(names)) == len(names), names
    for p in params:
        assert re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", p.name), p.name  # --set NAME=VALUE
        assert p.unit in UNITS, (p.name, p.unit)
        for suffix, unit in SUFFIX_UNITS.items():
            if p.name.endswith(suffix):
                assert p.unit == unit, (p.name, p.unit)
        _check_doc(p.doc, p.name)
        assert all(math.isfinite(x) for x in (p.min, p.default, p.max, p.step)), p.name
        assert p.min < p.max and p.min <= p.default <= p.max, p.name
        assert 0 < p.step <= p.max - p.min, p.name
        assert p.check(p.default) == p.default and p.check(str(p.max)) == p.max, p.name
        span = p.max - p.min
        for outside in (p.min - 1e-6 * span, p.max + 1e-6 * span, math.nan):
            with pytest.raises(BadParameter):
                p.check(outside)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_readout_spec_is_consistent(name):
    """Every scene readout: a unique name that no generic readout already takes, a known
    unit and a one-sentence doc."""
    from sandbox.physics.readouts import GENERIC_SET

    readouts = SCENES[name].readouts
    names = [r.name for r in readouts]
    assert len(set(names)) == len(names), names
    assert not set(names) & GENERIC_SET, set(names) & GENERIC_SET
    for r in readouts:
        assert re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", r.name), r.name  # a CSV column
        assert r.unit in UNITS, (r.name, r.unit)
        _check_doc(r.doc, r.name)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_param_extreme_compiles_or_is_refused_clearly(name):
    """Each extreme alone either runs or, when it contradicts another parameter (a rod
    shorter than the crank...), is refused with a one-line message naming the fix."""
    scene = SCENES[name]
    for p in scene.params:
        for value in (p.min, p.max):
            try:
                sim = Simulation(resolve(name), values={p.name: value})
            except BadParameter as exc:
                assert "\n" not in str(exc) and ("raise" in str(exc) or "lower" in str(exc))
                continue
            sim.step(5)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_default_timestep_is_declared_once_and_admitted(name):
    """``Scene.timestep`` is the default at the default parameters (a scene whose step
    follows its speed declares ``timestep_for``); every parameter's extremes give a step
    the scene accepts."""
    scene = SCENES[name]
    assert scene.default_timestep() == scene.timestep == Simulation(resolve(name)).timestep
    for p in scene.params:
        for value in (p.min, p.max):
            dt = scene.default_timestep({p.name: value})
            assert 0 < dt <= min(scene.max_timestep, 0.1), (p.name, value)


def test_physics_takes_a_spec_and_the_registry_is_passed_not_injected():
    """Physics never imports the scenes and keeps no registry: a name means a file there,
    and the error says where names are resolved; the scenes' :func:`resolve` passes the
    registry; loading the scenes changes nothing in physics (nothing is injected)."""
    import subprocess
    import sys

    script = (
        "import sys\n"
        "from sandbox.errors import UnknownScene\n"
        "from sandbox.physics import model\n"
        "from sandbox.physics.simulation import Simulation\n"
        "try:\n    Simulation('rotor')\nexcept UnknownScene as exc:\n    print(exc)\n"
        "assert 'sandbox.scenes' not in sys.modules\n"
        "from sandbox.scenes import SCENES, Source, get_scene, resolve\n"
        "assert Simulation(Source.of_scene(SCENES['rotor'])).label == 'rotor'\n"
        "assert resolve('rotor').scene is SCENES['rotor']\n"
        "assert Simulation(get_scene('rotor')).scene is SCENES['rotor']\n"
        "assert not hasattr(model, 'register_scenes')\n"
        "try:\n    Simulation('rotor')\nexcept UnknownScene as exc:\n    print(exc)\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert len(lines) == 2 and lines[0] == lines[1], lines  # the same before and after
    assert "sandbox.scenes.resolve" in lines[0]


@pytest.mark.parametrize("name", sorted(SCENES))
def test_a_variant_switches_off_what_it_does_not_call_for(name):
    """``Scene.effects_at`` (a variant's effects) stays within ``Scene.effects`` and is what
    the compiled model simulates: the wheel balancer's rigid bearings have no springs."""
    scene = SCENES[name]
    union = set(scene.effects.simulated())
    variants = [{}] + [{p.name: v} for p in scene.params for v in (p.min, p.max)]
    for values in variants:
        assert set(scene.effects_at(values).simulated()) <= union, values
    for values in variants[:3]:
        try:
            sim = Simulation(resolve(name), values=values)
        except BadParameter:
            continue
        flags = sim.model.opt.disableflags & ~int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
        assert flags == scene.effects_at(values).disable_flags(), values


def test_the_rigid_wheel_balancer_simulates_no_spring():
    scene = SCENES["wheel_balancer"]
    rigid, soft = scene.effects_at({"supports": 0}), scene.effects_at({"supports": 1})
    assert not rigid.springs and not rigid.joint_damping and soft.springs
    assert "Liaisons parfaites" in rigid.hypotheses()
    flags = Simulation(get_scene("wheel_balancer")).model.opt.disableflags
    assert flags & mujoco.mjtDisableBit.mjDSBL_SPRING and flags & mujoco.mjtDisableBit.mjDSBL_DAMPER


def test_a_kept_revolution_serves_within_the_speed_tolerance_and_goes_with_its_model():
    import gc

    from sandbox.scenes.revolutions import SPEED_TOLERANCE, PerModel

    kept: PerModel[str] = PerModel()
    sim = Simulation(get_scene("compressor"))
    model, values = sim.model, dict(sim.values)
    assert kept.get(model, values, 314.0) is None
    kept.put(model, values, 314.0, "one turn")
    assert kept.get(model, values, 314.0 * (1 + 0.5 * SPEED_TOLERANCE)) == "one turn"
    assert kept.get(model, values, 314.0 * (1 + 2 * SPEED_TOLERANCE)) is None
    assert kept.get(model, {**values, "R": values["R"] * 1.01}, 314.0) is None
    other = Simulation(get_scene("compressor")).model  # another session: its own revolution
    assert kept.get(other, values, 314.0) is None
    del sim, model
    gc.collect()
    assert len(kept._kept) == 0  # freed with its model


def test_a_revolution_simulated_while_the_motion_settles_is_simulated_again():
    """The engine's four cylinders cut to two: the new model spins up to its set point;
    the revolution simulated then leaks that transient (a first order of 0.2 N where the
    twin has none), so it is simulated once more a second later, and that one is kept."""
    from sandbox.scenes.engine import cycle as engine
    from sandbox.scenes.revolutions import SETTLE

    sim = Simulation(get_scene("engine"), motion="free")  # a revolution simulated ahead
    sim.advance(0.3)
    sim.set_value("cylinders", 2.0)
    sim.advance(0.05)
    misses = engine._REVOLUTIONS.misses
    sim.readouts(["shaking_force_h1"])  # provisional
    sim.advance(0.5 * SETTLE)
    sim.readouts(["shaking_force_h1"])
    assert engine._REVOLUTIONS.misses == misses + 1  # still the provisional one
    sim.advance(SETTLE)
    out = sim.readouts(["shaking_force_h1", "shaking_force_h2"])
    assert engine._REVOLUTIONS.misses == misses + 2  # simulated once more, settled
    for _ in range(5):
        sim.advance(0.5)
        again = sim.readouts(["shaking_force_h1"])
    assert engine._REVOLUTIONS.misses == misses + 2  # and kept
    assert again["shaking_force_h1"] == out["shaking_force_h1"]
    assert out["shaking_force_h1"] < 1e-3 * out["shaking_force_h2"]


def test_an_imposed_revolution_is_placed_once_for_every_session_at_the_same_values():
    """Thirty students at the lesson's values: the engine's exact revolution is placed at
    fixed angles, so the second session (another model, another crank angle) reads the
    first one's and computes none; other values, or another speed, place their own."""
    from sandbox.scenes.engine import cycle as engine

    engine._IMPOSED.clear()
    first, second = Simulation(get_scene("engine")), Simulation(get_scene("engine"))
    assert first.motion == "imposed" and second.motion == "imposed"
    second.advance(0.0123)  # another crank angle
    misses = engine._IMPOSED.misses
    a = first.readouts(["shaking_force_h1", "shaking_force_h2", "shaking_moment_max"])
    assert engine._IMPOSED.misses == misses + 1
    b = second.readouts(["shaking_force_h1", "shaking_force_h2", "shaking_moment_max"])
    assert engine._IMPOSED.misses == misses + 1  # shared, not placed again
    assert a == b
    rev = engine.revolution(first.snapshot())
    assert np.allclose(rev["angle_deg"], np.arange(64) * 360 / 64)  # fixed angles
    assert not rev["pilon"].flags.writeable  # shared: nobody may change it
    second.set_value("L", second.values["L"] * 1.1)
    second.readouts(["shaking_force_h1"])
    assert engine._IMPOSED.misses == misses + 2  # other values: their own
