"""Folder « Flux de puissance » (course 6.4.2): the wind turbine's chain drawn as a Sankey
diagram, each band as wide as its power, every number as the tables write it, nothing
drawn or written from a missing value, and every word inside the drawing."""

from __future__ import annotations

import contextlib
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from types import SimpleNamespace

import pytest

from sandbox.physics.page import FlowStage, Page, PowerFlow
from sandbox.web.loop.frame import Frame
from sandbox.web.panels.power_flow import (
    FOLDER,
    THICK,
    PowerFlowPanel,
    flow_names,
    flow_svg,
    panel_html,
)
from sandbox.web.view3d.label_layout import text_width
from sandbox.written import written
from tests.web.test_every_panel import problems, visible

SVG = "{http://www.w3.org/2000/svg}"

TURBINE = PowerFlow(
    source="P_wind",
    source_words="Vent, limite de Betz",
    stages=(
        FlowStage("Rotor", "P_rotor", "P_rotor_loss", "P_rotor_store", "vent non capté"),
        FlowStage("Multiplicateur", "P_generator_in", "P_gearbox_loss"),
        FlowStage("Génératrice", "P_electric", "P_generator_loss", "P_generator_store"),
        FlowStage("Transformateur", "P_transformer_out", "P_transformer_loss"),
        FlowStage("Lignes", "P_grid", "P_line_loss"),
    ),
    sink_words="Réseau",
    efficiency="eta",
)
"""The course's chain: P₁ = 5 MW through 0,75, 0,9, 0,9, 0,9 and 0,95."""

COURSE: dict[str, float] = {
    "P_wind": 5e6,
    "P_rotor": 3.75e6,
    "P_rotor_loss": 1.25e6,
    "P_generator_in": 3.375e6,
    "P_gearbox_loss": 375e3,
    "P_electric": 3.0375e6,
    "P_generator_loss": 337.5e3,
    "P_transformer_out": 2.73375e6,
    "P_transformer_loss": 303.75e3,
    "P_grid": 2.5970625e6,
    "P_line_loss": 136.6875e3,
    "P_rotor_store": 0.0,
    "P_generator_store": 0.0,
    "eta": 0.75 * 0.9 * 0.9 * 0.9 * 0.95,
}
OUTS = {s.name: s.power_out for s in TURBINE.stages}
LOSSES = {s.name: s.loss for s in TURBINE.stages}

# the rotor speeding up (1 MW stored) and the generator too (0,2 MW)
SPEEDING = {**COURSE, "P_rotor_store": 1e6, "P_rotor": 2.75e6, "P_generator_store": 2e5}
# both slowing down: their inertias give 0,8 MW and 0,3 MW back
SLOWING = {**COURSE, "P_rotor_store": -0.8e6, "P_rotor": 4.55e6, "P_generator_store": -3e5}
BROKEN = {**COURSE, "P_gearbox_loss": math.nan, "P_transformer_out": math.inf}
del BROKEN["P_rotor"]


def _svg(values: Mapping[str, float], flow: PowerFlow = TURBINE, zero: float = 0.0) -> ET.Element:
    return ET.fromstring(flow_svg(flow, values, zero))


def _bands(root: ET.Element) -> dict[str, ET.Element]:
    """The drawn bands by their ``data-flow``."""
    out = {}
    for e in root.iter():
        name = e.get("data-flow")
        if name is not None:
            assert name not in out, f"two bands {name}"
            out[name] = e
    return out


def _width(e: ET.Element) -> float:
    return float(e.get("stroke-width", "nan"))


def _words(root: ET.Element) -> str:
    """Every text of the drawing, one after another."""
    return " ".join("".join(t.itertext()) for t in root.iter(f"{SVG}text"))


def _view(root: ET.Element) -> tuple[float, float]:
    x0, y0, w, h = (float(v) for v in root.get("viewBox", "").split())
    assert (x0, y0) == (0.0, 0.0)
    return w, h


