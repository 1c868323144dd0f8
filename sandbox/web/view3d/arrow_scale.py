"""How long a force arrow is drawn and what its label says (no server).

Arrows are sized to the mechanism, not to the whole model (a rolling cylinder's 12 m
plane): shafts and heads are a fixed fraction of
:func:`~sandbox.web.view3d.geoms.mechanism_size`, and lengths are scaled so that the longest
arrow of each unit stays within :data:`MAX_REACH` of that size (the factor changes only
when an arrow would leave the view or shrink to a dot, so lengths can be compared from
one instant to the next). The page's arrows (:mod:`sandbox.web.view3d.arrows`) and the videos'
(:mod:`sandbox.web.video.frame`) share these rules.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from sandbox.physics.page import Arrow
from sandbox.physics.snapshot import Snapshot
from sandbox.written import written

MIN_LENGTH = 1e-4
"""Arrows shorter than this [m] are hidden (a cone alone would mislead)."""

SHAFT = 0.01
"""Shaft radius as a fraction of the mechanism's size (heads 2.5 and 6 shafts)."""

MAX_REACH = 0.6
"""Longest arrow of a unit, as a fraction of the mechanism's size, before user scaling."""

MIN_REACH = 0.05
"""Below this fraction the longest arrow of a unit is grown back (a dot says nothing)."""

USER_SCALES = (0.25, 4.0)
"""Range of the user's scale factor on the arrows' lengths."""


def arrow_points(arrow: Arrow, snapshot: Snapshot) -> tuple[np.ndarray, np.ndarray, float]:
    """Start and end [m] of an arrow in world coordinates (at the scene's own scale), and
    the magnitude of its vector."""
    origin, vector = arrow.fn(snapshot)
    origin = np.asarray(origin, dtype=float)
    vector = np.asarray(vector, dtype=float)
    return origin, origin + arrow.scale * vector, float(np.linalg.norm(vector))


def caption(
    arrow: Arrow,
    magnitude: float,
    unit: str,
    zero: Mapping[str, float],
    *,
    reading: float | None = None,
) -> str:
    """An arrow's label: its words, value and unit ("Palier A : 0,91 N"); its words
    alone for an arrow that shows a direction only. The value is ``reading``, the scene
    readout of the arrow's name at the same instant, when given (the pilon's sign, as the
    tables write it), else the arrow's magnitude. ``zero``: round-off by unit."""
    if not arrow.magnitude:
        return arrow.label
    value = magnitude if reading is None or not math.isfinite(reading) else reading
    # written as every view writes it: a speed in tr/min as the tables write it
    return f"{arrow.label} : {written(arrow.name, value, unit, zero=zero.get(unit, 0.0))}"


def auto_factor(current: float, longest: float, size: float) -> float:
    """The length factor of a unit's arrows: ``current`` unless its longest arrow
    (``longest`` metres at the scene's scale) would reach past :data:`MAX_REACH` or stay
    under :data:`MIN_REACH` of ``size``; then the factor that brings it to 3/4 of the
    reach (long enough to stick out of a body it starts inside, such as a rolling
    cylinder's contact forces)."""
    if not (math.isfinite(longest) and longest > 0):
        return current
    drawn = longest * current
    if MIN_REACH * size <= drawn <= MAX_REACH * size:
        return current
    return 0.75 * MAX_REACH * size / longest
