"""Folder "Isoler un solide": one column per component, numbers the French way."""

from __future__ import annotations

import math
import re

import mujoco
import numpy as np
import pytest

from sandbox.physics import isolate
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene, resolve
from sandbox.web.client.text import GAP
from sandbox.web.panels.isolate import isolate_markdown


def test_every_number_sits_in_its_own_column():
    """Issue 14: "73,23-72,95" ran together in the narrow panel."""
    sim = Simulation(get_scene("compressor"))
    sim.advance(0.05)
    scene = sim.scene
    assert scene is not None
    given = scene.page.names.solids
    assert isinstance(given, dict)
    names: dict[str, str] = given

    def relabel(text: str) -> str:
        for raw, shown in names.items():
            text = text.replace(raw, shown)
        return text

    for raw in ("crank", "rod", "piston"):
        body = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, raw)
        sim.snapshot(("sup_R_x", "dyn_R_x"))
        pfd = isolate.balance(sim.model, sim.data, body)
        md = isolate_markdown(pfd, label=relabel, zero=scene.zero)
        rows = [line for line in md.splitlines() if line.startswith("| ")]
        heads = [line for line in rows if line.startswith("| Action sur le solide")]
        assert len(heads) == 2 and "[N]" in heads[0] and "[N·m]" in heads[1]
        assert "R<sub>z₀</sub>" in heads[0] and "M<sub>G,z₀</sub>" in heads[1]
        for line in rows:
            if line in heads:
                continue
            cells = line.strip().strip("|").split("|")
            assert len(cells) == 4, line
            for value in cells[1:]:
                assert value.strip(" ").startswith(GAP), line
                assert re.fullmatch(
                    GAP + r"(−|-)?[\d\u202f]+(,\d+)?(×10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)?", value.strip(" ")
                ), value
        assert raw not in re.sub(r"<[^>]*>", "", md).replace(names[raw], "")
        assert not re.search(r"\d\.\d", md)
        assert "({𝒟}" not in md and "**{𝒟}** (somme des actions)" in md


def test_b1_at_o_and_a_gap_of_round_off_that_reads_0():
    """The rotor's frame action in the rotor's own basis B1 at O; the PFD's gap is
    round-off and reads 0, absolute and relative (issue 21: 3,2×10²⁸⁶ in the engine)."""
    import numpy as np

    for scene_name in ("rotor", "engine"):
        sim = Simulation(resolve(scene_name))
        sim.advance(0.05)
        scene = sim.scene
        assert scene is not None
        sim.snapshot(("sup_R_x", "dyn_R_x"))
        for body in isolate.solids(sim.model):
            pfd = isolate.balance(sim.model, sim.data, body, np.zeros(3))
            md = isolate_markdown(pfd, zero=scene.zero, point="O", basis="B1")
            assert "R<sub>x₁</sub>" in md and "M<sub>O,z₁</sub>" in md
            assert "liée au solide" in md
            last = md.splitlines()[-1]
            assert last.endswith("soit 0 de la plus grande action."), last
            assert "‖ΔR‖ = 0 N" in last, last


def test_a_component_five_decades_under_the_largest_reads_0():
    """The heavy top in steady precession: {𝒟} has no vertical resultant (the weight and
    the pivot's 9,81 N cancel) and no moment about z₀ at G; the integration leaves
    ~10⁻⁵ N and ~10⁻⁷ N·m there (0.5 ms), which read 0, while the 0,03 N horizontal {𝒟}
    (the centripetal m d sinθ ψ'²) keeps its digits."""
    import numpy as np

    sim = Simulation(get_scene("heavy_gyroscope"))
    sim.advance(1.0)
    scene = sim.scene
    assert scene is not None
    sim.snapshot(("sup_R_x", "dyn_R_x"))
    body = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, "rotor")
    pfd = isolate.balance(sim.model, sim.data, body)
    assert 0 < abs(pfd.dynamic.resultant[2]) < 1e-5 * 9.81  # really there, really tiny
    md = isolate_markdown(pfd, zero=scene.zero)
    d_rows = [line for line in md.splitlines() if line.startswith("| **{𝒟}**")]
    assert len(d_rows) == 2
    force, moment = ([c.strip(" " + GAP) for c in r.strip().strip("|").split("|")[1:]]
                     for r in d_rows)  # fmt: skip
    assert force[2] == "0" and moment[2] == "0", d_rows
    m, d = sim.values["mass"], sim.values["d"]
    horizontal = float(np.hypot(*pfd.dynamic.resultant[:2]))
    theta = math.radians(sim.values["tilt_deg"])
    psi_dot = sim.readouts()["precession_rate"]
    assert horizontal == pytest.approx(m * d * math.sin(theta) * psi_dot**2, rel=2e-2)
    assert force[0] != "0" and force[1] != "0"


@pytest.mark.parametrize("scene_name", ["compressor", "engine"])
def test_the_centre_of_mass_reads_0_where_the_closure_leaves_round_off(scene_name):
    """A teacher's trial read « G = (−0,003 ; −1,96×10⁻¹⁰ ; 0) m » for the compressor's
    crank: a coordinate a millionth of the largest is the loop closure's round-off and
    reads 0; the others keep their three digits."""
    import dataclasses

    sim = Simulation(resolve(scene_name))
    scene = sim.scene
    assert scene is not None
    crank = isolate.balance(sim.model, sim.data, isolate.solids(sim.model)[0])
    trial = dataclasses.replace(crank, centre=np.array([-0.003, -1.96e-10, 0.0]))
    line = isolate_markdown(trial, zero=scene.zero).splitlines()[0]
    assert line.startswith("G = (−0,003 ; 0 ; 0) m"), line
    for t in np.linspace(0.0, 0.05, 41):
        sim.advance(t - float(sim.data.time))
        sim.snapshot(forces=True)
        for body in isolate.solids(sim.model):
            pfd = isolate.balance(sim.model, sim.data, body)
            line = isolate_markdown(pfd, zero=scene.zero).splitlines()[0]
            centre = line[line.index("(") + 1 : line.index(")")]
            assert not re.search(r"×10⁻([6-9]|1\d)", centre), (body, t, line)
            if float(np.abs(pfd.centre).max()) > 1e-6:  # a real position keeps its digits
                assert any(c.strip() not in ("0", "−0") for c in centre.split(";")), line