# -- widths ------------------------------------------------------------------------------------
def test_every_band_is_as_wide_as_its_power_on_one_scale():
    bands = _bands(_svg(COURSE))
    expected = {"source": "P_wind"}
    expected |= {f"out:{n}": r for n, r in OUTS.items()}
    expected |= {f"loss:{n}": r for n, r in LOSSES.items()}
    assert set(bands) == set(expected)  # nothing stored: the rotor turns at a steady speed
    source = _width(bands["source"])
    assert source == pytest.approx(THICK, rel=1e-9)  # the largest power: the wind's
    for flow, readout in expected.items():
        assert float(bands[flow].get("data-power", "nan")) == COURSE[readout]
        ratio = _width(bands[flow]) / source
        assert ratio == pytest.approx(COURSE[readout] / COURSE["P_wind"], rel=1e-6), flow
    # the course's numbers: the gearbox loses 0,075 of the wind, the lines 0,0273
    assert _width(bands["loss:Multiplicateur"]) / source == pytest.approx(0.075, rel=1e-6)
    assert _width(bands["loss:Lignes"]) / source == pytest.approx(0.0273375, rel=1e-6)


def test_the_scale_is_set_by_the_largest_power_drawn():
    """An inertia giving back twice the wind's power: its band is the widest one."""
    values = {**COURSE, "P_rotor_store": -10e6, "P_rotor": 13.75e6}
    bands = _bands(_svg(values))
    assert _width(bands["out:Rotor"]) == pytest.approx(THICK, rel=1e-9)
    assert _width(bands["given:Rotor"]) / _width(bands["out:Rotor"]) == pytest.approx(
        10 / 13.75, rel=1e-6
    )
    assert _width(bands["source"]) / THICK == pytest.approx(5 / 13.75, rel=1e-6)
    assert max(_width(e) for e in bands.values()) == pytest.approx(THICK, rel=1e-9)


# -- numbers -----------------------------------------------------------------------------------
def test_the_labels_write_what_the_tables_write():
    root = _svg(COURSE)
    words = _words(root)
    for name, value in COURSE.items():
        if name in ("eta", "P_rotor_store", "P_generator_store"):
            continue
        assert str(written(name, value, "W")) in words, name
    assert str(written("P_gearbox_loss", 375e3, "W")) in words
    for stage in TURBINE.stages:
        assert stage.name in words
    assert "vent non capté" in words and words.count("chaleur") == 4
    assert "Vent, limite de Betz" in words and "Réseau" in words
    # a steady rotor: no kinetic energy drawn nor written
    assert "cinétique" not in words
    html = panel_html(TURBINE, COURSE)
    eta = written("eta", COURSE["eta"], "")
    assert eta.number == "0,5194"
    assert f"Rendement global η = {eta}" in visible(html)
    assert "proportionnelle à la puissance" in visible(html)
    assert "(rendue quand elles ralentissent)." in visible(html)  # the legend, whole


def test_the_power_leaving_is_written_at_the_right_end():
    """The last stage's power passed on is the power leaving: written once, with the
    sink's words, right of every other label."""
    root = _svg(COURSE)
    grid = str(written("P_grid", COURSE["P_grid"], "W"))
    texts = {"".join(t.itertext()): t for t in root.iter(f"{SVG}text")}
    assert _words(root).count(grid) == 1
    assert float(texts[grid].get("x", "nan")) == pytest.approx(
        float(texts["Réseau"].get("x", "nan"))
    )
    assert float(texts[grid].get("x", "nan")) > max(
        float(texts[s.name].get("x", "nan")) for s in TURBINE.stages
    )


def test_the_scenes_round_off_is_written_0():
    values = {**COURSE, "P_line_loss": 400.0}
    words = _words(_svg(values, zero=1e3))
    assert str(written("P_line_loss", 400.0, "W", zero=1e3)) in words
    assert written("P_line_loss", 400.0, "W", zero=1e3).number == "0"
    assert str(written("P_line_loss", 400.0, "W")) not in words


# -- missing, zero and negative powers ---------------------------------------------------------
def test_a_missing_or_non_finite_power_draws_no_band_and_writes_a_dash():
    svg = flow_svg(TURBINE, BROKEN)
    bands = _bands(ET.fromstring(svg))
    assert "loss:Multiplicateur" not in bands and "out:Rotor" not in bands
    assert "out:Transformateur" not in bands
    assert "loss:Rotor" in bands and "out:Multiplicateur" in bands
    assert _words(ET.fromstring(svg)).count("—") == 3
    assert not re.search(r"nan|inf", svg, re.IGNORECASE)
    for e in bands.values():
        assert math.isfinite(_width(e)) and _width(e) > 0


def test_nothing_at_all_draws_no_band_and_no_number():
    for values in ({}, {n: math.nan for n in COURSE}):
        html = panel_html(TURBINE, values)
        root = ET.fromstring(flow_svg(TURBINE, values))
        assert _bands(root) == {}
        assert "Rendement global η = —" in visible(html)
        assert not re.search(r"nan|inf", html, re.IGNORECASE)
        assert _words(root).count("—") == 1 + 5 + 5  # the source, the stages, the losses
        _inside(root)


