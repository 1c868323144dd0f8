"""Measures a scene's :class:`~sandbox.physics.spec.Accuracy` can use in ``sandbox bench``.

Each returns a function of the sampled readouts (name -> array over time) and the
parameter values, so a scene states *what* it compares in one line.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from sandbox.physics.spec import Series, Values

Measure = Callable[[Series, Values], float]


def worst_relative_error(key: str, reference: Callable[[Values], Mapping[str, float]]) -> Measure:
    """max over the run of |key − course| / |course| (a constant closed form)."""

    def measure(series: Series, values: Values) -> float:
        ref = float(reference(values)[key])
        return float(np.max(np.abs(np.asarray(series[key]) - ref)) / abs(ref))

    return measure


def relative_drift(name: str) -> Measure:
    """max over the run of |x(t) − x(0)| / |x(0)| (a conserved quantity)."""

    def measure(series: Series, values: Values) -> float:
        x = np.asarray(series[name], dtype=float)
        return float(np.max(np.abs(x - x[0])) / max(abs(x[0]), 1e-300))

    return measure


def largest(name: str) -> Measure:
    """max over the run of |x| (a violation that should stay 0)."""

    def measure(series: Series, values: Values) -> float:
        return float(np.max(np.abs(np.asarray(series[name], dtype=float))))

    return measure


def residual_over_peak(residual: str, peak: str) -> Measure:
    """max |residual| / max |peak| (e.g. the energy theorem against the motor power)."""

    def measure(series: Series, values: Values) -> float:
        top = float(np.max(np.abs(np.asarray(series[peak], dtype=float))))
        return float(np.max(np.abs(np.asarray(series[residual], dtype=float)))) / max(top, 1e-300)

    return measure


def energy_drift() -> Measure:
    """max over the run of |(T + V)(t) − (T + V)(0)| / max |T| (mechanical energy)."""

    def measure(series: Series, values: Values) -> float:
        e = np.asarray(series["T"], dtype=float) + np.asarray(series["V"], dtype=float)
        scale = max(float(np.max(np.abs(series["T"]))), 1e-300)
        return float(np.max(np.abs(e - e[0])) / scale)

    return measure
