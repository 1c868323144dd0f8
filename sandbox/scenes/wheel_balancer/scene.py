"""The wheel balancer's spec (course 7.1, 7.2), with the lab bench's influence-coefficient
method (three runs of the scene's own simulation) and its timestep.
"""

from __future__ import annotations

import mujoco
import numpy as np

from sandbox.mechanics.two_planes import clip_unbalance, influence_correction
from sandbox.physics.model import Source
from sandbox.physics.page import Names, Page
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.simulation import Simulation
from sandbox.physics.spec import Accuracy, Effects, Scene, Values, per_revolution_timestep
from sandbox.scenes import bearings
from sandbox.scenes.imposed import spinning
from sandbox.scenes.measures import relative_drift, worst_relative_error
from sandbox.scenes.wheel_balancer.course import machine_solution, reference, supports_model
from sandbox.scenes.wheel_balancer.model import drive, edit, initial_state
from sandbox.scenes.wheel_balancer.params import CLIP_RADIUS, PARAMS, effects, omega, soft
from sandbox.scenes.wheel_balancer.readouts import (
    ARROWS,
    BEARINGS,
    READOUTS,
    accelerometer,
    phase,
)


def _soft_bench(values: Values) -> tuple[str, str] | None:
    """The lab bench's housing vibrates on its springs: its motion must be simulated."""
    if not soft(values):
        return None
    return (
        "the lab bench's bearings vibrate on their springs: their motion must be simulated "
        "(supports=0 for the rigid bearings of the garage's machine)",
        "Sur le banc de laboratoire, les paliers vibrent sur leurs ressorts : leur mouvement "
        "doit être simulé (paliers rigides pour imposer la rotation).",
    )


def vibrations(values: Values, *, settle: float = 1.0) -> np.ndarray:
    """The two accelerometers' readings (complex, rotor frame) after ``settle`` seconds of
    simulation at ``values`` (shape (2,))."""
    sim = Simulation(Source.of_scene(SCENE), values=dict(values))
    sim.advance(settle)
    snap = sim.snapshot((), forces=True)
    return np.array([accelerometer(snap, "sensor_A"), accelerometer(snap, "sensor_B")])


def influence_solution(values: Values) -> dict[str, float]:
    """The lab bench's balancing (figure 40): three simulated runs, without trial mass,
    with it in the inner plane, then in the outer plane, give the influence coefficients;
    :func:`~sandbox.mechanics.two_planes.influence_correction` turns them into the clips
    (trial mass removed). Existing clips are kept in the runs and the result adds to them."""
    base = {**values, "trial_plane": 0.0}
    v0 = vibrations(base)
    v_in = vibrations({**base, "trial_plane": 1.0})
    v_out = vibrations({**base, "trial_plane": 2.0})
    trial = clip_unbalance(values["trial_g"], 0.0, CLIP_RADIUS)
    clips = influence_correction(
        v0, v_in, v_out, trial, trial, radius_inner=CLIP_RADIUS, radius_outer=CLIP_RADIUS
    )
    total_in = clip_unbalance(values["mass_inner_g"], values["angle_inner_deg"], CLIP_RADIUS)
    total_out = clip_unbalance(values["mass_outer_g"], values["angle_outer_deg"], CLIP_RADIUS)
    total_in += clip_unbalance(clips.clip_inner_g, clips.clip_inner_deg, CLIP_RADIUS)
    total_out += clip_unbalance(clips.clip_outer_g, clips.clip_outer_deg, CLIP_RADIUS)
    out = {"trial_plane": 0.0}
    for side, u in (("inner", total_in), ("outer", total_out)):
        out[f"mass_{side}_g"] = abs(u) / CLIP_RADIUS * 1000
        out[f"angle_{side}_deg"] = phase(u)
    return out


# -- timestep -----------------------------------------------------------------------------------
RIGID_TIMESTEP = 1e-2
"""Rigid bearings: a uniform rotation, integrated exactly at any step."""
SOFT_ANGLE = 0.36
"""Soft supports: at most this angle [rad] per step of the fastest motion, the rotation or
the supports' highest critical speed (sandbox bench at 600 tr/min: RK4 within 2e-5 of the
closed form at 3e-3 s, 1e-4 at 5e-3 s; 5e-4 at 2000 tr/min)."""
SOFT_LARGEST = 5e-3


