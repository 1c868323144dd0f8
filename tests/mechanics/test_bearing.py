"""Appendix B.2 (from global to local in a plain bearing) and 6.4.2 (a power chain),
checked by an independent derivation: the pressure distributions integrated numerically
over the loaded half of the bore, not the closed forms restated."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.mechanics import bearing
from sandbox.mechanics.bearing import COSINE, UNIFORM

R, L, F, f = 0.02, 0.03, 4000.0, 0.1  # a 40 mm shaft, 30 mm long, 4 kN, bronze on steel


def _integrals(hypothesis: str, n: int = 20_000) -> tuple[float, float, float]:
    """(resultant along the load, across it, friction moment about the axis) of the
    pressure over the bore, by the midpoint rule in φ (the z integral is a factor L)."""
    phi = -math.pi + (np.arange(2 * n) + 0.5) * (math.pi / n)  # the whole bore
    p = np.array([bearing.pressure(x, F, R, L, hypothesis) for x in phi])
    ds = R * (math.pi / n) * L
    along = float(np.sum(p * np.cos(phi)) * ds)
    across = float(np.sum(p * np.sin(phi)) * ds)
    moment = float(np.sum(f * p * R) * ds)
    return along, across, moment


@pytest.mark.parametrize("hypothesis", [UNIFORM, COSINE])
def test_the_pressure_integrates_back_to_the_load_and_the_friction_torque(hypothesis):
    along, across, moment = _integrals(hypothesis)
    assert along == pytest.approx(F, rel=1e-6)
    assert abs(across) < 1e-9 * F
    assert moment == pytest.approx(bearing.friction_torque(F, R, L, f, hypothesis), rel=1e-6)


def test_the_courses_closed_forms_and_where_the_printed_line_differs():
    p0 = bearing.mean_pressure(F, R, L)
    assert p0 == pytest.approx(F / (2 * R * L))  # hypothesis 1: 3,33 MPa, 33 bar
    assert bearing.max_pressure(F, R, L, COSINE) == pytest.approx(2 * F / (math.pi * R * L))
    assert bearing.max_pressure(F, R, L, COSINE) / p0 == pytest.approx(4 / math.pi)
    # hypothesis 3: π R² L f p₀ = (π/2) f R F; the course prints 2π R² p₀ f: 2/L apart
    derived = bearing.friction_torque(F, R, L, f)
    assert derived == pytest.approx(math.pi * R**2 * L * f * p0)
    assert derived == pytest.approx(math.pi / 2 * f * R * F)  # 12,6 N·m
    printed = bearing.printed_friction_torque(F, R, L, f)
    assert printed / derived == pytest.approx(2 / L)
    # the 200 bar limit: the load it allows
    assert bearing.LIMIT_PA == 2e7
    allowed = bearing.LIMIT_PA * 2 * R * L
    assert bearing.max_pressure(allowed, R, L) == pytest.approx(bearing.LIMIT_PA)


def test_bad_inputs_name_the_problem():
    with pytest.raises(ValueError, match="radius R"):
        bearing.mean_pressure(F, 0.0, L)
    with pytest.raises(ValueError, match="radial load"):
        bearing.mean_pressure(-1.0, R, L)
    with pytest.raises(ValueError, match="valid: uniform, cosine"):
        bearing.max_pressure(F, R, L, "parabolic")
    with pytest.raises(ValueError, match="friction coefficient"):
        bearing.friction_torque(F, R, L, math.nan)


def test_the_wind_turbines_chain_as_the_course_estimates_it():
    """6.4.2: 0.75 × 0.9 × 0.9 × 0.9 × 0.95 ≈ 0.52; for 5 MW of wind, 3.75 MW enter the
    gearbox and 375 kW of it become heat its lubrication must carry away."""
    assert bearing.overall_efficiency() == pytest.approx(0.519, abs=5e-4)
    flows = bearing.power_flow(5e6)
    assert [flow.stage.name for flow in flows][:2] == ["hélice", "multiplicateur"]
    gearbox = flows[1]
    assert gearbox.power_in == pytest.approx(3.75e6) and gearbox.loss == pytest.approx(3.75e5)
    assert flows[-1].power_out == pytest.approx(5e6 * bearing.overall_efficiency())
    assert sum(flow.loss for flow in flows) + flows[-1].power_out == pytest.approx(5e6)
    # Betz: 8/27 ρ S V³; a 126 m rotor in a 12 m/s wind, sea-level air
    area = math.pi * 63.0**2
    assert bearing.betz_power(1.225, area, 12.0) == pytest.approx(8 / 27 * 1.225 * area * 12.0**3)
    with pytest.raises(ValueError, match="between 0 and 1"):
        bearing.power_flow(1.0, [bearing.Stage("x", 1.5)])