@pytest.mark.parametrize("size", [5e-324, 1e-300, 1e300, 1.7e308])
def test_tiny_and_huge_powers_draw_finite_bands(size: float):
    values = {name: value / 5e6 * size for name, value in COURSE.items() if name != "eta"}
    svg = flow_svg(TURBINE, values)
    root = ET.fromstring(svg)
    bands = _bands(root)
    assert not re.search(r"nan|inf", svg, re.IGNORECASE)
    assert _width(bands["source"]) == pytest.approx(THICK)
    assert all(0 <= _width(e) <= THICK * (1 + 1e-9) for e in bands.values())
    _inside(root, crossing=True)  # « 6,075×10²⁹² MW »: wider than the room kept


def test_zero_and_negative_powers_draw_no_band():
    values = {**COURSE, "P_line_loss": 0.0, "P_transformer_loss": -2.0, "P_grid": -1.0}
    bands = _bands(_svg(values))
    assert "loss:Lignes" not in bands and "loss:Transformateur" not in bands
    assert "out:Lignes" not in bands
    assert all(_width(e) > 0 for e in bands.values())
    words = _words(_svg(values))
    assert str(written("P_transformer_loss", -2.0, "W")) in words  # still written


# -- kinetic energy ----------------------------------------------------------------------------
def test_an_inertia_speeding_up_stores_kinetic_energy_upward():
    root = _svg(SPEEDING)
    bands = _bands(root)
    source = _width(bands["source"])
    assert _width(bands["stored:Rotor"]) / source == pytest.approx(0.2, rel=1e-6)
    assert _width(bands["stored:Génératrice"]) / source == pytest.approx(0.04, rel=1e-6)
    assert not any(name.startswith("given:") for name in bands)
    words = _words(root)
    assert words.count("énergie cinétique stockée") == 2
    assert str(written("P_rotor_store", 1e6, "W")) in words
    assert str(written("P_generator_store", 2e5, "W")) in words
    # it leaves upward: its arrow ends above the band, the losses end below it
    band_top = min(_ys(bands["source"]))
    assert max(_ys(bands["stored:Rotor"])) <= band_top + 1e-6 + _width(bands["stored:Rotor"])
    assert min(_ys(bands["stored:Rotor"])) < band_top
    assert min(_ys(bands["loss:Rotor"])) > band_top


def test_an_inertia_slowing_down_gives_kinetic_energy_back_from_above():
    root = _svg(SLOWING)
    bands = _bands(root)
    assert "given:Rotor" in bands and "given:Génératrice" in bands
    assert not any(name.startswith("stored:") for name in bands)
    ratio = _width(bands["given:Rotor"]) / _width(bands["source"])
    assert ratio == pytest.approx(0.8 / 5, rel=1e-6)
    assert float(bands["given:Rotor"].get("data-power", "nan")) == -0.8e6
    words = _words(root)
    assert words.count("énergie cinétique rendue") == 2 and "stockée" not in words
    assert str(written("P_rotor_store", -0.8e6, "W")) in words
    assert min(_ys(bands["given:Rotor"])) < min(_ys(bands["source"]))


def test_a_negligible_stored_power_is_not_drawn():
    values = {**COURSE, "P_rotor_store": 4e3, "P_generator_store": -4e3}  # 0,0008 P₁
    root = _svg(values)
    assert not any(n.startswith(("stored:", "given:")) for n in _bands(root))
    assert "cinétique" not in _words(root)
    root = _svg({**COURSE, "P_rotor_store": 6e3})  # 0,0012 P₁
    assert "stored:Rotor" in _bands(root)


# -- reading -----------------------------------------------------------------------------------
CASES = {"course": COURSE, "speeding": SPEEDING, "slowing": SLOWING, "broken": BROKEN}


@pytest.mark.parametrize("case", sorted(CASES))
def test_no_english_and_no_contract_name_is_read(case: str):
    html = panel_html(TURBINE, CASES[case])
    assert problems(html) == []
    for name in CASES[case]:
        assert name not in visible(html)
    assert not re.search("[\u2600-\u27bf\U0001f000-\U0001faff]", html)  # no emoji


