"""What a run of a parameter study keeps of its samples: one number (:data:`STATISTICS`),
the last one, their mean, their largest value, half their range, an order over the last
revolution, an oscillation's period or the time of an event (see :func:`reduce`).
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.scenes.compressor import fit_orders  # the course's orders, fitted once

STATISTICS = ("final", "mean", "max", "amplitude", "order1", "order2", "period", "onset")
"""What a run's samples are reduced to: the last one, their mean, their largest value,
half their range, the amplitude of the first or second order over the last revolution
of the scene's first hinge (least squares on cos kθ, sin kθ), or the mean time between
two rises through the middle of their range (an oscillation's period, e.g. the flips of
a solid launched about its intermediate axis), or the time of an event: the first instant
the readout leaves its value at the settling time by more than :data:`ONSET` of its
largest departure over the run and by more than :data:`ONSET_FLOOR` in its unit (a slip
velocity that starts growing, a contact flag that drops); NaN when it never does."""

ONSET = 0.01
"""Share of a readout's largest departure that marks an event (statistic ``onset``)."""

ONSET_FLOOR = 1e-3
"""Smallest departure that is an event, in the readout's unit (1 mm/s of slip, 1 mN):
a soft contact lets a rolling cylinder creep at 10⁻⁶ m/s, which is no slip."""


def period(times: np.ndarray, values: np.ndarray) -> float:
    """Mean time between rises through the middle of the samples' range (linear
    interpolation between samples); NaN without two rises."""
    middle = 0.5 * (float(values.max()) + float(values.min()))
    a = values - middle
    up = np.nonzero((a[:-1] < 0.0) & (a[1:] >= 0.0))[0]
    if len(up) < 2:
        return math.nan
    at = times[up] - a[up] * (times[up + 1] - times[up]) / (a[up + 1] - a[up])
    return float(np.mean(np.diff(at)))


def onset(times: np.ndarray, values: np.ndarray) -> float:
    """The first time ``values`` leaves its first value by more than :data:`ONSET` of
    its largest departure and :data:`ONSET_FLOOR` (NaN when it never does)."""
    departure = np.abs(values - values[0])
    largest = float(departure.max()) if len(departure) else 0.0
    if not math.isfinite(largest) or largest <= ONSET_FLOOR:
        return math.nan
    return float(times[int(np.argmax(departure > max(ONSET * largest, ONSET_FLOOR)))])


def reduce(
    statistic: str,
    values: np.ndarray,
    angles: np.ndarray | None,
    times: np.ndarray | None = None,
) -> float:
    """One number from a run's samples (``angles``: the hinge's, for the orders;
    ``times``: their times, for the period)."""
    if len(values) == 0:
        return math.nan
    if statistic == "onset":
        return onset(times, values) if times is not None and len(times) == len(values) else math.nan
    if statistic == "period":
        return (
            period(times, values) if times is not None and len(times) == len(values) else math.nan
        )
    if statistic == "final":
        return float(values[-1])
    if statistic == "mean":
        return float(values.mean())
    if statistic == "max":
        return float(values.max())
    if statistic == "amplitude":
        return float(values.max() - values.min()) / 2.0
    order = int(statistic[-1])
    if angles is None or len(angles) < 8:
        return math.nan
    end = angles[-1]
    turn = np.abs(angles - end) <= 2 * math.pi * (1 + 1e-9)  # the last revolution
    if abs(angles[turn][0] - end) < 2 * math.pi * 0.9:  # less than a revolution sampled
        return math.nan
    return float(fit_orders(angles[turn], values[turn], orders=max(order, 4))[order])
