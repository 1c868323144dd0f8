"""Readout tables: torsors transported to the chosen point and basis, course gaps."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from sandbox.mechanics import rotation_matrix
from sandbox.physics.simulation import Simulation
from sandbox.web import tables


def _shown(markdown: str, key: str) -> float:
    match = re.search(rf'data-readout="{key}">([^<]*(?:<sup>[^<]*</sup>)?)<', markdown)
    assert match, key
    text = match.group(1).replace("·10<sup>", "e").replace("</sup>", "")
    return float(text)


def test_fmt_and_gap():
    assert tables.fmt(1234.5678) == "1235"
    assert tables.fmt(1.5e-7) == "1.5·10<sup>-7</sup>"
    assert tables.fmt(math.nan) == "—"
    assert tables.gap(101.0, 100.0) == "+1.00 %"
    assert tables.gap(1.0, 0.0) == "—"


def test_torsors_are_transported_and_projected():
    """M_P = M_O + PO ∧ R, then components in a rotated basis."""
    values = {f"{p}_{k}_{c}": 0.0 for p in ("kin", "dyn", "sup") for k in "RM" for c in "xyz"}
    values.update({"sup_R_y": 10.0, "sup_M_z": 1.0})
    point = np.array([0.5, 0.0, 0.0])
    md = tables.torsors_markdown(
        values, point=point, point_name="A", basis=np.eye(3), basis_name="B0", axes="xyz"
    )
    # M_A = M_O + AO ∧ R = (0,0,1) + (-0.5,0,0) ∧ (0,10,0) = (0, 0, 1 - 5)
    assert _shown(md, "shown_sup_M2") == pytest.approx(-4.0)
    assert _shown(md, "shown_sup_R1") == pytest.approx(10.0)
    basis = rotation_matrix([0, 0, 1], math.pi / 2)  # x1 = y0
    md = tables.torsors_markdown(
        values, point=point, point_name="A", basis=basis, basis_name="B1", axes="xyz"
    )
    assert _shown(md, "shown_sup_R0") == pytest.approx(10.0)
    assert _shown(md, "shown_sup_R1") == pytest.approx(0.0, abs=1e-9)


def test_scene_table_compares_with_the_course():
    sim = Simulation("rotor")
    sim.advance(0.1)
    values = sim.readouts()
    md = tables.scene_markdown(
        [(r.name, r.unit, r.doc) for r in sim.scene.readouts], values, sim.reference()
    )
    assert _shown(md, "bearing_A") == pytest.approx(values["bearing_A"], rel=1e-3)
    assert "+0.00 %" in md


def test_energy_table_closes_the_kinetic_energy_theorem():
    sim = Simulation("rotor")
    sim.advance(0.1)
    md = tables.energy_markdown(sim.readouts())
    assert abs(_shown(md, "P_frame")) < 1e-6 * max(1.0, abs(_shown(md, "P_ext")))


def test_untrusted_labels_are_escaped_in_every_table():
    """A file's names reach the tables: they are shown as text, never as HTML."""
    values = {f"{p}_{k}_{c}": 1.0 for p in ("kin", "dyn", "sup") for k in "RM" for c in "xyz"}
    md = tables.torsors_markdown(
        values,
        point=np.zeros(3),
        point_name="<script>x</script>",
        basis=np.eye(3),
        basis_name="<b>B</b>",
        axes="xyz",
    )
    assert "<script>" not in md and "<b>" not in md
    assert "Réduits en **&lt;script&gt;x&lt;/script&gt;**" in md
    assert "M<sub>&lt;script&gt;x&lt;/script&gt;</sub>" in md
    hyp = tables.hypotheses_markdown(
        ["<img src=x onerror=alert(1)>"], integrator="rk4", timestep=1e-3
    )
    assert hyp.splitlines()[0] == "- &lt;img src=x onerror=alert(1)&gt;"
    assert hyp.splitlines()[1] == "- Intégrateur **rk4**, pas de temps dt = 1 ms"