def _boxes(root: ET.Element) -> list[tuple[str, float, float, float, float]]:
    """Each text's box as the layout estimates it (an upper bound of the fonts' widths)."""
    out = []
    for t in root.iter(f"{SVG}text"):
        text = "".join(t.itertext())
        size = float(t.get("font-size", root.get("font-size", "14")))
        w = text_width(text, size) * (1.08 if t.get("font-weight") else 1.0)
        x, y = float(t.get("x", "nan")), float(t.get("y", "nan"))
        left = {"start": x, "middle": x - w / 2, "end": x - w}[t.get("text-anchor", "start")]
        out.append((text, left, left + w, y - 0.8 * size, y + 0.25 * size))
    return out


def _points(d: str) -> list[tuple[float, float]]:
    """The points a path's ``d`` goes through (M, A, H, V commands, absolute)."""
    out: list[tuple[float, float]] = []
    x = y = math.nan
    for op, args in re.findall(r"([MAVH])([^MAVH]*)", d):
        nums = [float(v) for v in args.split()]
        if op == "V":
            y = nums[0]
        elif op == "H":
            x = nums[0]
        else:
            x, y = nums[-2], nums[-1]
        out.append((x, y))
    return out


def _ys(e: ET.Element) -> list[float]:
    """The y of every point of a band's path (its ends and bends)."""
    return [y for _, y in _points(e.get("d", ""))]


def _verticals(root: ET.Element) -> list[tuple[float, float, float]]:
    """Every vertical stretch of a path (arrows, dotted lines): (x, y from, y to)."""
    out = []
    for e in root.iter(f"{SVG}path"):
        points = _points(e.get("d", ""))
        for (x0, y0), (x1, y1) in zip(points, points[1:], strict=False):
            if x0 == x1 and y0 != y1:
                out.append((x0, min(y0, y1), max(y0, y1)))
    return out


def _inside(root: ET.Element, *, crossing: bool = False) -> None:
    """Every text inside the drawing, none over another, none crossed by an arrow or a
    dotted line unless ``crossing`` (no room left), every number of the SVG finite."""
    width, height = _view(root)
    boxes = _boxes(root)
    for text, left, right, top, bottom in boxes:
        assert 0 <= left and right <= width, text
        assert 0 <= top and bottom <= height, text
    for i, (a, l1, r1, t1, b1) in enumerate(boxes):
        for b, l2, r2, t2, b2 in boxes[i + 1 :]:
            assert not (l1 < r2 and l2 < r1 and t1 < b2 and t2 < b1), f"{a!r} over {b!r}"
    crossings = [
        f"a line at x = {x} crosses {text!r}"
        for x, y0, y1 in _verticals(root)
        for text, left, right, top, bottom in boxes
        if left - 1 < x < right + 1 and y0 < bottom - 1 and top + 1 < y1
    ]
    assert crossing or not crossings, crossings
    numbers = re.findall(r'="(-?[\d.]+)"', ET.tostring(root, encoding="unicode"))
    assert all(math.isfinite(float(v)) for v in numbers)


@pytest.mark.parametrize("case", sorted(CASES))
def test_every_word_is_inside_the_drawing_and_none_overlaps(case: str):
    root = _svg(CASES[case])
    _inside(root)
    width, height = _view(root)
    assert width == 400 and 200 < height < 400  # a side panel's drawing, one unit a pixel
    for text in root.iter(f"{SVG}text"):
        assert float(text.get("font-size", "14")) >= 13


def test_a_longer_chain_with_long_names_still_fits():
    """Eight stages, each storing or giving back energy: every word still inside, none
    over another."""
    stages = tuple(
        FlowStage(f"Organe{i} intermédiaire", f"P_out{i}", f"P_loss{i}", f"P_store{i}", "chaleur")
        for i in range(8)
    )
    flow = PowerFlow("P_in", "Puissance mécanique fournie", stages, "Utilisateur", "")
    values = {"P_in": 1e5}
    for i in range(8):
        values[f"P_loss{i}"] = 1e3 * (i + 1)
        values[f"P_store{i}"] = 2e3 * (-1) ** i
        before = values.get(f"P_out{i - 1}", 1e5)
        values[f"P_out{i}"] = before - values[f"P_loss{i}"] - values[f"P_store{i}"]
    root = _svg(values, flow)
    _inside(root, crossing=True)  # 10 labels of 180 units in 400: lines must cross some
    assert len(_bands(root)) == 1 + 8 * 3
    assert "Rendement global" not in panel_html(flow, values)


