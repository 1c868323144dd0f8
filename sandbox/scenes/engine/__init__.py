"""Inline engine with 1, 2 or 4 cylinders (course sections 1, 7.3 and figure 1).

Each cylinder is the compressor's slider-crank (:mod:`sandbox.scenes.compressor`): crank
radius R, rod 2 (mass m2, AG2 = d2, I_A,z = C2), piston 3 (mass m3); the cylinders stand
along y0 in the planes z = z_i of the crankshaft (axis z0), a apart, around the block's
centre C (the origin). Throws at 0° (one cylinder), 0-180° (twin) and 0-180-180-0° (the
flat-crank four of figure 1). Each throw carries its share of crank mass m1 at d1 and a
counterweight at R opposite its pin that balances the fraction k_r of the rotating mass
and k_a of the reciprocating one (the course's "balourd", section 1). The Lanchester
option adds two shafts below the crank, geared to it at +2ω and −2ω (joint equalities),
whose unbalance cancels the two-term second-order pilon. A velocity servo holds the
crankshaft at ``speed_rpm``; the block is the frame. Weight neglected, perfect joints,
links never touch.

Readouts and how they are measured:

- ``pilon`` / ``tamis``: force of the moving parts on the block along y0 / x0, minus the
  frame's action on the mechanism (``s.support``: joint and closure reactions).
- ``pilon_1`` .. ``pilon_4``: each cylinder's share (piston, rod, throw, counterweight),
  −Σ m Γ(G)·y0 from the simulated body accelerations; 0 for an absent cylinder (a column
  that always exists keeps CSV files of 1, 2 and 4 cylinders alike). With the shafts'
  own share they add up to ``pilon``, a second route to the same force.
- ``shaking_force_h1`` / ``_h2``: amplitudes of orders 1 and 2 of the simulated pilon over
  one revolution: the revolution is simulated ahead on a scratch copy of the state (the
  trajectory is untouched, cached while model, parameters and speed stay), and the
  samples are projected on cos kθ, sin kθ by least squares (the compressor's
  :func:`~sandbox.scenes.compressor.fit_orders`). Their course values are the exact
  slider-crank's orders (:func:`sandbox.mechanics.engine.pilon_orders`); the two-term
  formula m R ω² λ of the second order is 1.9 % lower at the default λ = 0.27.
- ``shaking_moment``: norm of the rocking moment on the block about C, its components
  along x0 (pitch, from the pilons) and y0 (yaw, from the tamis); the moment along the
  crankshaft z0 (the motor's reaction) is left out, as in the course's balancing.
  ``shaking_moment_max`` is its largest value over a revolution, from the same simulated
  revolution (orders 0..4 of each component evaluated densely).

C2 stops at 5e-3 kg·m² (77 times the default rod): the rods' swing then makes the
crank's inertia vary so much that the servo lets the speed ripple by 0.6 %, which the
constant-speed references see as a 0.3 % gap on the pilon.

The references take the engine at constant ω (:class:`sandbox.mechanics.engine.Engine`)
at the measured speed; the servo holds it within 3e-4 of its set point (four cylinders,
3000 rpm), so the gap is the simulation's own error. Measured with RK4 at the default
step, the compressor's crank angle (5e-4 s at 3000 rpm, 1e-4 s at 17,000 rpm): pilon
within 3.3e-4 of its peak, loops closed to 6.6e-7 m (7.8e-7 m at 17,000 rpm), |P_int|
below 3e-5 of the shaft's power; the four cylinders run 33 times faster than real time
on one core in free motion (the default motion is imposed, computed exactly).

Modules: :mod:`.params` (the parameter table), :mod:`.course` (the closed forms),
:mod:`.model` (model edits, servo, state, timestep), :mod:`.cycle` (one revolution and its
orders), :mod:`.readouts` (readouts and arrows).
"""

from __future__ import annotations

import dataclasses

from sandbox.physics.page import Names, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.spec import Effects, Scene
from sandbox.scenes import bearings
from sandbox.scenes.compressor.params import RPM
from sandbox.scenes.engine.course import (
    counterweight_mass,
    cylinder_count,
    engine_of,
    masses,
    motor_torque_ref,
    reference,
)
from sandbox.scenes.engine.cycle import DENSE, orders, revolution
from sandbox.scenes.engine.model import (
    IMPOSED,
    SHAFT_ECCENTRICITY,
    STEP_ANGLE,
    default_timestep,
    drive,
    edit,
    initial_state,
    place,
    positions,
    set_state,
)
from sandbox.scenes.engine.params import DEFAULTS, MAX_CYLINDERS, PARAMS
from sandbox.scenes.engine.readouts import ARROWS, BEARINGS, FORCE_SCALE, MOMENT_SCALE, READOUTS
from sandbox.scenes.roundoff import ROUND_OFF
from sandbox.scenes.slider_crank import ACCURACY

