"""The French words of the web page: every parameter, readout and arrow has a label in
words with the course's symbol, a one-sentence tooltip, a unit a French reader writes, a
folder; round-off thresholds hide only round-off.

A parameter, readout or arrow added without its French words fails here.
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Iterator

import pytest

from sandbox.physics.page import Arrow
from sandbox.physics.readouts import GENERIC_READOUTS
from sandbox.physics.simulation import Simulation
from sandbox.physics.spec import Param, Scene
from sandbox.physics.units import DISPLAY_UNITS, display_unit
from sandbox.scenes import SCENES, get_scene, resolve

ENGLISH = {
    "and", "angular", "axis", "bearing", "closure", "counterweight", "crank", "drift",
    "energy", "error", "force", "friction", "from", "gimbal", "inertia", "length", "lock",
    "mass", "momentum", "of", "pitch", "power", "radius", "rod", "roll", "slope",
    "speed", "spin", "the", "tilt", "torque", "velocity", "when", "with", "yaw",
    "omega", "theta", "lambda", "mu", "sigma", "delta", "rpm", "deg",
}  # fmt: skip
"""English words (and symbols spelled out, code units) that a French label or tooltip
never needs."""

ALLOWED_SYMBOLS = {"°"}
"""Characters of Unicode category "So" (other symbols, where emoji live) that may appear."""


def _items() -> Iterator[tuple[str, str, str, str]]:
    """(where, contract name, label, hint) of everything the page names."""
    for r in GENERIC_READOUTS:
        yield "generic", r.name, r.label, r.hint
    for scene in SCENES.values():
        for p in scene.params:
            yield scene.name, p.name, p.label, p.hint
        for sr in scene.readouts:
            yield scene.name, sr.name, sr.label, sr.hint
        for a in scene.page.arrows:
            yield scene.name, f"arrow {a.name}", a.label, a.hint


ITEMS = list(_items())
IDS = [f"{where}:{name}" for where, name, _, _ in ITEMS]


def _words(text: str) -> list[str]:
    return re.findall(r"[A-Za-zÀ-ÿœŒ]+", text)


def _check_characters(text: str, what: str) -> None:
    for ch in text:
        assert ord(ch) <= 0xFFFF, (what, ch)  # emoji live above the basic plane
        assert unicodedata.category(ch) != "So" or ch in ALLOWED_SYMBOLS, (what, ch)
        assert ch not in "<>`*_[]|\\", (what, ch)  # raw HTML, markdown, code


@pytest.mark.parametrize(("where", "name", "label", "hint"), ITEMS, ids=IDS)
def test_label_is_french_words_with_the_course_symbol(where, name, label, hint):
    """A label: French words, no code name, no unit (the page adds it), no markup."""
    what = f"{where}:{name}"
    assert label and label == label.strip() and "\n" not in label, what
    assert 3 <= len(label) <= 60, what
    assert label[0].isupper(), what  # a French capital, not a code name
    _check_characters(label, what)
    assert "[" not in label and not label.endswith("."), what
    assert not {w.lower() for w in _words(label)} & ENGLISH, what
    assert not re.search(r"[A-Za-z][0-9]", label), what  # A1, x0: the course writes A₁, x₀


@pytest.mark.parametrize(("where", "name", "label", "hint"), ITEMS, ids=IDS)
def test_hint_is_one_french_sentence(where, name, label, hint):
    """A tooltip: one sentence ending with a period, in French, without markup."""
    what = f"{where}:{name}"
    assert hint and hint == hint.strip() and "\n" not in hint, what
    assert 15 <= len(hint) <= 200, what
    assert hint.endswith(".") and not hint.endswith(".."), what
    assert hint[0].isupper() or hint[0].isdigit(), what
    assert not re.search(r"[.!?] +[A-ZÀ-Ý]", hint[:-1]), what  # one sentence
    _check_characters(hint, what)
    assert not {w.lower() for w in _words(hint)} & ENGLISH, what
    assert not re.search(r"[A-Za-z][0-9]", hint), what


@pytest.mark.parametrize("name", sorted(SCENES))
def test_labels_are_unique_in_a_scene(name):
    """No two things of one scene read the same (params, readouts and generic readouts
    together; arrows among themselves, they may repeat the readout they draw)."""
    scene = SCENES[name]
    labels = [p.label for p in scene.params] + [r.label for r in scene.readouts]
    labels += [r.label for r in GENERIC_READOUTS]
    assert len(set(labels)) == len(labels), sorted(x for x in labels if labels.count(x) > 1)
    arrows = [a.label for a in scene.page.arrows]
    assert len(set(arrows)) == len(arrows), arrows


def test_display_units_are_french():
    """The page shows tr/min and °; CSV and describe keep rpm and deg (contracts)."""
    assert display_unit("rpm") == "tr/min" and display_unit("deg") == "°"
    assert display_unit("N·m") == "N·m" and display_unit("") == ""
    units = [r.display_unit for r in GENERIC_READOUTS]
    for scene in SCENES.values():
        units += [p.display_unit for p in scene.params]
        units += [r.display_unit for r in scene.readouts]
        units += [a.display_unit for a in scene.page.arrows]
    assert set(units) <= DISPLAY_UNITS, set(units) - DISPLAY_UNITS
    assert "rpm" not in units and "deg" not in units


def test_simulation_passes_the_french_words_on():
    """What the web layer reads (``Simulation.readout_infos``) carries the labels."""
    infos = Simulation(get_scene("rotor")).readout_infos()
    by_name = {i.name: i for i in infos}
    assert by_name["bearing_A"].label == "Effort du palier A"
    assert by_name["T"].label == "Énergie cinétique T"
    assert by_name["P_ext"].label == "Puissance des efforts extérieurs Pₑₓₜ"
    assert all(i.label and i.hint for i in infos)
    assert by_name["omega"].unit == "rad/s"
    speed = SCENES["rotor"].param("speed_rpm")
    assert (speed.unit, speed.display_unit) == ("rpm", "tr/min")


@pytest.mark.parametrize("name", sorted(SCENES))
def test_parameters_are_grouped_for_the_projector(name):
    """Every parameter sits in a French folder; at most a few folders; the rarely changed
    ones are folded but something stays visible; ranges spanning decades are typed as
    numbers; a choice names each of its values."""
    scene: Scene = SCENES[name]
    groups = list(dict.fromkeys(p.group for p in scene.params))
    assert all(groups) and len(groups) <= 6, groups
    for g in groups:
        assert g[0].isupper() and "_" not in g and not set(_words(g.lower())) & ENGLISH, g
    assert any(not p.advanced for p in scene.params)
    for p in scene.params:
        _check_param_entry(p)


def _check_param_entry(p: Param) -> None:
    if p.choices:
        assert p.min == 0 and p.step == 1 and len(p.choices) == int(p.max) + 1, p.name
        assert all(c and c[0].isupper() and "_" not in c for c in p.choices), p.name
    # A slider of ~300 px cannot set a value smaller than its range / 300 to 1 %: such a
    # parameter is typed as a number instead.
    if 0 < abs(p.default) < (p.max - p.min) / 3000:
        assert p.log, (p.name, "its default is out of a slider's reach: set log=True")
    if p.log:
        assert p.step <= abs(p.default) / 10, (p.name, "step coarser than the default")


def test_compressor_inertias_are_folded_and_reachable():
    """Issue 14: the 0-0.1 kg·m² sliders could not reach 0.0002 and showed 0.00000."""
    scene = SCENES["compressor"]
    for name in ("A1", "B1", "C1", "E1", "A2", "B2", "C2"):
        p = scene.param(name)
        assert p.advanced and p.log and p.group == "Inerties", name
        assert p.min < abs(p.default) < p.max and p.step <= abs(p.default) / 10, name
        assert p.check(2e-4 if name != "B2" else 2e-6)
    visible = [p.name for p in scene.params if not p.advanced]
    assert len(visible) <= 10, visible


@pytest.mark.parametrize("name", sorted(SCENES))
def test_arrows_carry_their_unit_and_point(name):
    """An arrow's 3D label reads "Palier A : 0,91 N"; a direction reads its words alone;
    its origin is a named point, offered as a reduction point of the torsors."""
    for a in SCENES[name].page.arrows:
        assert a.point and re.fullmatch(r"[A-Z]", a.point), a.name
        if a.magnitude:
            assert a.unit, a.name
            assert a.caption("0,91") == f"{a.label} : 0,91 {a.display_unit}"
        else:
            assert a.caption("1") == a.label


def test_arrow_caption_examples():
    rotor = {a.name: a for a in SCENES["rotor"].page.arrows}
    assert rotor["bearing_A"].caption("0,91") == "Palier A : 0,91 N"
    gyro = {a.name: a for a in SCENES["gyroscope"].page.arrows}
    assert gyro["sigma_G"].caption("0,503") == "Moment cinétique σ en G : 0,503 kg·m²/s"
    assert gyro["axis"].caption("1") == "Axe du rotor"
    bare = Arrow("f", "Effort", (0, 0, 0), lambda s: (None, None))  # type: ignore[arg-type,return-value]
    assert bare.caption("2") == "Effort : 2"


@pytest.mark.parametrize("name", sorted(SCENES))
def test_round_off_hides_only_round_off(name):
    """``Scene.zero`` thresholds sit at least 1e8 times below the largest readout of their
    unit (0.4 s at the defaults), so no value the scene means is shown as 0."""
    scene = SCENES[name]
    sim = Simulation(resolve(name))
    units = {i.name: i.unit for i in sim.readout_infos()}
    peaks: dict[str, float] = {}
    for _ in range(20):
        sim.advance(0.02)
        for n, v in sim.readouts().items():
            if math.isfinite(v):
                peaks[units[n]] = max(peaks.get(units[n], 0.0), abs(v))
    assert set(scene.zero) <= set(units.values()), set(scene.zero) - set(units.values())
    for unit, zero in scene.zero.items():
        assert 0 < zero == scene.zero_for(unit), unit
        # Either far below the unit's largest value, or every value of that unit is
        # round-off (the rotor's powers at constant speed: 1e-29 W).
        assert zero <= 1e-8 * peaks[unit] or peaks[unit] <= zero, (unit, zero, peaks[unit])
    assert scene.zero_for("no such unit") == 0.0


def test_round_off_of_the_rotor_is_shown_as_zero():
    """At 1500 rpm {D} keeps ~6e-12 N along z0 where the course has 0: below the scene's
    round-off, which the page passes to ``text.number(..., zero=...)``."""
    from sandbox.web.client.text import number

    scene = SCENES["rotor"]
    sim = Simulation(get_scene("rotor"))
    sim.advance(0.1)
    values = sim.readouts(["dyn_R_z", "sup_M_y", "bearing_A"])
    assert abs(values["dyn_R_z"]) <= scene.zero_for("N")
    assert number(values["dyn_R_z"], zero=scene.zero_for("N")) == "0"
    assert number(values["bearing_A"], zero=scene.zero_for("N")) != "0"


@pytest.mark.parametrize("name", sorted(SCENES))
def test_overlay_writes_three_or_four_key_readouts_in_french(name):
    """Projector mode writes a scene's key readouts large over the 3D view: each one a
    readout of the scene, with French short words (or its label)."""
    scene = SCENES[name]
    known = set(Simulation(resolve(name)).readout_names())
    assert 2 <= len(scene.page.overlay) <= 4, scene.page.overlay
    for readout, short in scene.page.overlay.items():
        assert readout in known, readout
        if short:
            _check_characters(short, readout)
            assert not {w.lower() for w in _words(short)} & (ENGLISH - {"omega", "theta"})
