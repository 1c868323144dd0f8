"""Unbalanced rotor on a fixed axis (course section 7.2): static and dynamic balancing.

Rotor 1 turns about (O, x0) at constant speed, guided by two bearings A and B. A defect
mass gives a static unbalance (G off the axis) and a skewed disk a couple unbalance
(products of inertia E, F of the x column). Two correction masses, one per plane at a
fixed radius, let the student cancel both: static balance needs Y = 0, dynamic balance
needs Y = 0 and E = F = 0.

Modules: :mod:`.params` (the parameter table and the geometry), :mod:`.course`
(the closed forms of 7.2), :mod:`.model` (model edits and drive), :mod:`.readouts`
(readouts and arrows).
"""

from __future__ import annotations

from sandbox.physics.page import Components, Names, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.spec import Accuracy, Effects, Scene
from sandbox.scenes import bearings
from sandbox.scenes.imposed import spinning
from sandbox.scenes.measures import relative_drift, worst_relative_error
from sandbox.scenes.rotor.course import (
    balancing_solution,
    bearing_split,
    disk_axis,
    mass_points,
    mass_properties,
    omega,
    reference,
    unbalance,
)
from sandbox.scenes.rotor.diagram import DIAGRAM
from sandbox.scenes.rotor.model import drive, edit, initial_state
from sandbox.scenes.rotor.params import (
    AXIS,
    BEARING_X,
    CORRECTION_RADIUS,
    DEFECT_RADIUS,
    DEFECT_X,
    DISK_RADIUS,
    DISK_THICKNESS,
    FLANGE_RADIUS,
    FLANGE_THICKNESS,
    MASS_SPHERE_RADIUS,
    PARAMS,
    PLANE_X,
    SHAFT_LENGTH,
    SHAFT_RADIUS,
    STEEL,
)
from sandbox.scenes.rotor.readouts import ARROWS, BEARINGS, READOUTS
from sandbox.scenes.roundoff import ROUND_OFF

EFFECTS, EFFECTS_AT = bearings.with_friction(Effects(gravity=False, contacts=False, actuation=True))
"""The motor, and the bearings' friction while it is on."""

SCENE = Scene(
    name="rotor",
    title="Rotor déséquilibré à équilibrer",  # one line in a projected panel
    summary=(
        "A rotor on two bearings turns at constant speed. A defect mass and a skewed disk "
        "make the frame feel rotating forces; two correction masses cancel them."
    ),
    mjcf="rotor.xml",
    params=PARAMS,
    effects=EFFECTS,
    effects_for=EFFECTS_AT,
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    # « Paliers avec frottement »: the bearings' torque from their live load, each step
    control=bearings.friction_control(BEARINGS, "spin", "motor", omega),
    control_when=bearings.friction_on,
    imposed=spinning("spin", "motor", friction=bearings.imposed_friction(BEARINGS)),
    initial_state=initial_state,
    reference=reference,
    # A uniform rotation is integrated exactly by every integrator (sandbox bench: errors
    # ~1e-14 at every timestep), so the default is the cheapest run on the Pareto front;
    # implicitfast also keeps the speed servo stable through slider jumps.
    integrator="implicitfast",
    timestep=1e-2,
    sections="2–3, 5, 6, 7.2",
    solutions={"balancing_solution": balancing_solution},
    # Round-off: at 1500 rpm {D} and the frame's action keep 6e-12 N and 2e-12 N·m on
    # axes where the course has 0 (1e-13 of the 54 N peak), 1e-10 N at 6000 rpm.
    # The bearings' pressure: the N floor over the bores' default 2RL (2e-4 m²), 1e-8 bar.
    zero={**ROUND_OFF, "kg·m": 1e-13, "kg·m²": 1e-14, "Pa": 1e-3},
    # Key quantity: the bearing force at A against 7.2's closed form; invariant: T, constant
    # at constant speed (the servo holds ω, so a drift of T means the motion is wrong).
    accuracy=Accuracy(
        key="bearing_A",
        readouts=("bearing_A", "T"),
        duration=0.5,
        error=worst_relative_error("bearing_A", reference),
        invariant="T (constant speed)",
        drift=relative_drift("T"),
        values={"speed_rpm": 3000.0},
        timesteps=(1e-4, 3e-4, 1e-3, 3e-3, 1e-2),
    ),
    page=Page(
        overlay={"omega": "ω", "bearing_A": "Palier A", "bearing_B": "Palier B"},
        plots=("bearing_A", "bearing_B"),
        xy_presets=(
            XYPreset(
                "Efforts des paliers selon ω, au démarrage",
                "omega",
                ("bearing_A", "bearing_B"),
                values={"ramp_s": 2.0, "speed_rpm": 6000.0},
                hint="Le rotor part du repos et monte à 6000 tr/min : les efforts des paliers "
                "suivent la parabole du cours en ω² (tirets).",
            ),
            XYPreset(
                "Efforts des paliers au cours du temps",
                "time",
                ("bearing_A", "bearing_B"),
                hint="À vitesse constante, les efforts tournent avec le rotor mais gardent leur "
                "intensité : celle du cours (tirets).",
            ),
        ),
        study_presets=(
            StudyPreset(
                "Effort du palier A selon la vitesse (0 à 6000 tr/min)",
                ("speed_rpm", 0.0, 6000.0, 13),
                "bearing_A",
                duration=0.1,
                hint="Chaque point est une simulation à vitesse constante : l'effort croît "
                "comme ω² (cours 7.2).",
            ),
            StudyPreset(
                "Pression au palier A selon la vitesse (200 g de défaut)",
                ("speed_rpm", 4000.0, 6000.0, 9),
                "bearing_A_pmax",
                duration=0.1,
                fixed={"defect_mass_g": 200.0, "bearing_model": 1.0},
                hint="Pression en cosinus dans un alésage de 10 mm × 10 mm : elle croît comme "
                "ω² et franchit les 200 bar vers 5520 tr/min (annexe B.2).",
            ),
        ),
        arrows=ARROWS,
        body_frame="rotor",
        names=Names(
            solids={"rotor": "1 (rotor)"},
            markers={"defect": "Défaut", "correction1": "m₁", "correction2": "m₂"},
        ),
        unbalance_diagram=DIAGRAM,
        bearings=BEARINGS,
        # Course 7.2: the bearing forces of an unbalanced rotor are fixed in the rotor (B1),
        # so they turn at ω in the frame. In B1 they are constant while ω and the masses are;
        # in B0 they would be sinusoids at up to 100 Hz, which 10 samples a second alias.
        components=Components(("bearing_A", "bearing_B"), "B1", (1, 2), "B₁, liée au rotor"),
        balancing=("bearing_A", "bearing_B"),
    ),
)

__all__ = [
    "ARROWS",
    "AXIS",
    "BEARING_X",
    "CORRECTION_RADIUS",
    "DEFECT_RADIUS",
    "DEFECT_X",
    "DISK_RADIUS",
    "DISK_THICKNESS",
    "FLANGE_RADIUS",
    "FLANGE_THICKNESS",
    "MASS_SPHERE_RADIUS",
    "PARAMS",
    "PLANE_X",
    "READOUTS",
    "SCENE",
    "SHAFT_LENGTH",
    "SHAFT_RADIUS",
    "STEEL",
    "balancing_solution",
    "bearing_split",
    "disk_axis",
    "drive",
    "edit",
    "initial_state",
    "mass_points",
    "mass_properties",
    "omega",
    "reference",
    "unbalance",
]
