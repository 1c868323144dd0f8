"""Imposed motions of a mechanism's input, as the course writes them: the position, speed
and acceleration of one coordinate (a crank's angle θ, a carriage's position y) as exact
functions of time, from an *anchor* (the instant, position and speed they start from).

Two laws cover the course's examples:

- :func:`set_speed`: a motor that brings its shaft to a set speed ω_c, at once or
  through a first-order lag of time constant τ (ω(t) = ω_c + (ω₀ − ω_c) e^(−s/τ), the
  filter a start from rest follows);
- :func:`follow`: a reference motion x_ref(t) (a trapezoidal speed profile) joined from
  the anchor by a critically damped return of time constant T, so that the position and
  the speed are continuous when the law starts.

Pure functions (numpy only): no MuJoCo, no state.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

Motion = tuple[float, float, float]
"""(position, speed, acceleration) of the input at one instant [rad or m, /s, /s²]."""


@dataclass(frozen=True)
class Anchor:
    """Where an imposed law starts: the instant [s], the input's position and speed."""

    time: float
    position: float
    speed: float


def set_speed(anchor: Anchor, target: float, tau: float, t: float) -> Motion:
    """A shaft brought to the speed ``target`` from the anchor.

    τ = 0: the speed is ``target`` from the anchor on (a step: the course's constant ω).
    τ > 0: ω(t) = ω_c + (ω₀ − ω_c) e^(−s/τ) with s = t − t₀, so
    θ(t) = θ₀ + ω_c s + (ω₀ − ω_c) τ (1 − e^(−s/τ)) and θ'' = −(ω₀ − ω_c) e^(−s/τ) / τ
    (``expm1`` keeps every digit for s ≪ τ).

    Args:
        anchor: Instant [s], position [rad] and speed [rad/s] the law starts from.
        target: Set speed ω_c [rad/s].
        tau: Time constant of the lag [s] (0: none).
        t: Time [s] (at or after the anchor).
    """
    s = t - anchor.time
    if tau <= 0.0:
        return anchor.position + target * s, target, 0.0
    gap = anchor.speed - target
    decay = math.exp(-s / tau)
    return (
        anchor.position + target * s - gap * tau * math.expm1(-s / tau),
        target + gap * decay,
        -gap * decay / tau,
    )


def follow(anchor: Anchor, reference: Callable[[float], Motion], settle: float, t: float) -> Motion:
    """The reference motion x_ref(t), joined from the anchor without a jump.

    The gap e = x − x_ref starts at the anchor's (e₀, ė₀) and dies out critically damped:
    e(s) = (e₀ + (ė₀ + e₀/T) s) e^(−s/T), s = t − t₀, which keeps the position and the
    speed continuous when the law starts (e.g. after a simulated stretch whose servo
    followed the reference with a small lag); it is exactly the reference once the gap is
    zero.

    Args:
        anchor: Instant [s], position and speed the law starts from.
        reference: x_ref(t) -> (position, speed, acceleration).
        settle: Time constant T of the return to the reference [s] (> 0).
        t: Time [s] (at or after the anchor).
    """
    x, v, a = reference(t)
    x0, v0, _ = reference(anchor.time)
    e0, de0 = anchor.position - x0, anchor.speed - v0
    if e0 == 0.0 and de0 == 0.0:
        return x, v, a
    s = t - anchor.time
    k = de0 + e0 / settle
    decay = math.exp(-s / settle)
    e = (e0 + k * s) * decay
    de = (k - (e0 + k * s) / settle) * decay
    dde = (-2.0 * k / settle + (e0 + k * s) / settle**2) * decay
    return x + e, v + de, a + dde
