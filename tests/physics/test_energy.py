"""The kinetic-energy theorem's remainder: the power of the frame's reactions."""

from __future__ import annotations

import math

import pytest

from sandbox.physics.energy import frame_power
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene


def test_frame_power_by_hand():
    assert frame_power({"P_acc": 5.0, "P_ext": 7.0, "P_int": -2.5}) == pytest.approx(0.5)
    assert math.isnan(frame_power({"P_acc": 5.0, "P_ext": 7.0}))


def test_perfect_fixed_joints_do_no_work():
    sim = Simulation(get_scene("rotor"))
    sim.advance(0.1)
    values = sim.readouts()
    assert abs(frame_power(values)) < 1e-6 * max(1.0, abs(values["P_ext"]))
