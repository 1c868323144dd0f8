"""The slider-crank shared by the compressor and the engine: the least-squares orders of
its force over a revolution and the benchmark's accuracy entry, measured on both scenes.

Every cylinder of :mod:`sandbox.scenes.engine` is the compressor's slider-crank
(:mod:`sandbox.scenes.compressor`): both read the pilon's orders with :func:`fit_orders`
and are benchmarked with :data:`ACCURACY` (the pilon against the course's at 17,000 rpm).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from sandbox.physics.spec import Accuracy, Values
from sandbox.scenes.measures import largest, residual_over_peak

FITTED_ORDERS = 12
"""Orders fitted together (as many as the samples allow): a slider-crank's force has
every even order, and a revolution sampled 29 times at the engine's default step leaked
its orders 4 to 8 into order 1 when only orders up to 4 were fitted (2x10⁻³ N where the
course says 0; 4x10⁻¹⁰ N with twelve)."""


def fit_orders(theta: np.ndarray, values: np.ndarray, orders: int = 4) -> np.ndarray:
    """Least-squares amplitudes of orders 0..``orders`` of ``values`` sampled at angles θ
    (fitted with orders up to :data:`FITTED_ORDERS`, or as many as the samples allow)."""
    fitted = max(orders, min(FITTED_ORDERS, (len(theta) - 3) // 2))
    cols = [np.ones_like(theta)]
    for k in range(1, fitted + 1):
        cols += [np.cos(k * theta), np.sin(k * theta)]
    coef, *_ = np.linalg.lstsq(np.stack(cols, axis=1), values, rcond=None)
    amp = np.concatenate([[abs(coef[0])], np.hypot(coef[1::2], coef[2::2])])
    return amp[: orders + 1]


def peak_error(series: Any, values: Values) -> float:
    """max |pilon − course| / max |course pilon| over the run."""
    ref = np.asarray(series["pilon_ref"])
    return float(np.max(np.abs(np.asarray(series["pilon"]) - ref)) / np.max(np.abs(ref)))


# Measured at 17,000 rpm, the hardest speed the course mentions: at 3000 rpm every RK4
# timestep up to 1e-4 s gives the pilon within 1e-4, so only the top speed separates
# them; first-order integrators drain 1-20 % of the motor power in the closure.
ACCURACY = Accuracy(
    key="pilon",
    readouts=("pilon", "pilon_ref", "P_int", "P_ext", "closure_error"),
    duration=0.04,
    values={"speed_rpm": 17000.0},
    timesteps=(1e-5, 3e-5, 1e-4, 3e-4, 1e-3),
    error=peak_error,
    invariant="energy theorem (|P_int| / peak P_ext)",
    drift=residual_over_peak("P_int", "P_ext"),
    constraint=largest("closure_error"),
    settle=0.003,  # the servo takes a few steps to build its torque
    drift_tol=1e-3,  # the limit on the energy-theorem residual
    constraint_tol=1e-6,
    same_angle=True,  # the default step is a crank angle (ω·dt): see Accuracy.same_angle
)
"""Accuracy entry of the compressor and of the engine (the same slider-crank benchmark)."""


def revolution_table(
    rows: Sequence[Sequence[float]], columns: tuple[str, ...]
) -> dict[str, np.ndarray]:
    """One revolution's samples as the cycle chart reads them: ``rows`` of (θ, then one
    value per name of ``columns``) sorted by θ in [0, 2π), with ``angle_deg`` (that angle
    in degrees) and ``theta`` (θ as sampled) ahead of the named columns."""
    a = np.array(rows, dtype=float).reshape(-1, 1 + len(columns))
    a = a[np.argsort(np.mod(a[:, 0], 2 * np.pi))]
    out = {"angle_deg": np.degrees(np.mod(a[:, 0], 2 * np.pi)), "theta": a[:, 0]}
    out.update({name: a[:, 1 + i] for i, name in enumerate(columns)})
    for column in out.values():  # read only: sessions may share one (an imposed revolution)
        column.flags.writeable = False
    return out
