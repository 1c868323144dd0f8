"""The picture of a frame, and its public twin: a hidden defect's shape never drawn."""

from __future__ import annotations

import random

import numpy as np
import pytest

from sandbox.challenges import CHALLENGES
from sandbox.physics.model import build
from sandbox.physics.picture import TwinMismatch, check_twin, geom_local_poses, picture
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene, resolve


def _twin(sim: Simulation, **public: float):
    twin = build(sim.source, {**sim.values, **public})
    check_twin(sim.model, twin)
    return twin


@pytest.mark.parametrize("skew", [3.0, -2.0])
def test_the_twin_draws_the_public_shapes_posed_by_the_simulated_motion(skew: float) -> None:
    """A rotor whose disk is tilted by a hidden angle: with a twin built at 0°, what is
    drawn (shapes, every body's pose) does not depend on the hidden angle, and the
    rotor's pose is the simulated one."""
    sim = Simulation(get_scene("rotor"), values={"skew_deg": skew, "defect_mass_g": 35.0})
    sim.advance(0.137)
    twin = _twin(sim, skew_deg=0.0, defect_mass_g=1.0)
    drawn = picture(sim.snapshot(), shown=twin)
    plain = picture(sim.snapshot())
    assert drawn.model is twin and plain.model is sim.model
    assert np.array_equal(drawn.roots, plain.roots)
    assert drawn.poses == pytest.approx(plain.poses, abs=1e-12)  # the motion is the same
    assert drawn.arrows == pytest.approx(plain.arrows, nan_ok=True)  # forces measured
    # the shapes: the twin's at any hidden angle, and the real ones differ from them
    untilted = Simulation(get_scene("rotor"), values={"skew_deg": 0.0, "defect_mass_g": 1.0})
    assert geom_local_poses(twin) == pytest.approx(geom_local_poses(untilted.model), abs=1e-12)
    assert not np.allclose(geom_local_poses(sim.model), geom_local_poses(twin), atol=1e-6)
    rotor = sim.model.body("rotor").id
    assert drawn.body_xquat[rotor] == pytest.approx(plain.body_xquat[rotor], abs=1e-12)


def test_the_wheel_s_tilted_tyre_is_drawn_straight() -> None:
    """The tyre is a body welded to the wheel, tilted by the hidden skew: the twin's
    welded pose is drawn (the real one would reach the browser in body_xquat)."""
    sim = Simulation(get_scene("wheel_balancer"), values={"skew_deg": 0.8, "skew_angle_deg": 70.0})
    sim.advance(0.05)
    twin = _twin(sim, skew_deg=0.0, defect_mass_g=0.0)
    tyre = sim.model.body("tyre").id
    drawn, plain = picture(sim.snapshot(), shown=twin), picture(sim.snapshot())
    assert drawn.poses == pytest.approx(plain.poses, abs=1e-12)
    assert not np.allclose(drawn.body_xquat[tyre], plain.body_xquat[tyre], atol=1e-4)
    straight = Simulation(get_scene("wheel_balancer"), values={"skew_deg": 0.0})
    straight.advance(0.05)
    assert drawn.body_xquat[tyre] == pytest.approx(
        picture(straight.snapshot()).body_xquat[tyre], abs=1e-9
    )


def test_a_twin_of_another_structure_is_refused() -> None:
    sim = Simulation(get_scene("wheel_balancer"))
    soft = build(sim.source, {**sim.values, "supports": 1.0})  # four more joints
    with pytest.raises(TwinMismatch, match="joints"):
        check_twin(sim.model, soft)
    assert get_scene("wheel_balancer").param("supports").choices  # a structural choice


@pytest.mark.parametrize("name", ["rotor_balance", "wheel_balance", "rotor_speed"])
def test_a_challenge_s_twin_draws_the_same_whatever_was_drawn(name: str) -> None:
    """Two students, two secrets: the shapes and every body's pose they are sent are the
    same (the secrets' stand-ins), while the simulated machines differ."""
    c = CHALLENGES[name]
    base = {**get_scene(c.scene).defaults(), **dict(c.fixed)}
    drawn = []
    for seed in (1, 2):
        sim = Simulation(resolve(c.scene), values={**base, **c.draw(base, random.Random(seed))})
        sim.advance(0.05)
        twin = _twin(sim, **c.public())
        drawn.append((sim, picture(sim.snapshot(), shown=twin)))
    (sim_a, a), (sim_b, b) = drawn
    assert geom_local_poses(a.model) == pytest.approx(geom_local_poses(b.model), abs=1e-12)
    assert a.body_xquat == pytest.approx(b.body_xquat, abs=1e-9)
    assert a.body_xpos == pytest.approx(b.body_xpos, abs=1e-9)
    assert not np.allclose(geom_local_poses(sim_a.model), geom_local_poses(sim_b.model))
