"""Model of the wind turbine: the blades, tower and hub height from the diameter (MjSpec);
the two affine torques, the inertias and the generator's rotor as the slow shaft's
armature (drive); the start (initial state)."""

from __future__ import annotations

import math

import mujoco

from sandbox.physics.spec import Values
from sandbox.scenes.wind_turbine.course import (
    generator_damping,
    steady_speed,
    torque_coefficients,
)

HUB_CLEARANCE = 20.0
"""Height of the blades' lowest point above the ground [m]."""


def hub_height(values: Values) -> float:
    return values["diameter"] / 2.0 + HUB_CLEARANCE


def edit(spec: mujoco.MjSpec, values: Values) -> None:
    """Blades of length D/2 at 120°, the tower and the nacelle at the hub's height; the
    rotor's inertia J_r and the generator's seen through the gearbox, J_g k² / ρ_m, as the
    slow shaft's armature (compiled: MuJoCo 4 keeps inertias as model constants)."""
    j = values["rotor_inertia"]
    rotor = spec.body("rotor")
    rotor.inertia = [j, j / 2.0, j / 2.0]
    spec.joint("rotor").armature = (
        values["generator_inertia"] * values["gear_ratio"] ** 2 / values["eta_gearbox"]
    )
    radius, height = values["diameter"] / 2.0, hub_height(values)
    rotor.pos = [-1.5, 0.0, height]
    spec.geom("tower").fromto = [5.0, 0.0, 0.0, 5.0, 0.0, height]
    spec.geom("nacelle").pos = [7.0, 0.0, height]
    chord = max(0.6, 0.017 * radius * 2.0)
    for i in range(3):
        angle = math.pi / 2 + 2 * math.pi * i / 3
        c, s = math.cos(angle), math.sin(angle)
        blade = spec.geom(f"blade{i + 1}")
        blade.fromto = [0.0, 2.0 * c, 2.0 * s, 0.0, radius * c, radius * s]
        blade.size = [chord / 2.0, 0.0, 0.0]


_APPLIED_START = 0
"""``userdata`` slot holding the ``start`` last applied."""


def _launch(data: mujoco.MjData, values: Values) -> None:
    """The rotor at rest (``start`` = 1) or at its steady speed, the start remembered."""
    data.qvel[0] = 0.0 if values["start"] >= 0.5 else steady_speed(values)
    data.userdata[_APPLIED_START] = values["start"]


def drive(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """The wind's torque a − b ω and the generator's k² K ω / ρ_m on the slow shaft; a
    new ``start`` relaunches the rotor at once (from rest, or at its steady speed), the
    time going on."""
    a, b = torque_coefficients(values)
    wind = model.actuator("wind").id
    generator = model.actuator("generator").id
    model.actuator_biasprm[wind, :3] = (a, 0.0, -b)
    model.actuator_biasprm[generator, :3] = (0.0, 0.0, -generator_damping(values))
    if data.userdata[_APPLIED_START] != values["start"]:
        _launch(data, values)


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, values: Values) -> None:
    """At the steady speed ω_∞, or at rest."""
    data.qpos[:] = 0.0
    _launch(data, values)
