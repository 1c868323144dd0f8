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


def test_balance_reduces_everything_at_g_and_closes_the_pfd():
    """The panel's numbers: G, {D} and the actions moved to G (M_G = M_O + R ∧ OG), and
    the PFD's relative residual."""
    sim = Simulation("compressor")
    sim.advance(0.002)
    sim.snapshot(["sup_R_x"])
    for solid in isolate.solids(sim.model):
        b = isolate.balance(sim.model, sim.data, solid)
        members = isolate.members(sim.model, solid)
        mass = sim.model.body_mass[members]
        g = (mass[:, None] * sim.data.xipos[members]).sum(0) / mass.sum()
        assert np.allclose(b.centre, g)
        d = isolate.dynamic_torsor(sim.model, sim.data, solid)
        assert np.allclose(b.dynamic.moment, d.moment + np.cross(d.resultant, g))
        acts = isolate.actions(sim.model, sim.data, solid)
        assert [a.label for a in b.actions] == [a.label for a in acts]
        assert np.allclose(b.actions[0].moment, acts[0].moment + np.cross(acts[0].resultant, g))
        assert b.residual < 1e-9


def test_pfd_residual_by_hand():
    d = isolate.Action("{D}", np.array([3.0, 4.0, 0.0]), np.zeros(3))
    acts = [
        isolate.Action("a", np.array([1.0, 0.0, 0.0]), np.zeros(3)),
        isolate.Action("b", np.array([2.0, 4.0, 5.0]), np.zeros(3)),
    ]
    assert isolate.pfd_residual(d, acts) == pytest.approx(1.0)  # |(0, 0, 5)| / |(3, 4, 0)|
    assert isolate.pfd_residual(d, []) == pytest.approx(1.0)