SOLID_NAMES = {
    "crank": "1 (vilebrequin)",
    **{f"throw_{i}": f"bras de manivelle {i}" for i in range(1, MAX_CYLINDERS + 1)},
    **{f"cw_{i}": f"contrepoids {i}" for i in range(1, MAX_CYLINDERS + 1)},
    **{f"rod_{i}": f"bielle {i}" for i in range(1, MAX_CYLINDERS + 1)},
    **{f"piston_{i}": f"piston {i}" for i in range(1, MAX_CYLINDERS + 1)},
    "shaft_1": "arbre d'équilibrage 1 (+2ω)",
    "shaft_2": "arbre d'équilibrage 2 (−2ω)",
}
"""French names of the bodies (the web page's solid picker)."""


EFFECTS, EFFECTS_AT = bearings.with_friction(
    Effects(gravity=False, contacts=False, equality=True, actuation=True)
)
"""A closed loop, the motor, and the bearings' friction while it is on."""

SCENE = Scene(
    name="engine",
    title="Moteur en ligne : équilibrage des machines alternatives",
    summary=(
        "One, two or four slider-cranks on one crankshaft, held at constant speed. The "
        "block feels the pilons and their rocking moment: the flat-crank four cancels the "
        "first order and the moment but keeps four times one cylinder's second order, "
        "which counterweights cannot touch and Lanchester shafts at 2ω cancel."
    ),
    mjcf="engine.xml",
    params=PARAMS,
    effects=EFFECTS,
    effects_for=EFFECTS_AT,
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    # « Paliers avec frottement »: the bearings' torque from their live load, each step
    control=bearings.friction_control(BEARINGS, "crank", "motor", lambda v: v["speed_rpm"] * RPM),
    control_when=bearings.friction_on,
    initial_state=initial_state,
    reference=reference,
    # The compressor's choices: RK4 keeps the closures from draining energy; the same
    # crank angle per step at every speed (5e-4 s at 3000 rpm, 1e-4 s at 17,000 rpm).
    integrator="rk4",
    timestep=5e-4,
    timestep_for=default_timestep,
    sections="1, 7.3, figure 1",
    cycle=revolution,
    zero={**ROUND_OFF, "m": 1e-15, "Pa": 1e-3},
    accuracy=ACCURACY,
    imposed=dataclasses.replace(IMPOSED, friction=bearings.imposed_friction(BEARINGS)),
    page=Page(
        bearings=BEARINGS,
        overlay={
            "omega": "ω",
            "shaking_force_h1": "Pilon, ordre 1",
            "shaking_force_h2": "Pilon, ordre 2",
            "shaking_moment_max": "Basculement maximal",
        },
        # The orders, steady at a steady speed: the pilon itself turns at 50 to 280 Hz, which
        # ten samples a second alias into noise (its curve over a turn is « Sur un tour »).
        plots=("shaking_force_h1", "shaking_force_h2", "shaking_moment_max"),
        study_presets=(
            StudyPreset(
                "Force de secouement d'ordre 2 selon la vitesse",
                ("speed_rpm", 1000.0, 6000.0, 11),
                "shaking_force_h2",
                duration=0.05,
                hint="Dans un moteur à quatre cylindres en ligne, les forces d'ordre 2 des "
                "pistons s'ajoutent : elles croissent comme ω².",
            ),
        ),
        xy_presets=(
            XYPreset(
                "Pilon sur un tour du vilebrequin",
                "theta",
                ("pilon",),
                hint="La somme des effets de pilon des cylindres selon l'angle θ ; en tirets, "
                "celle du cours.",
            ),
            XYPreset(
                "Moment de basculement sur un tour du vilebrequin",
                "theta",
                ("shaking_moment",),
                hint="Le moment que les équipages mobiles exercent sur le bâti selon θ ; en "
                "tirets, celui du cours.",
            ),
        ),
        arrows=ARROWS,
        body_frame="crank",
        camera=((1.0, 0.45, 0.8), (0.0, 1.0, 0.0)),
        # framed with room for the arrows: the force on the block reaches ~0.22 m from C
        look_at=((0.0, 0.03, 0.0), 0.42),
        names=Names(solids=SOLID_NAMES),
    ),
)

__all__ = [
    "ARROWS",
    "DEFAULTS",
    "DENSE",
    "FORCE_SCALE",
    "IMPOSED",
    "MAX_CYLINDERS",
    "MOMENT_SCALE",
    "PARAMS",
    "READOUTS",
    "SCENE",
    "SHAFT_ECCENTRICITY",
    "SOLID_NAMES",
    "STEP_ANGLE",
    "counterweight_mass",
    "cylinder_count",
    "default_timestep",
    "drive",
    "edit",
    "engine_of",
    "initial_state",
    "masses",
    "motor_torque_ref",
    "orders",
    "place",
    "positions",
    "reference",
    "revolution",
    "set_state",
]
