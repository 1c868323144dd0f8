"""From global to local in a plain bearing (course, appendix B.2): a shaft of radius R
turning in a bore of length L carries a radial load F; under a chosen pressure
distribution, the largest contact pressure (to keep under 200 bar) and the friction
torque it costs.

The load F acts along a direction of the bore's plane; φ is the angle of a point of the
bore from that direction. The loaded half is φ ∈ [−π/2, π/2]; an element of surface is
R dφ dz, z ∈ [−L/2, L/2].

- **Uniform** (hypothesis 1): p(φ) = p₀ on the loaded half. The resultant is
  ∫ p₀ cos φ R L dφ = 2 R L p₀, hence p₀ = F / (2 R L): the load over the bore's
  projected area.
- **Cosine** (hypothesis 2): p(φ) = p_max cos φ. The resultant is
  ∫ p_max cos² φ R L dφ = (π/2) R L p_max, hence p_max = 2F / (π R L) = (4/π) p₀.
- **With friction** (hypothesis 3: hypothesis 1 plus Coulomb's f): a tangential f·p
  opposes the sliding; its moment about the axis is ∫ R · f p₀ · R L dφ over a span of π,
  hence C_f = π R² L f p₀ = (π/2) f R F. Under the cosine distribution the same
  integral gives C_f = 2 f R² L p_max = (4/π) f R F.

The course prints C_f = 2π R² p₀ f for hypothesis 3: the integral over the half bore
spans π, not 2π, and the length L of the bore is missing (its factor
∫ dz over [−L/2, L/2]). :func:`printed_friction_torque` keeps the printed line so that a
page can show both and say where they differ; every number here is the derivation's.

Also the course's power chain (6.4.2, the wind turbine): Betz's power P₁ = 8/27 ρ S V³
through efficiencies in series, the overall efficiency their product.

Pure functions (math only): no MuJoCo, no state.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

UNIFORM, COSINE = "uniform", "cosine"
"""The two pressure distributions (hypotheses 1 and 2; 3 is 1 with friction)."""
HYPOTHESES = (UNIFORM, COSINE)

LIMIT_PA = 200e5
"""Contact pressure the course's surfaces must stay under: 200 bar [Pa]."""


def _check(load: float, radius: float, length: float) -> None:
    if not (math.isfinite(load) and load >= 0.0):
        raise ValueError(f"the radial load must be a finite force >= 0 N, got {load!r}")
    for name, value in (("radius R", radius), ("length L", length)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"the bore's {name} must be a finite length > 0 m, got {value!r}")


def _hypothesis(hypothesis: str) -> str:
    if hypothesis not in HYPOTHESES:
        raise ValueError(
            f"unknown pressure distribution {hypothesis!r}; valid: {', '.join(HYPOTHESES)}"
        )
    return hypothesis


def mean_pressure(load: float, radius: float, length: float) -> float:
    """p₀ = F / (2 R L) [Pa]: hypothesis 1's uniform pressure (the load over the bore's
    projected area 2 R L)."""
    _check(load, radius, length)
    return load / (2.0 * radius * length)


def max_pressure(load: float, radius: float, length: float, hypothesis: str = UNIFORM) -> float:
    """The largest contact pressure [Pa]: p₀ (uniform) or 2F / (π R L) (cosine)."""
    p0 = mean_pressure(load, radius, length)
    return p0 if _hypothesis(hypothesis) == UNIFORM else 4.0 / math.pi * p0


def pressure(
    phi: float, load: float, radius: float, length: float, hypothesis: str = UNIFORM
) -> float:
    """The contact pressure [Pa] at angle ``phi`` [rad] from the load's direction: 0 on
    the unloaded half."""
    p_max = max_pressure(load, radius, length, hypothesis)
    c = math.cos(phi)
    if c < 0.0 or (c == 0.0 and hypothesis == COSINE):
        return 0.0
    return p_max if hypothesis == UNIFORM else p_max * c


def friction_torque(
    load: float, radius: float, length: float, friction: float, hypothesis: str = UNIFORM
) -> float:
    """C_f [N·m], the moment of Coulomb friction about the axis: (π/2) f R F (uniform,
    hypothesis 3) or (4/π) f R F (cosine). Independent of L: a longer bore spreads the
    same load at a lower pressure."""
    _check(load, radius, length)
    if not (math.isfinite(friction) and friction >= 0.0):
        raise ValueError(
            f"the friction coefficient f must be a finite number >= 0, got {friction!r}"
        )
    factor = math.pi / 2.0 if _hypothesis(hypothesis) == UNIFORM else 4.0 / math.pi
    return factor * friction * radius * load


def printed_friction_torque(load: float, radius: float, length: float, friction: float) -> float:
    """The course's printed line for hypothesis 3, C_f = 2π R² p₀ f: its unit is the
    newton, not N·m, since L is missing. Kept to test what the page says about it; never
    a number the page states as the friction torque."""
    return 2.0 * math.pi * radius**2 * mean_pressure(load, radius, length) * friction


# -- the power chain (6.4.2) ----------------------------------------------------------------
def betz_power(density: float, area: float, speed: float) -> float:
    """P₁ = 8/27 ρ S V³ [W]: the wind's power a rotor of swept area ``area`` [m²] can
    take at most (Betz's limit), air of ``density`` [kg/m³] at ``speed`` [m/s]."""
    for name, value in (
        ("air density ρ", density),
        ("swept area S", area),
        ("wind speed V", speed),
    ):
        if not (math.isfinite(value) and value >= 0.0):
            raise ValueError(f"the {name} must be a finite number >= 0, got {value!r}")
    return 8.0 / 27.0 * density * area * speed**3


@dataclass(frozen=True)
class Stage:
    """One organ of a power chain: its name and efficiency ρ (power out / power in)."""

    name: str
    efficiency: float


WIND_TURBINE = (
    Stage("hélice", 0.75),
    Stage("multiplicateur", 0.9),
    Stage("alternateur", 0.9),
    Stage("transformateur", 0.9),
    Stage("lignes électriques", 0.95),
)
"""The course's estimates for an offshore wind turbine (6.4.2)."""


@dataclass(frozen=True)
class Flow:
    """What one stage of a chain passes on: the power entering and leaving it [W] and
    the power it turns into heat [W]."""

    stage: Stage
    power_in: float
    power_out: float

    @property
    def loss(self) -> float:
        return self.power_in - self.power_out


def power_flow(power_in: float, chain: Sequence[Stage] = WIND_TURBINE) -> list[Flow]:
    """The powers through a chain in series, stage by stage, from ``power_in`` [W]."""
    flows = []
    power = power_in
    for stage in chain:
        if not (math.isfinite(stage.efficiency) and 0.0 <= stage.efficiency <= 1.0):
            raise ValueError(
                f"the efficiency of {stage.name!r} must be between 0 and 1, "
                f"got {stage.efficiency!r}"
            )
        out = power * stage.efficiency
        flows.append(Flow(stage, power, out))
        power = out
    return flows


def overall_efficiency(chain: Sequence[Stage] = WIND_TURBINE) -> float:
    """The chain's efficiency: the product of its stages' (0.52 for the wind turbine)."""
    return math.prod(stage.efficiency for stage in chain)
