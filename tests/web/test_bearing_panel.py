"""Folder « Pression dans les paliers » (issue 39, course appendix B.2): the formulas with
today's numbers, the verdict against 200 bar, the loaded zone drawn where the shaft
presses, and the page's numbers equal to the course's for the rotor's bearings."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from sandbox.physics.page import Bearing
from sandbox.web.panels.bearing import (
    BORE,
    FOLDER,
    LIMIT_ROOM,
    PRINTED_NOTE,
    SIZE,
    Loaded,
    in_plane,
    panel_html,
)
from sandbox.web.panels.readouts import SCENE_FOLDER
from tests.robustness.test_hostile_web import Page
from tests.web.test_every_panel import problems, visible

X_AXIS = Bearing(
    "A", "Palier A", lambda s: np.zeros(3), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), ("y₀", "z₀")
)
VALUES = {"bearing_R": 10.0, "bearing_L": 10.0, "bearing_model": 0.0, "bearing_f": 0.1}
NNBSP = "\u202f"


def _loaded(force: float, model: float = 0.0, angle_deg: float = 0.0) -> Loaded:
    a = math.radians(angle_deg)
    p0 = force / (2 * 0.01 * 0.01)
    p_max = p0 * (4 / math.pi if model == 1.0 else 1.0)
    return Loaded(X_AXIS, (force * math.cos(a), force * math.sin(a)), p_max)


def _text(force: float, model: float) -> str:
    values = {**VALUES, "bearing_model": model}
    return visible(panel_html([_loaded(force, model)], values, {}))


def test_hypothesis_1_at_round_numbers_and_the_200_bar_verdict():
    """1000 N on a 10 mm × 10 mm bore: p₀ = F/(2RL) = 5×10⁶ Pa, written 50 bar."""
    text = _text(1000.0, 0.0)
    assert f"charge radiale F = 1{NNBSP}000\u00a0N" in text
    assert (
        f"p₀ = F / (2·R·L) = 1{NNBSP}000\u00a0N / (2 × 10\u00a0mm × 10\u00a0mm) = 50\u00a0bar"
        in text
    )
    assert "pₘₐₓ = p₀ = 50\u00a0bar" in text
    assert "sous les 200 bar : tenue" in text and "au-delà" not in text
    over = panel_html([_loaded(5000.0)], VALUES, {})
    assert "pₘₐₓ = p₀ = 250\u00a0bar" in visible(over)
    assert "au-delà de 200 bar" in visible(over)
    assert 'fill="#c0392b" fill-opacity' in over  # the zone turns red past the limit
    assert problems(over) == [] and problems(panel_html([_loaded(1000.0)], VALUES, {})) == []


def test_hypothesis_2_writes_the_cosines_peak():
    """p_max = (4/π) p₀ = 2F/(πRL): 63,66 bar for 1000 N."""
    text = _text(1000.0, 1.0)
    assert "Pression en cosinus (hypothèse 2)" in text
    assert "pₘₐₓ = (4/π)·p₀ = 2·F / (π·R·L) = 63,66\u00a0bar" in text
    assert "Cf" not in text and PRINTED_NOTE not in text


def test_hypothesis_3_writes_the_derived_torque_and_where_the_printed_line_differs():
    """C_f = π R² L f p₀ = (π/2) f R F = 1,571 N·m for f = 0,1, R = 10 mm, F = 1000 N."""
    text = _text(1000.0, 2.0)
    n = f"1{NNBSP}000\u00a0N"
    assert (
        f"Cf = π·R²·L·f·p₀ = (π/2)·f·R·F = (π/2) × 0,1 × 10\u00a0mm × {n} = 1,571\u00a0N·m" in text
    )
    assert "2·π·R²·p₀·f" in text and "oublie L" in text
    assert "pₘₐₓ = p₀ = 50\u00a0bar" in text  # hypothesis 1's pressure


def _zone_direction(svg: str) -> float:
    """Angle [deg] of the coloured zone's centroid from the first diagram's centre."""
    points = re.search(r'<polygon points="([^"]+)" fill="#[0-9a-f]{6}" fill-opacity', svg)
    assert points is not None
    xy = np.array([[float(v) for v in p.split(",")] for p in points.group(1).split()])
    cx, cy = SIZE / 2, 30.0 + BORE + LIMIT_ROOM
    mean = xy.mean(axis=0)
    return math.degrees(math.atan2(cy - mean[1], mean[0] - cx))


@pytest.mark.parametrize("angle", [0.0, 60.0, 135.0, -90.0])
def test_the_loaded_zone_is_centred_on_the_shafts_load(angle):
    svg = panel_html([_loaded(1000.0, 1.0, angle)], {**VALUES, "bearing_model": 1.0}, {})
    gap = (_zone_direction(svg) - angle + 180.0) % 360.0 - 180.0
    assert abs(gap) < 0.5


def test_the_shaft_presses_where_the_frame_pushes_it_from():
    """The frame pushing the shaft down (−z₀) means the shaft presses on the bore's top."""
    assert in_plane(X_AXIS, np.array([3.0, 0.0, -100.0])) == pytest.approx((0.0, 100.0))
    assert in_plane(X_AXIS, np.array([0.0, 40.0, 0.0])) == pytest.approx((-40.0, 0.0))


def test_the_rotors_folder_writes_the_courses_pressures(tmp_path: Path):
    """At 1500 rpm with 20 g of defect, bearing A carries the course's 54,42 N: 2,721 bar
    spread uniformly over 2RL = 2 cm², 3,464 bar at the cosine's peak, in the folder
    and in the table (one presentation)."""
    page = Page("rotor", tmp_path)
    try:
        page.tick(0.3)
        page.show(FOLDER)
        page.tick(0.6)

        def shown() -> str:
            return "\n".join(
                visible(str(h.content)) for h in page.client.gui.handles if h.kind == "html"
            )

        assert "Palier A : charge radiale F = 54,42\u00a0N" in shown()
        assert "pₘₐₓ = p₀ = 2,721\u00a0bar" in shown()
        assert "pₘₐₓ = p₀ = 0,747\u00a0bar" in shown()  # B: 14,94 N
        page.send(page.find("dropdown", "Hypothèse de pression dans les paliers"),
                  "Pression en cosinus (hypothèse 2)")  # fmt: skip
        page.tick(0.6)
        assert "pₘₐₓ = (4/π)·p₀ = 2·F / (π·R·L) = 3,464\u00a0bar" in shown()
        page.show(SCENE_FOLDER)
        page.tick(0.6)
        assert re.search(
            r"Pression maximale au palier A</span> \[bar\] \| [^<]*<span "
            r'data-readout="bearing_A_pmax"[^>]*>3,464<',
            page.markdown(),
        )
    finally:
        page.session.stop()
