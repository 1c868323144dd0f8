"""Isolating a solid: the actions on it sum to its dynamic torsor (PFD per solid)."""

from __future__ import annotations

import numpy as np
import pytest

from sandbox.physics import isolate
from sandbox.physics.simulation import Simulation


@pytest.mark.parametrize("target", ["compressor", "rotor"])
def test_actions_sum_to_the_dynamic_torsor_of_each_solid(target):
    sim = Simulation(target)
    sim.advance(0.003)
    sim.snapshot(["sup_R_x"])
    for solid in isolate.solids(sim.model):
        d = isolate.dynamic_torsor(sim.model, sim.data, solid)
        acts = isolate.actions(sim.model, sim.data, solid)
        r = sum(a.resultant for a in acts)
        m = sum(a.moment for a in acts)
        scale = max(np.abs(d.resultant).max(), 1.0)
        assert np.abs(r - d.resultant).max() < 1e-9 * scale
        assert np.abs(m - d.moment).max() < 1e-9 * scale


def test_piston_sees_the_frame_and_the_rod():
    """Course exercise: isolating the piston 3 shows the action of 0 (slide) and of 2."""
    sim = Simulation("compressor")
    sim.advance(0.002)
    sim.snapshot(["sup_R_x"])
    import mujoco

    piston = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, "piston")
    labels = [a.label for a in isolate.actions(sim.model, sim.data, piston)]
    assert labels == ["0 (bâti) → solide (glissière)", "rod → solide"]
    slide = isolate.actions(sim.model, sim.data, piston)[0]
    assert abs(slide.resultant[1]) < 1e-9 * np.abs(slide.resultant).max()  # no force along y0
