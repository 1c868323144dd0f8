"""Statistics of the classroom benchmark's samples: the percentile and the summary (min,
median, p95, max) a report gives of each figure.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Sequence


def percentile(values: Sequence[float], q: float) -> float:
    """Linear-interpolation percentile (numpy's default); NaN for no values.

    Args:
        values: Samples.
        q: Percentile in [0, 100].
    """
    data = sorted(values)
    if not data:
        return math.nan
    pos = (len(data) - 1) * q / 100.0
    lo = math.floor(pos)
    hi = min(lo + 1, len(data) - 1)
    return data[lo] + (data[hi] - data[lo]) * (pos - lo)


def summary(values: Sequence[float]) -> dict[str, float]:
    """``min``, ``median``, ``p95`` and ``max`` of ``values`` (NaN when empty)."""
    if not values:
        return {k: math.nan for k in ("min", "median", "p95", "max")}
    return {
        "min": min(values),
        "median": statistics.median(values),
        "p95": percentile(values, 95),
        "max": max(values),
    }
