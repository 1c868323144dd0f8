"""Micro-compressor, a slider-crank (course sections 1, 4, 5.7, 6.1.2, 6.2, 7.3).

Frame 0, crank 1 (OA = R x1, OG1 = d1 x1, inertia I_O,1 with A1, B1, C1 and the product
E1), rod 2 (AB = L y2, AG2 = d2 y2, I_A,2 = diag(A2, B2, C2)), piston 3 sliding along
(O, y0) with BG3 = d3 y0 and OB = λ y0. θ is the angle from x0 to x1 about z0. A motor
holds the crank at ``speed_rpm``; a counterweight on the crank, opposite the pin, trades
part of the order-1 pilon for a tamis. Weight neglected, perfect joints, links never touch.

Closed forms: λ = R sin θ + √(L² − R² cos² θ); every centre of mass moves on a known
curve, so the force the moving parts transmit to the frame is −Σ m_i Γ(G_i), and the
kinetic-energy theorem gives the motor torque C_mot ω = dT/dt (course, constant ω). The
readouts' references use the exact slider-crank at the current θ, θ' and θ'' (the
simulated crank acceleration): during a ramp (ramp_s = 0.2 s) the θ'' terms reach 27 % of
the torque's peak, and the constant-speed formulas would blame the simulation for them.

Modules: :mod:`.params` (the parameter table), :mod:`.course` (the closed forms),
:mod:`.model` (model edits, servo, timestep), :mod:`.cycle` (one revolution and its
orders), :mod:`.readouts` (readouts and arrows).
"""

from __future__ import annotations

import dataclasses

from sandbox.physics.page import Names, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.spec import Effects, Scene
from sandbox.scenes import bearings
from sandbox.scenes.compressor.course import (
    HARMONIC_SAMPLES,
    Kinematics,
    frame_force,
    kinematics,
    motor_torque,
    reference,
)
from sandbox.scenes.compressor.cycle import (
    LOOP_SAMPLES,
    loop_forces,
    pilon_harmonics,
    revolution,
    steady,
)
from sandbox.scenes.compressor.model import (
    CLOSURE_TIMECONST,
    FASTER,
    IMPOSED,
    LARGEST_TIMESTEP,
    SERVO_STIFFNESS,
    STEP_ANGLE,
    default_timestep,
    drive,
    edit,
    initial_state,
    place,
    set_loop_state,
)
from sandbox.scenes.compressor.params import DEFAULTS, PARAMS, RPM
from sandbox.scenes.compressor.readouts import ARROW_SCALE, ARROWS, BEARINGS, READOUTS
from sandbox.scenes.roundoff import ROUND_OFF
from sandbox.scenes.slider_crank import ACCURACY, FITTED_ORDERS, fit_orders

EFFECTS, EFFECTS_AT = bearings.with_friction(
    Effects(gravity=False, contacts=False, equality=True, actuation=True)
)
"""A closed loop, the motor, and the bearings' friction while it is on."""

SCENE = Scene(
    name="compressor",
    title="Micro-compresseur : effets de pilon et de tamis",
    summary=(
        "A slider-crank held at constant speed by a motor. The moving parts shake the frame "
        "along the cylinder (pilon) and across it (tamis); a counterweight on the crank "
        "trades part of the first one for the second."
    ),
    mjcf="compressor.xml",
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
    # RK4 keeps the closure from draining energy: first-order integrators (euler,
    # implicitfast...) lose 1-5 % of the motor power in it at 2e-5 to 1e-4 s, whatever the
    # closure's time constant. dt = 1e-4 s (ω dt = 0.18 at 17,000 rpm) keeps the 17,000 rpm
    # loop closed to 1e-6 m (7.8e-7 measured; 7e-5 s gives 4.8e-7) and costs ~0.15 s of
    # CPU per simulated second; the same angle per step is enough at every speed
    # (default_timestep), so 3000 rpm runs at 5e-4 s, five times cheaper.
    integrator="rk4",
    timestep=5e-4,
    timestep_for=default_timestep,
    sections="1, 4, 5.7, 6.1.2, 6.2, 7.3",
    cycle=revolution,
    # Round-off: the closure error (1e-8 m and more) stays visible; forces reach 1e4 N.
    zero={**ROUND_OFF, "m": 1e-13, "Pa": 1e-3},
    accuracy=ACCURACY,
    imposed=dataclasses.replace(IMPOSED, friction=bearings.imposed_friction(BEARINGS)),
    page=Page(
        bearings=BEARINGS,
        overlay={
            "theta": "θ",
            "pilon": "Effet de pilon",
            "tamis": "Effet de tamis",
            "motor_torque": "Couple moteur",
        },
        imposed_overlay={"motor_torque": "Couple nécessaire"},
        # Time plots of slow quantities (the pilon itself is drawn against θ in "Sur un tour").
        plots=("pilon_h1", "pilon_h2", "tamis_h1", "omega"),
        xy_presets=(
            XYPreset(
                "Pilon et tamis sur un tour du vilebrequin",
                "theta",
                ("pilon", "tamis"),
                hint="Les efforts transmis au bâti selon l'angle θ du vilebrequin ; en tirets, "
                "les expressions du cours (7.3).",
            ),
            XYPreset(
                "Couple moteur sur un tour du vilebrequin",
                "theta",
                ("motor_torque",),
                hint="Le couple que le moteur fournit selon θ ; en tirets, celui que donne le "
                "théorème de l'énergie cinétique.",
            ),
        ),
        study_presets=(
            StudyPreset(
                "Pilon d'ordre 2 selon R/L",
                ("L", 0.04, 0.2, 9),
                "pilon",
                statistic="order2",
                duration=0.1,
                settle=0.02,
                hint="L'harmonique d'ordre 2 de l'effet de pilon est proportionnelle à R/L "
                "(cours 7.3) : une bielle plus longue secoue moins le bâti.",
                x=("Rapport R/L", lambda v: v["R"] / v["L"]),
            ),
        ),
        arrows=ARROWS,
        body_frame="crank",
        camera=((0.35, -0.45, 1.0), (0.0, 1.0, 0.0)),  # facing the mechanism's plane, y0 up
        names=Names(
            solids={"crank": "1 (vilebrequin)", "rod": "2 (bielle)", "piston": "3 (piston)"}
        ),
    ),
)

__all__ = [
    "ARROWS",
    "ARROW_SCALE",
    "CLOSURE_TIMECONST",
    "DEFAULTS",
    "FASTER",
    "FITTED_ORDERS",
    "IMPOSED",
    "HARMONIC_SAMPLES",
    "LARGEST_TIMESTEP",
    "LOOP_SAMPLES",
    "PARAMS",
    "READOUTS",
    "RPM",
    "SCENE",
    "SERVO_STIFFNESS",
    "STEP_ANGLE",
    "Kinematics",
    "default_timestep",
    "drive",
    "edit",
    "fit_orders",
    "frame_force",
    "initial_state",
    "kinematics",
    "loop_forces",
    "motor_torque",
    "pilon_harmonics",
    "place",
    "reference",
    "revolution",
    "set_loop_state",
    "steady",
]