def test_the_svg_is_one_inline_french_image():
    svg = flow_svg(TURBINE, COURSE)
    root = ET.fromstring(svg)
    assert root.tag == f"{SVG}svg" and svg.count("<svg") == 1
    assert root.get("width") == "100%" and root.get("role") == "img"
    assert root.get("font-family") == "sans-serif"
    assert "puissance" in root.get("aria-label", "")


# -- the panel ---------------------------------------------------------------------------------
class _Html:
    def __init__(self) -> None:
        self.writes = 0
        self._content = ""

    @property
    def content(self) -> str:
        return self._content

    @content.setter
    def content(self, text: str) -> None:
        self.writes += 1
        self._content = text


class _Gui:
    def __init__(self) -> None:
        self.folders: list[str] = []
        self.html = _Html()

    def add_folder(self, label: str, **_: object) -> contextlib.nullcontext[None]:
        self.folders.append(label)
        return contextlib.nullcontext()

    def add_html(self, content: str) -> _Html:
        self.html.content = content
        return self.html


def _scene(flow: PowerFlow | None, zero: float = 0.0) -> SimpleNamespace:
    return SimpleNamespace(page=Page(power_flow=flow), zero_for=lambda unit: {"W": zero}[unit])


def _frame(readouts: Mapping[str, float] | None) -> Frame:
    return Frame(now=0.0, time=0.0, generation=0, model_id=0, playing=True, diverged=None,
                 readouts=readouts)  # fmt: skip


def test_the_panel_exists_only_for_a_scene_with_a_chain():
    assert PowerFlowPanel.create(_Gui(), SimpleNamespace(scene=None)) is None  # type: ignore[arg-type]
    other = SimpleNamespace(scene=_scene(None))
    assert PowerFlowPanel.create(_Gui(), other) is None  # type: ignore[arg-type]


def test_the_panel_writes_the_frames_readouts_once_per_change():
    gui = _Gui()
    sim = SimpleNamespace(scene=_scene(TURBINE, zero=1e3))
    panel = PowerFlowPanel.create(gui, sim)  # type: ignore[arg-type]
    assert panel is not None and gui.folders == [FOLDER]
    (folder,) = panel.pickable()
    assert folder.title == "Flux de puissance" and folder.handle is panel.folder
    assert folder.needs_readouts and not folder.secret_safe
    assert tuple(folder.names()) == panel.names == flow_names(TURBINE)
    assert set(panel.names) == set(COURSE) and panel.names[0] == "P_wind"
    assert folder.refresh is not None
    start = gui.html.writes
    folder.refresh(_frame(COURSE))
    assert gui.html.writes == start + 1
    assert gui.html.content == panel_html(TURBINE, COURSE, 1e3)
    folder.refresh(_frame(dict(COURSE)))  # the same numbers: nothing sent
    assert gui.html.writes == start + 1
    folder.refresh(_frame(SPEEDING))
    assert gui.html.writes == start + 2 and "énergie cinétique" in gui.html.content
    folder.refresh(_frame(None))  # no readouts: every number a dash, no band
    assert gui.html.writes == start + 3 and "data-flow" not in gui.html.content


def test_the_names_are_only_the_declared_readouts():
    flow = PowerFlow("P_a", "Entrée", (FlowStage("Arbre", "P_b"),), "Sortie")
    assert flow_names(flow) == ("P_a", "P_b")
    words = _words(_svg({"P_a": 10.0, "P_b": 8.0}, flow))
    assert str(written("P_b", 8.0, "W")) in words and "chaleur" not in words


def test_the_wind_turbines_folder_writes_the_courses_chain(tmp_path):
    """The real page on the wind turbine: « Flux de puissance » writes the course's 5 MW,
    3,75 MW and 0,375 MW lost in the gearbox, and the overall 0,5194, from the frame's
    readouts (the tables' numbers)."""
    from sandbox.web.panels.power_flow import FOLDER as FLOW_FOLDER
    from tests.robustness.test_hostile_web import Page

    page = Page("wind_turbine", tmp_path)
    try:
        page.tick(0.3)
        page.show(FLOW_FOLDER)
        page.tick(0.6)
        shown = "\n".join(
            visible(str(h.content)) for h in page.client.gui.handles if h.kind == "html"
        )
        for text in ("5\u00a0MW", "3,75\u00a0MW", "0,375\u00a0MW", "Rendement global η = 0,5194"):
            assert text in shown, text
        assert problems(shown) == []
    finally:
        page.session.stop()
