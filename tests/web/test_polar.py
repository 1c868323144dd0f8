"""The rotor's polar unbalance diagram: vectors by hand, balance against the simulation,
the SVG and its refresh."""

from __future__ import annotations

import contextlib
import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

from sandbox.mechanics.unbalance import rotating_loads, two_planes
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene, rotor
from sandbox.scenes.rotor.diagram import rotor_unbalance
from sandbox.web.panels.polar import FOLDER, PolarPanel, panel_html

DEFAULTS = SCENES["rotor"].defaults()  # 20 g defect at 80 mm, disk skewed by 2°, no masses
EMOJI = re.compile("[\u2600-\u27bf\U0001f000-\U0001faff\ufe0f]")


def _disk_products(skew_deg: float) -> float:
    """F of the skewed disk by hand: I = I_d 1 + (I_a - I_d) e eᵀ, e = (cos β, sin β, 0),
    so I_xy = (I_a - I_d) sin β cos β = -F (the course's signs)."""
    m = rotor.STEEL * math.pi * rotor.DISK_RADIUS**2 * rotor.DISK_THICKNESS
    i_a = m * rotor.DISK_RADIUS**2 / 2
    i_d = m * (rotor.DISK_RADIUS**2 / 4 + rotor.DISK_THICKNESS**2 / 12)
    b = math.radians(skew_deg)
    return -(i_a - i_d) * math.sin(b) * math.cos(b)


def test_the_defaults_by_hand():
    u = rotor_unbalance(DEFAULTS)
    assert u.static["rotor"] == pytest.approx([0.020 * 0.080, 0.0], abs=1e-12)  # 1 600 g·mm
    assert u.couple["rotor"] == pytest.approx([_disk_products(2.0), 0.0], abs=1e-12)
    assert u.couple["rotor"][0] == pytest.approx(-4.2164e-4, rel=1e-4)
    assert u.static["m1"] == pytest.approx([0, 0]) and u.couple["m2"] == pytest.approx([0, 0])


@pytest.mark.parametrize(
    ("mass1", "angle1", "mass2", "angle2"),
    [(32.0, 180.0, 0.0, 0.0), (40.0, 150.0, 10.0, 20.0), (5.0, -90.0, 70.0, 45.0)],
)
def test_correction_masses_add_m_r_and_x_m_r(mass1, angle1, mass2, angle2):
    values = {**DEFAULTS, "mass1_g": mass1, "angle1_deg": angle1}
    values |= {"mass2_g": mass2, "angle2_deg": angle2}
    u = rotor_unbalance(values)
    a1, a2 = math.radians(angle1), math.radians(angle2)
    m1 = mass1 / 1000 * 0.05 * np.array([math.cos(a1), math.sin(a1)])
    m2 = mass2 / 1000 * 0.05 * np.array([math.cos(a2), math.sin(a2)])
    assert u.static["m1"] == pytest.approx(m1, abs=1e-15)
    assert u.couple["m1"] == pytest.approx(-0.12 * m1, abs=1e-15)  # plane 1 at x = -120 mm
    assert u.couple["m2"] == pytest.approx(0.12 * m2, abs=1e-15)
    # the sums agree with the scene's closed form of the whole rotor (masses included)
    mass, g, e, f = rotor.unbalance(values)
    assert u.static_total == pytest.approx(mass * g[1:], abs=1e-12)
    assert u.couple_total == pytest.approx([f, e], abs=1e-12)


def test_the_bearing_forces_follow_the_diagram():
    """ω² |m·OG⊥| and ω² |(F, E)| are the course's rotating resultant and moment."""
    values = {**DEFAULTS, "mass1_g": 40.0, "angle1_deg": 150.0}
    u = rotor_unbalance(values)
    w = rotor.omega(values)
    loads = rotating_loads(u.static_total, u.couple_total, w)
    ref = rotor.reference(values)
    assert np.linalg.norm(loads[:2]) == pytest.approx(ref["F_rot"], rel=1e-9)
    assert np.linalg.norm(loads[2:]) == pytest.approx(ref["M_rot"], rel=1e-9)


def test_a_balanced_rotor_has_zero_vectors_and_no_bearing_force():
    u = rotor_unbalance(DEFAULTS)
    m1, m2 = two_planes(u.static["rotor"], u.couple["rotor"], -0.12, 0.12, 0.05)
    solution = rotor.balancing_solution(DEFAULTS)
    assert solution["mass1_g"] == pytest.approx(1000 * m1.mass)  # 51,1 g at 180°
    assert solution["mass2_g"] == pytest.approx(1000 * m2.mass)  # 19,1 g at 0°
    assert abs(solution["angle1_deg"]) == pytest.approx(abs(m1.angle_deg))
    values = {**DEFAULTS, **solution}
    balanced = rotor_unbalance(values)
    assert np.linalg.norm(balanced.static_total) < 1e-12 * 1.6e-3
    assert np.linalg.norm(balanced.couple_total) < 1e-12 * 4.2e-4
    sim = Simulation(get_scene("rotor"), values=values)
    sim.advance(0.1)
    forces = sim.readouts()
    assert forces["bearing_A"] < 1e-6 and forces["bearing_B"] < 1e-6  # from 54 N and 15 N
    html = panel_html(rotor_unbalance(values))
    (total,) = re.findall(r"Résultante</td>(.*?)</tr>", html)
    assert re.findall(r">([^<]*)</td>", total) == ["0", "0"]


def test_the_panel_is_french_svg_without_emoji_or_code_names():
    html = panel_html(rotor_unbalance({**DEFAULTS, "mass1_g": 32.0, "angle1_deg": 180.0}))
    assert html.count("<svg") >= 1 and "Balourd statique" in html and "Balourd de couple" in html
    assert "0,0016 à 0°" in html  # the defect: 20 g × 80 mm, decimal comma, degrees
    assert "0,0016 à 180°" in html  # m1: 32 g × 50 mm opposite
    assert not EMOJI.search(html)
    for name in DEFAULTS:
        assert name not in html
    assert not re.search(r"\bnan\b", html, re.IGNORECASE) and "—" not in html


class _Gui:
    def __init__(self) -> None:
        self.folders: list[str] = []
        self.html = SimpleNamespace(content="")

    def add_folder(self, label: str, **_: object) -> contextlib.nullcontext[None]:
        self.folders.append(label)
        return contextlib.nullcontext()

    def add_html(self, content: str) -> SimpleNamespace:
        self.html.content = content
        return self.html


def test_the_panel_redraws_only_when_a_value_changes():
    sim = SimpleNamespace(scene=SCENES["rotor"], values=dict(DEFAULTS))
    gui = _Gui()
    panel = PolarPanel.create(gui, sim)  # type: ignore[arg-type]
    assert panel is not None and gui.folders == [FOLDER] and "<svg" in gui.html.content
    assert panel.refresh() is False  # nothing changed
    sim.values["speed_rpm"] = 3000.0
    assert panel.refresh() is False  # the speed does not change the unbalance
    sim.values["mass1_g"] = 10.0
    assert panel.refresh() is True and "0,0005 à 0°" in gui.html.content
    other = SimpleNamespace(scene=SCENES["gyroscope"])
    assert PolarPanel.create(_Gui(), other) is None  # type: ignore[arg-type]
