"""Every registered scene compiles, steps, stays finite and switches off unneeded effects."""

from __future__ import annotations

import math

import mujoco
import pytest

from sandbox.errors import BadParameter
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES


@pytest.mark.parametrize("name", sorted(SCENES))
def test_scene_compiles_steps_and_stays_finite(name):
    sim = Simulation(name)
    sim.advance(0.2)
    values = sim.readouts()
    assert all(math.isfinite(v) for v in values.values())
    assert set(sim.readout_names()) >= {r.name for r in SCENES[name].readouts}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_effects_not_called_for_are_off(name):
    scene = SCENES[name]
    flags = Simulation(name).model.opt.disableflags
    assert bool(flags & mujoco.mjtDisableBit.mjDSBL_GRAVITY) == (not scene.effects.gravity)
    assert bool(flags & mujoco.mjtDisableBit.mjDSBL_CONTACT) == (not scene.effects.contacts)
    assert flags & mujoco.mjtDisableBit.mjDSBL_AUTORESET


@pytest.mark.parametrize("name", sorted(SCENES))
def test_parameter_spec_is_consistent(name):
    for p in SCENES[name].params:
        assert p.min <= p.default <= p.max, p.name
        assert p.doc and p.unit is not None


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_param_extreme_compiles_or_is_refused_clearly(name):
    """Each extreme alone either runs or, when it contradicts another parameter (a rod
    shorter than the crank...), is refused with a one-line message naming the fix."""
    scene = SCENES[name]
    for p in scene.params:
        for value in (p.min, p.max):
            try:
                sim = Simulation(name, values={p.name: value})
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
    assert scene.default_timestep() == scene.timestep == Simulation(name).timestep
    for p in scene.params:
        for value in (p.min, p.max):
            dt = scene.default_timestep({p.name: value})
            assert 0 < dt <= min(scene.max_timestep, 0.1), (p.name, value)


def test_the_registry_passes_itself_down_to_physics():
    """Physics never imports the scenes: it takes a spec, and knows the names only once
    the registry is loaded (every entry point loads it); without it the error says so."""
    import subprocess
    import sys

    script = (
        "import sys\n"
        "from sandbox.errors import UnknownScene\n"
        "from sandbox.physics.simulation import Simulation\n"
        "try:\n    Simulation('rotor')\nexcept UnknownScene as exc:\n    print(exc)\n"
        "assert 'sandbox.scenes' not in sys.modules\n"
        "from sandbox.scenes import SCENES, Source, resolve\n"
        "assert Simulation(Source.of_scene(SCENES['rotor'])).label == 'rotor'\n"
        "assert resolve('rotor').scene is SCENES['rotor'] and Simulation('rotor').scene\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "import sandbox.scenes" in out.stdout
