"""What a plain bearing's parameters mean (course, appendix B.2): the pressure hypothesis
chosen, whether its friction counts, the largest contact pressure and the friction
torque under a load, and a bearing's radial load at a state. Shared by the scenes (their
readouts and the friction they apply) and the page's folder « Pression dans les paliers »,
so that both read the values one way.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from sandbox.mechanics import bearing as mech
from sandbox.physics.page import Bearing
from sandbox.physics.snapshot import Snapshot

HYPOTHESIS_WORDS = (
    "Pression uniforme (hypothèse 1)",
    "Pression en cosinus (hypothèse 2)",
    "Uniforme avec frottement f (hypothèse 3)",
)
"""The page's words for ``bearing_model`` = 0, 1, 2."""
UNIFORM, COSINE, FRICTION = 0, 1, 2

FRICTION_WORDS = ("Non : liaisons parfaites", "Oui : couple Cf selon la charge")
"""The page's words for ``bearing_friction`` = 0, 1."""


def friction_on(values: Mapping[str, float]) -> bool:
    """The bearings' friction torque is applied in the simulation."""
    return float(values.get("bearing_friction", 0.0)) > 0.5


def radial(load: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """The part of ``load`` across ``axis`` (a unit vector)."""
    load = np.asarray(load, dtype=float)
    return load - float(load @ axis) * np.asarray(axis, dtype=float)


def radial_load(b: Bearing, s: Snapshot) -> np.ndarray:
    """The frame's force on the shaft across the bore [N], world axes; cached a snapshot."""
    key = f"bearing_{b.name}_radial"
    if key not in s.cache:
        s.cache[key] = radial(b.load(s), np.asarray(b.axis, dtype=float))
    return np.asarray(s.cache[key])


MM = 1e-3
"""The bore's parameters are typed in millimetres, as bearings are drawn and sold."""


def bore(values: Mapping[str, float]) -> tuple[float, float]:
    """The bore's radius R and length L [m] (the parameters ``bearing_R`` and
    ``bearing_L`` are in mm)."""
    return values["bearing_R"] * MM, values["bearing_L"] * MM


def hypothesis(values: Mapping[str, float]) -> int:
    """``bearing_model`` as 0, 1 or 2 (a value out of range reads as the nearest)."""
    return int(min(max(round(float(values.get("bearing_model", 0.0))), 0), 2))


def pressure_model(values: Mapping[str, float]) -> str:
    """The pressure distribution of the chosen hypothesis (3 is 1's with friction)."""
    return mech.COSINE if hypothesis(values) == COSINE else mech.UNIFORM


def max_pressure(load: float, values: Mapping[str, float]) -> float:
    """The largest contact pressure [Pa] under ``load`` [N] for these values."""
    radius, length = bore(values)
    return mech.max_pressure(load, radius, length, pressure_model(values))


def has_friction(values: Mapping[str, float]) -> bool:
    """Friction counts: hypothesis 3, or the friction applied in the simulation."""
    return hypothesis(values) == FRICTION or friction_on(values)


def friction_torque(load: float, values: Mapping[str, float]) -> float:
    """The friction torque [N·m] under ``load`` [N]: (π/2) f R F (uniform pressure,
    hypothesis 3) or (4/π) f R F (the cosine's, when the friction is applied with
    hypothesis 2); 0 without friction (the course's perfect joints)."""
    if not has_friction(values):
        return 0.0
    return mech.friction_torque(
        load, *bore(values), values["bearing_f"],
        pressure_model(values),
    )  # fmt: skip