def default_timestep(values: Values, data: mujoco.MjData | None = None) -> float:
    """1e-2 s on rigid bearings; on soft ones, SOFT_ANGLE per step of the fastest motion."""
    if not soft(values):
        return RIGID_TIMESTEP
    fastest = max(abs(omega(values)), *_criticals(), 1.0)
    return per_revolution_timestep(SOFT_ANGLE, fastest, largest=SOFT_LARGEST)


def _criticals() -> tuple[float, ...]:
    global _CRITICALS
    if _CRITICALS is None:
        defaults = {p.name: p.default for p in PARAMS} | {"supports": 1.0}
        _CRITICALS = supports_model(defaults).critical_speeds()
    return _CRITICALS


_CRITICALS: tuple[float, ...] | None = None

SCENE_NAME = "wheel_balancer"
BENCH_VALUES = {"supports": 1.0, "speed_rpm": 600.0}

SCENE = Scene(
    name=SCENE_NAME,
    title="Équilibreuse de roues : deux masselottes, deux plans",
    summary=(
        "A car wheel with an unknown static and couple unbalance turns on the machine's "
        "shaft. The machine measures its two bearing forces and computes the two clip-on "
        "masses that cancel them; on soft supports, trial masses find the correction."
    ),
    mjcf="wheel_balancer.xml",
    params=PARAMS,
    effects=Effects(
        gravity=False,
        contacts=False,
        actuation=True,
        springs=True,
        joint_damping=True,
        joint_friction=True,
    ),
    effects_for=effects,
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    # « Paliers avec frottement »: the bearings' torque from their live load, each step
    control=bearings.friction_control(BEARINGS, "spin", "motor", omega),
    control_when=bearings.friction_on,
    imposed=spinning(
        "spin", "motor", unavailable=_soft_bench, friction=bearings.imposed_friction(BEARINGS)
    ),
    initial_state=initial_state,
    reference=reference,
    # RK4: exact for the uniform rotation on rigid bearings at any step, and fourth order
    # for the soft supports' vibration (sandbox bench).
    integrator="rk4",
    timestep=RIGID_TIMESTEP,
    timestep_for=default_timestep,
    # beyond 1e-2 s the soft supports' vibration loses its accuracy (sandbox bench: 8e-4 at
    # 9e-3 s, diverged at 3e-2 s); rigid bearings use 1e-2 s
    max_timestep=RIGID_TIMESTEP,
    sections="7.1, 7.2",
    solutions={"machine_solution": machine_solution, "influence_solution": influence_solution},
    zero={"N": 1e-9, "N·m": 1e-10, "W": 1e-12, "g": 1e-7, "m/s²": 1e-9, "Pa": 1e-5},
    # Key quantity: the lab bench's vibration at B against the linear synchronous response
    # (rigid bearings are exact at every step); invariant: T at constant speed.
    accuracy=Accuracy(
        key="accel_outer",
        readouts=("accel_outer", "T"),
        duration=1.0,
        error=worst_relative_error("accel_outer", reference),
        invariant="T (constant speed)",
        drift=relative_drift("T"),
        values=BENCH_VALUES,
    ),
    page=Page(
        plots=("bearing_inner", "bearing_outer"),
        study_presets=(
            StudyPreset(
                "Effort du palier intérieur selon la vitesse",
                ("speed_rpm", 0.0, 2000.0, 11),
                "bearing_inner",
                duration=0.5,
                hint="Chaque point est une simulation à vitesse constante : l'effort croît "
                "comme ω².",
            ),
        ),
        xy_presets=(
            XYPreset(
                "Efforts des paliers au cours du temps",
                "time",
                ("bearing_inner", "bearing_outer"),
                hint="À vitesse constante, les efforts tournent avec la roue avec une intensité "
                "fixe ; en tirets, celle du cours.",
            ),
        ),
        overlay={
            "bearing_inner": "Palier A",
            "bearing_outer": "Palier B",
            "clip_inner_g": "Masselotte intérieure",
            "clip_outer_g": "Masselotte extérieure",
        },
        arrows=ARROWS,
        body_frame="wheel",
        names=Names(
            solids={"wheel": "1 (roue)"},
            markers={
                "defect": "Point lourd",
                "clip_inner": "m₁",
                "clip_outer": "m₂",
                "trial": "Essai",
            },
        ),
        balancing=("bearing_inner", "bearing_outer"),
        bearings=BEARINGS,
    ),
)
