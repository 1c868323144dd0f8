"""Wheel-balancing machine (course 7.1, 7.2): a car wheel, its unknown unbalance, two clips.

The machine's shaft turns about (O, x0) at ``speed_rpm`` in two bearings, A inside the
machine (x = −0.30 m) and B next to the wheel (x = −0.10 m); O is the hub face. The wheel
(shaft, flange, aluminium disc and rim, tyre) carries an unbalance the student does not
see: a heavy spot on the tread (static unbalance) and a tyre mounted askew (couple
unbalance). With ``mystery`` > 0 those come from :data:`MYSTERIES` and the sliders keep
showing the free setting: no parameter, readout or marker shows the hidden values.

The machine reads its two bearing forces (the frame's action on the shaft, split between
A and B), turns them into the static and couple unbalance (course 7.2.1:
``P_A + P_B = ω² S``, ``x_A P_A + x_B P_B = ω² C``) and displays the two clip-on masses
and angles that cancel both (7.2.3) in the rim's planes, x = 15 mm and 185 mm at 190 mm
from the axis (:mod:`sandbox.mechanics.two_planes`). Angles run from the valve (y1)
towards z1.

``supports`` = 1 is the lab bench of figure 40: the bearing housing hangs on springs
(slides y, z and tilts about y, z, stiffness and damping per bearing), accelerometers on
the bearings read the housing's vibration (amplitude and phase against the valve, as the
tachometer of the helicopter's balancing kit); a trial mass in either plane gives the
influence coefficients, from which :func:`influence_solution` computes the clips.

The package holds one concept per module: :mod:`~sandbox.scenes.wheel_balancer.params`
(dimensions, hidden wheels, parameter table), :mod:`~sandbox.scenes.wheel_balancer.geometry`
(where the parts sit), :mod:`~sandbox.scenes.wheel_balancer.course` (the closed forms),
:mod:`~sandbox.scenes.wheel_balancer.model` (the MJCF edits, drive and initial state),
:mod:`~sandbox.scenes.wheel_balancer.readouts` (what the machine measures) and
:mod:`~sandbox.scenes.wheel_balancer.scene` (the spec, the influence method, the timestep).
"""

from __future__ import annotations

from sandbox.scenes.wheel_balancer.course import (
    bare,
    machine_solution,
    reference,
    supports_model,
    unbalance,
    wheel_properties,
)
from sandbox.scenes.wheel_balancer.params import HIDDEN, MYSTERIES, PARAMS
from sandbox.scenes.wheel_balancer.readouts import machine_clips
from sandbox.scenes.wheel_balancer.scene import SCENE, influence_solution

__all__ = [
    "HIDDEN",
    "MYSTERIES",
    "PARAMS",
    "SCENE",
    "bare",
    "influence_solution",
    "machine_clips",
    "machine_solution",
    "reference",
    "supports_model",
    "unbalance",
    "wheel_properties",
]
