"""The back-and-forth move of a transfer robot: the trapezoidal speed profile of its
point-to-point cycle."""

from __future__ import annotations

import math


def back_and_forth(
    t: float, stroke: float, top_speed: float, accel_time: float, pause: float
) -> tuple[float, float]:
    """(position [m], speed [m/s]) of a point-to-point cycle between 0 and ``stroke``.

    Trapezoidal speed profile: accelerate at a = top_speed / accel_time, cruise at
    ``top_speed``, decelerate at −a, stand still for ``pause``; then the same move back
    to 0 and a pause; the cycle repeats for ever (period 2 (t_move + pause)). A stroke too
    short to reach ``top_speed`` gives a triangle of peak √(stroke a). Zero top speed or
    stroke: at rest at 0.

    Args:
        t: Time [s] since the start of the first move (t < 0: at rest at 0).
        stroke: Distance of one move [m] (>= 0).
        top_speed: Cruise speed [m/s] (its magnitude is used).
        accel_time: Time to reach ``top_speed`` from rest [s] (0: a speed step).
        pause: Standstill at each end [s] (>= 0).
    """
    x, v, _ = back_and_forth_motion(t, stroke, top_speed, accel_time, pause)
    return x, v


def back_and_forth_motion(
    t: float, stroke: float, top_speed: float, accel_time: float, pause: float
) -> tuple[float, float, float]:
    """(position [m], speed [m/s], acceleration [m/s²]) of :func:`back_and_forth`'s cycle.

    The acceleration is ±top_speed / accel_time on the ramps and 0 elsewhere (at a
    ramp's end, the value of the segment that starts there); a speed step (accel_time = 0)
    has no finite acceleration and reads 0.
    """
    v_top = abs(top_speed)
    if stroke <= 0 or v_top <= 0 or t <= 0:
        return 0.0, 0.0, 0.0
    ramp = max(accel_time, 0.0)
    if ramp > 0 and stroke < v_top * ramp:  # triangle: never reaches v_top
        v_top = math.sqrt(stroke * v_top / ramp)
        ramp = stroke / v_top
    move = stroke / v_top + ramp  # two half ramps add one ramp to stroke / v_top
    t = t % (2.0 * (move + pause))
    back = t >= move + pause
    if back:
        t -= move + pause
    if t >= move:
        x, v, a = stroke, 0.0, 0.0
    elif ramp > 0 and t < ramp:
        x, v, a = 0.5 * v_top * t * t / ramp, v_top * t / ramp, v_top / ramp
    elif ramp > 0 and t > move - ramp:
        left = move - t
        x, v, a = stroke - 0.5 * v_top * left * left / ramp, v_top * left / ramp, -v_top / ramp
    else:
        x, v, a = v_top * (t - 0.5 * ramp), v_top, 0.0
    return (stroke - x, -v, -a) if back else (x, v, a)
