"""Shared test models (inline MJCF) as fixtures writing them to a temporary file."""

from __future__ import annotations

from pathlib import Path

import pytest

DIVERGING = """
<mujoco>
  <option timestep="0.05" integrator="Euler"/>
  <worldbody>
    <body>
      <joint type="slide" axis="1 0 0" stiffness="1e6"/>
      <geom type="sphere" size="0.1" mass="0.001"/>
    </body>
  </worldbody>
  <keyframe><key qpos="0.1"/></keyframe>
</mujoco>
"""
"""A stiff spring (ω ≈ 3·10⁴ rad/s) integrated by explicit Euler at dt = 0.05 s: ω dt ≫ 2."""


@pytest.fixture
def diverging_xml(tmp_path: Path) -> Path:
    path = tmp_path / "diverging.xml"
    path.write_text(DIVERGING)
    return path
