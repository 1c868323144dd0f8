"""Folder "Isoler un solide": one column per component, numbers the French way."""

from __future__ import annotations

import re

import mujoco

from sandbox.physics import isolate
from sandbox.physics.simulation import Simulation
from sandbox.scenes.base import as_scene
from sandbox.web.isolate_panel import GAP, isolate_markdown


def test_every_number_sits_in_its_own_column():
    """Issue 14: "73,23-72,95" ran together in the narrow panel."""
    sim = Simulation("compressor")
    sim.advance(0.05)
    scene = as_scene(sim.scene)
    assert scene is not None
    given = scene.extra["solid_names"]
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
        assert "[N]" in rows[0] and "[N·m]" in rows[0]
        for line in rows[1:]:
            cells = line.strip().strip("|").split("|")
            assert len(cells) == 5, line
            for value in cells[1:]:
                assert value.strip(" ").startswith(GAP), line
                assert re.fullmatch(
                    r"\u2002(−|-)?[\d\u202f]+(,\d+)?(×10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)?", value.strip(" ")
                ), value
        assert raw not in re.sub(r"<[^>]*>", "", md).replace(names[raw], "")
        assert not re.search(r"\d\.\d", md)
        assert "({𝒟}" not in md and "**{𝒟}** (somme des actions)" in md
