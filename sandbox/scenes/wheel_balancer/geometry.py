"""Where the wheel's parts sit: the point masses (heavy spot, clips, trial mass), the tilted
tyre, the tubes' inertias and the soft supports' springs, shared by the model edits and
the closed forms.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.mechanics import hollow_cylinder
from sandbox.physics.spec import Values
from sandbox.scenes.wheel_balancer.params import (
    CLIP_RADIUS,
    DAMPER,
    DEFECT_RADIUS,
    HALF_SPAN,
    SPRING,
    X_INNER,
    X_OUTER,
    X_WHEEL,
    effective,
)


def _radial(x: float, radius: float, angle_deg: float) -> np.ndarray:
    a = math.radians(angle_deg)
    return np.array([x, radius * math.cos(a), radius * math.sin(a)])


def tyre_axis(values: Values) -> np.ndarray:
    """Unit axis of the tyre in the wheel frame: tilted by β towards the direction ψ."""
    v = effective(values)
    b, p = math.radians(v["skew_deg"]), math.radians(v["skew_angle_deg"])
    return np.array([math.cos(b), math.sin(b) * math.cos(p), math.sin(b) * math.sin(p)])


def _trial_x(values: Values) -> float | None:
    plane = int(round(values["trial_plane"]))
    return {1: X_INNER, 2: X_OUTER}.get(plane)


def mass_points(values: Values) -> list[tuple[str, float, np.ndarray]]:
    """(geom name, mass [kg], position in the wheel frame [m]) of the point masses."""
    v = effective(values)
    trial_x = _trial_x(values)
    return [
        (
            "defect",
            v["defect_mass_g"] / 1000,
            _radial(X_WHEEL, DEFECT_RADIUS, v["defect_angle_deg"]),
        ),
        (
            "clip_inner",
            values["mass_inner_g"] / 1000,
            _radial(X_INNER, CLIP_RADIUS, values["angle_inner_deg"]),
        ),
        (
            "clip_outer",
            values["mass_outer_g"] / 1000,
            _radial(X_OUTER, CLIP_RADIUS, values["angle_outer_deg"]),
        ),
        (
            "trial",
            values["trial_g"] / 1000 if trial_x is not None else 0.0,
            _radial(trial_x if trial_x is not None else X_INNER, CLIP_RADIUS, 0.0),
        ),
    ]


def tube_inertia(mass: float, outer: float, inner: float, width: float) -> np.ndarray:
    """Inertia at G of a tube, axis z (the tyre, the rim barrel)."""
    return hollow_cylinder(mass, outer, inner, width)


def z_to(axis: np.ndarray) -> np.ndarray:
    """Quaternion (w, x, y, z) of the rotation that takes z onto ``axis``."""
    quat = np.zeros(4)
    mujoco.mju_quatZ2Vec(quat, np.asarray(axis, dtype=float))
    return quat


def springs() -> tuple[float, float, float, float]:
    """(k_t, c_t, k_r, c_r) of the housing's joints from the per-bearing springs."""
    d2 = HALF_SPAN * HALF_SPAN
    return 2 * SPRING, 2 * DAMPER, 2 * SPRING * d2, 2 * DAMPER * d2
