"""Readout tables: torsors transported to the chosen point and basis, course gaps."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from sandbox.mechanics import rotation_matrix
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene, resolve
from sandbox.web.panels import tables

SUPERSCRIPTS = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")


def _shown(markdown: str, key: str) -> float:
    """The number a reader sees in a readout cell, read back the French way; it must
    agree with the exact value the cell carries for scripts (``data-value``)."""
    match = re.search(rf'data-readout="{key}" data-value="([^"]*)">([^<]*)<', markdown)
    assert match, key
    text = match.group(2).replace("\u202f", "").replace(",", ".").replace("−", "-")
    mantissa, _, power = text.partition("×10")
    shown = float(mantissa) * 10.0 ** int(power.translate(SUPERSCRIPTS) or 0)
    exact = float(match.group(1))
    assert shown == pytest.approx(exact, rel=1e-3) or shown == 0.0
    return shown


def test_fmt_and_gap():
    assert tables.fmt(1234.5678) == "1\u202f235"
    assert tables.fmt(0.5) == "0,5"
    assert tables.fmt(1.5e-7) == "1,5×10⁻⁷"
    assert tables.fmt(1.959e-19, floor=1e-9) == "0"
    assert tables.fmt(math.nan) == "—"
    assert tables.gap(101.0, 100.0) == "+1,00\u202f%"
    assert tables.gap(99.0, 100.0) == "−1,00\u202f%"
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
    sim = Simulation(get_scene("rotor"))
    sim.advance(0.1)
    values = sim.readouts()
    md = tables.scene_markdown(
        [(r.name, r.unit, r.doc) for r in sim.scene.readouts], values, sim.reference()
    )
    assert _shown(md, "bearing_A") == pytest.approx(values["bearing_A"], rel=1e-3)
    assert "+0,00\u202f%" in md


def test_energy_table_closes_the_kinetic_energy_theorem():
    sim = Simulation(get_scene("rotor"))
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
    assert hyp.splitlines()[1] == "- Intégrateur **Runge-Kutta 4**, pas de temps dt = 1 ms"
    # a timestep is written as « Précision et coût » writes it: « 200 µs », not « 0,2 ms »
    hyp = tables.hypotheses_markdown([], integrator="rk4", timestep=2e-4)
    assert hyp.splitlines()[-1].endswith("dt = 200 µs")


CODE_NAME = re.compile(r"\b[a-z]+_[a-zA-Z0-9_]+\b")
"""A snake_case identifier (speed_rpm, bearing_A, mass1_g): a code name."""


def _visible(markdown: str) -> str:
    """What a reader sees: the markdown without HTML tags and attributes."""
    return re.sub(r"<[^>]*>", "", markdown)


@pytest.mark.parametrize(
    "scene", ["rotor", "compressor", "rolling_cylinder", "gyroscope", "heavy_gyroscope"]
)
def test_scene_table_speaks_french_with_a_decimal_comma(scene):
    """Labels (or names while a scene has none), French units, decimal comma, no
    raw HTML cut by a ``|`` (the rolling cylinder's ``|Tt| / N`` tooltip did)."""

    sim = Simulation(resolve(scene))
    sim.advance(0.05)
    spec = sim.scene
    rows = [
        tables.Row(r.name, r.unit, r.doc, r.label, r.hint, spec.zero_for(r.unit))
        for r in spec.readouts
    ]
    md = tables.scene_markdown(rows, sim.readouts(), sim.reference())
    lines = md.splitlines()
    body = [line for line in lines if line.startswith("| ") and "data-readout" in line]
    assert len(body) == len(rows)
    for line, row in zip(body, rows, strict=True):
        cells = line.strip("|").split("|")
        assert len(cells) == 4, f"a | cut the row of {row.name}: {line}"
        first = cells[0]
        assert first.count("<span") == first.count("</span>") == 1
        if row.label:
            assert _visible(first).strip().startswith(row.label.split("|")[0].strip()[:8])
        assert "rpm" not in _visible(first) and "[deg]" not in _visible(first)
        if row.hint:
            assert f'title="{tables.cell(row.hint)}"' in first
    visible = _visible(md)
    assert not re.search(r"\d\.\d", visible), visible
    labelled = [row.name for row in rows if row.label and "_" in row.name]
    for name in labelled:
        assert not re.search(rf"\b{re.escape(name)}\b", visible), name
    if all(row.label for row in rows):
        assert not CODE_NAME.search(visible), CODE_NAME.findall(visible)


def test_round_off_is_shown_as_zero():
    """A bearing force of 1,959×10⁻¹⁹ N where the course says 0 reads 0."""
    rows = [tables.Row("bearing_A", "N", "", "Effort du palier A", "", 1e-9)]
    md = tables.scene_markdown(rows, {"bearing_A": 1.959e-19}, {"bearing_A": 0.0})
    assert _shown(md, "bearing_A") == 0.0
    assert "10⁻¹⁹" not in md and "Effort du palier A</span> [N]" in md
    values = {f"{p}_{k}_{c}": 0.0 for p in ("kin", "dyn", "sup") for k in "RM" for c in "xyz"}
    values.update({"sup_R_y": 3e-10, "sup_M_z": 2.0})  # 3e-10 N: below the scene's 1e-9 N
    md = tables.torsors_markdown(
        values,
        point=np.array([0.5, 0.0, 0.0]),
        point_name="A",
        basis=np.eye(3),
        basis_name="B0",
        axes="xyz",
        zero={"N": 1e-9},
    )
    assert _shown(md, "shown_sup_R1") == 0.0
    assert "(0,5 ; 0 ; 0) m" in md
    energy = tables.energy_markdown(
        {"T": 1.0, "V": 0.0, "P_ext": 1e-12, "P_int": 0.0, "P_acc": 1e-12}, zero={"W": 1e-9}
    )
    assert _shown(energy, "P_ext") == 0.0


def test_a_pipe_in_a_tooltip_or_label_stays_inside_its_cell():
    rows = [tables.Row("mu_required", "", "|Tt| / N: the friction used.", "μ = |T|/N")]
    md = tables.scene_markdown(rows, {"mu_required": 0.25}, {})
    line = next(line for line in md.splitlines() if "mu_required" in line)
    assert len(line.strip("|").split("|")) == 4
    assert 'title="&#124;Tt&#124; / N: the friction used."' in line
    assert ">μ = &#124;T&#124;/N</span>" in line and ">0,25</span>" in line


def test_a_vector_is_written_to_the_precision_of_its_largest_component():
    """The heavy top in steady precession: G turns in a horizontal plane, so {𝒞} has no
    vertical resultant; the integration leaves 2×10⁻⁹ kg·m/s there (θ held to 10⁻⁷ rad),
    which read as a number beside 0,03409. Below the last digit written of the largest
    component it reads 0; above it, a small component keeps its digits."""
    assert tables.written_floor([0.01535, 0.02678, -3.063e-7]) == pytest.approx(5e-6)
    assert tables.written_floor([389.9, 0.0087]) == pytest.approx(0.05)
    assert tables.written_floor([0.0, math.nan]) == 0.0 and tables.written_floor([]) == 0.0
    values = {f"{p}_{k}_{c}": 0.0 for p in ("kin", "dyn", "sup") for k in "RM" for c in "xyz"}
    values.update({"kin_R_x": 0.03409, "kin_R_y": -0.01954, "kin_R_z": 1.963e-9})
    values.update({"kin_M_x": -0.3104, "kin_M_y": 2.7e-3, "kin_M_z": 1.091})
    md = tables.torsors_markdown(
        values, point=np.zeros(3), point_name="O", basis=np.eye(3), basis_name="B0", axes="xyz"
    )
    assert _shown(md, "shown_kin_R2") == 0.0 and "10⁻⁹" not in md
    assert _shown(md, "shown_kin_R0") == pytest.approx(0.03409)
    assert _shown(md, "shown_kin_M1") == pytest.approx(2.7e-3)  # above 5×10⁻⁴: kept


def test_the_powers_of_the_balance_are_written_to_the_largest_ones_precision():
    """The compressor: the loop closure works 0,0087 W (2×10⁻⁵ of the motor's 390 W, the
    simulation's error) and read « 0,008738 » beside « inter-efforts : nulle si liaisons
    parfaites »; written to the motor's precision it reads 0, and dT/dt = Pext + Pint reads
    389,9 = 389,9 + 0. A friction power within the written digits is kept."""
    values = {"T": 999.1, "V": 0.0, "P_ext": 389.9, "P_int": 0.008738, "P_acc": 389.91}
    md = tables.energy_markdown(values)
    assert _shown(md, "P_int") == 0.0 and _shown(md, "P_ext") == pytest.approx(389.9)
    assert _shown(md, "T") == pytest.approx(999.1)
    rubbing = tables.energy_markdown({**values, "P_int": -1.25, "P_acc": 388.65})
    assert _shown(rubbing, "P_int") == pytest.approx(-1.25)


def test_the_two_sides_of_the_pfd_are_written_to_one_precision():
    """The robot axis at constant speed: {𝒟} is nil, and the integration left « R y₀ =
    −1,164×10⁻⁵ N » and moments of 4×10⁻⁷ N·m beside the frame's 223,8 N and 22,38 N·m.
    {𝒟} and {𝒯} are written to the precision of the larger: those read 0. {𝒞}, in other
    units, keeps its own."""
    values = {f"{p}_{k}_{c}": 0.0 for p in ("kin", "dyn", "sup") for k in "RM" for c in "xyz"}
    values.update({"kin_R_y": -38.12, "kin_M_x": -0.5236, "kin_M_z": -1.349, "kin_R_x": 0.02})
    values.update({"dyn_R_y": -1.164e-5, "dyn_M_x": -3.954e-7, "dyn_M_z": -4.851e-7})
    values.update({"sup_R_y": 223.8, "sup_M_x": -22.38})
    md = tables.torsors_markdown(
        values, point=np.zeros(3), point_name="O", basis=np.eye(3), basis_name="B0", axes="xyz"
    )
    for key in ("shown_dyn_R1", "shown_dyn_M0", "shown_dyn_M2"):
        assert _shown(md, key) == 0.0, key
    assert _shown(md, "shown_sup_R1") == pytest.approx(223.8)
    assert _shown(md, "shown_kin_R0") == pytest.approx(0.02)  # 0,02 beside 38,12: kept
    assert "10⁻" not in md


def test_a_flag_reads_oui_or_non_in_the_scene_table():
    """The rolling cylinder's table read « Contact avec le plan 1 » and « Sur le plan 1 »;
    the overlay already said « oui ». The cell keeps the file's 1 as its exact value."""
    rows = [tables.Row("contact", "", "", "Contact avec le plan"), tables.Row("on_plane", "", "")]
    md = tables.scene_markdown(rows, {"contact": 1.0, "on_plane": 0.0}, {})
    assert 'data-readout="contact" data-value="1.0">oui<' in md
    assert 'data-readout="on_plane" data-value="0.0">non<' in md
