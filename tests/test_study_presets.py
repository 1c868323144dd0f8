"""Every scene's parameter-study preset ("Étude paramétrique") against the course's law:
each simulated point on the closed form within the tolerance the scene's accuracy allows
(relative to the curve's largest value), and the law's shape where the course states it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.scenes import SCENES
from sandbox.sweep import Measure, Study, Vary, run_study

TOLERANCE = {
    "rotor": 1e-6,  # course 7.2, a uniform rotation: every integrator exact (bench ~1e-14)
    "wheel_balancer": 1e-6,  # the same law on the balancing machine
    "robot_axis": 1e-12,  # J_eq from the model's own inertias: exact
    "compressor": 5e-3,  # order 2 fitted on the last revolution (bench: 0.5 %)
    "engine": 5e-3,  # the same fit on four cylinders
    "rolling_cylinder": 1e-4,  # soft contact (bench: 1e-4 on a)
    "heavy_gyroscope": 1e-4,  # mean precession against the steady one
    "inertia": 1e-5,  # Euler's period of the flip (bench: 1e-5)
    "wind_turbine": 1e-9,  # each run starts at its own steady state: exact
}
"""Largest |simulated − course| / max |course| of each scene's preset."""

PRESETS = [(name, p) for name, scene in SCENES.items() for p in scene.page.study_presets]


def _study(name: str, preset, count: int = 5) -> Study:
    """The preset with fewer points (its end points kept): what a student runs."""
    n, a, b, _ = preset.vary
    return Study(
        name,
        (Vary(n, a, b, count),),
        Measure(preset.measure, preset.statistic),
        preset.duration,
        preset.settle,
        fixed=tuple((k, repr(v)) for k, v in preset.fixed.items()),
        course=preset.course,
    )


def test_every_scene_with_a_closed_form_proposes_a_study():
    assert {name for name, _ in PRESETS} == set(TOLERANCE)


@pytest.mark.parametrize(("name", "preset"), PRESETS, ids=[f"{n}-{p.measure}" for n, p in PRESETS])
def test_the_preset_follows_the_course(name, preset):
    rows = run_study(_study(name, preset))
    assert all(r["status"] == "ok" for r in rows)
    course = np.array([r["closed_form"] for r in rows])
    measure = np.array([r["measure"] for r in rows])
    assert np.isfinite(course).all(), "a preset always has its closed form"
    scale = np.max(np.abs(course))
    assert np.max(np.abs(measure - course)) <= TOLERANCE[name] * scale


def test_the_laws_shapes():
    """ω² for the rotor's bearing (course 7.2), 1/ω for the fast top's precession, and
    a pilon's second order that grows with R/L (course 7.3: its exact value, with the
    rod's mass split that changes with L, is checked point by point above)."""
    by = {name: p for name, p in PRESETS}
    rotor = run_study(_study("rotor", by["rotor"]))
    k = [r["measure"] / r["speed_rpm"] ** 2 for r in rotor if r["speed_rpm"] > 0]
    assert max(k) == pytest.approx(min(k), rel=1e-9)
    top = run_study(_study("heavy_gyroscope", by["heavy_gyroscope"]))
    product = [r["measure"] * r["spin_rpm"] for r in top]
    # the fast top's 1/ω (the exact steady precession adds a term that fades as ω grows:
    # 1.4 % from 2000 to 10,000 rpm)
    assert max(product) == pytest.approx(min(product), rel=0.02)
    pilon = run_study(_study("compressor", by["compressor"], 3))
    x_words, x_of = by["compressor"].x
    assert x_words == "Rapport R/L"
    x = [x_of({"R": 0.015, "L": r["L"]}) for r in pilon]
    assert x == sorted(x, reverse=True)  # L grows, R/L falls
    assert pilon[0]["measure"] > pilon[1]["measure"] > pilon[2]["measure"]


def test_the_rolling_cylinder_crosses_the_slip_threshold():
    """Below tan α = 3μ (μ = 0.3: α ≈ 42°) the cylinder rolls, a = (2/3) g sin α;
    above, it slips, a = g (sin α − μ cos α): the preset's range holds both."""
    preset = next(p for n, p in PRESETS if n == "rolling_cylinder")
    n, a, b, _ = preset.vary
    assert a < math.degrees(math.atan(0.9)) < b
    rows = run_study(
        Study("rolling_cylinder", (Vary(n, 30.0, 55.0, 2),), Measure("a"), preset.duration)
    )
    g = 9.81
    rolls, slips = rows
    assert rolls["measure"] == pytest.approx(2 / 3 * g * math.sin(math.radians(30)), rel=1e-4)
    s = math.radians(55)
    assert slips["measure"] == pytest.approx(g * (math.sin(s) - 0.3 * math.cos(s)), rel=1e-4)
