"""Wind turbine: a power chain with its efficiencies (course 6.4.2).

The wind's power P₁ = 8/27 ρ S V³ (Betz) passes the rotor (0,75), the gearbox (0,9), the
generator (0,9), the transformer (0,9) and the lines (0,95): 0,52 overall, and for the
course's 5 MW, 3,75 MW enter the gearbox, whose lubrication must carry away 375 kW.

Simulated: the slow shaft's one degree of freedom, driven by the wind's torque (the blades
take ρ_h P₁ s(λ/λ*), a power coefficient whose maximum is ρ_h·16/27 at the optimal tip-speed
ratio λ*) and braked by the generator through the gearbox; both torques are affine in ω,
so MuJoCo integrates them in C (:mod:`.course` for the closed forms: a first-order
approach to the steady speed). Everything after the generator is algebra: no dynamics.
The folder « Flux de puissance » draws the chain live (:class:`~sandbox.physics.page.PowerFlow`).
"""

from __future__ import annotations

import numpy as np

from sandbox.physics.page import FlowStage, Page, PowerFlow
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.spec import Accuracy, Effects, Scene, Series, Values
from sandbox.scenes.wind_turbine.course import speed_from, steady_chain, steady_speed
from sandbox.scenes.wind_turbine.model import drive, edit, initial_state
from sandbox.scenes.wind_turbine.params import PARAMS
from sandbox.scenes.wind_turbine.readouts import READOUTS, mechanism


def reference(values: Values) -> dict[str, float]:
    """The steady state's closed forms: every stage's power, ω, λ, Cp, the efficiency."""
    return steady_chain(values)


def start_error(series: Series, values: Values) -> float:
    """Largest |ω − ω(t)| / ω_∞ over a start from rest, ω(t) = ω_∞ (1 − e^(−t/τ))."""
    t = np.asarray(series["time"], dtype=float)
    w = np.asarray(series["omega"], dtype=float)
    exact = np.array([speed_from(0.0, float(x), values) for x in t])
    return float(np.max(np.abs(w - exact)) / steady_speed(values))


def theorem_gap(series: Series, values: Values) -> float:
    """Largest |P_acc − P_ext − P_int| over the peak of P_ext (the kinetic-energy theorem)."""
    gap = np.asarray(series["P_acc"]) - np.asarray(series["P_ext"]) - np.asarray(series["P_int"])
    top = float(np.max(np.abs(series["P_ext"])))
    return float(np.max(np.abs(gap))) / max(top, 1e-300)


FLOW = PowerFlow(
    source="P_wind",
    source_words="Vent (limite de Betz)",
    stages=(
        FlowStage("Hélice", "P_rotor", loss="P_rotor_loss", loss_words="vent non capté"),
        FlowStage("Arbre lent", "P_gearbox_in", stored="P_rotor_store"),
        FlowStage(
            "Multiplicateur", "P_generator_in", loss="P_gearbox_loss", stored="P_generator_store"
        ),  # fmt: skip
        FlowStage("Alternateur", "P_electric", loss="P_generator_loss"),
        FlowStage("Transformateur", "P_transformer_out", loss="P_transformer_loss"),
        FlowStage("Lignes", "P_grid", loss="P_line_loss"),
    ),
    sink_words="Réseau à terre",
    efficiency="efficiency",
)
"""The chain the folder « Flux de puissance » draws. The generator's rotor stores its
kinetic energy after the gearbox: the multiplier's stage passes P_generator_in on, its
output ρ_m P_in less what that rotor stores."""

SCENE = Scene(
    name="wind_turbine",
    title="Éolienne : chaîne de puissance",
    summary=(
        "A wind turbine's power chain: the wind's power through the rotor, the gearbox, "
        "the generator, the transformer and the lines, each with its efficiency; the "
        "rotor starts from rest or runs in its steady state."
    ),
    mjcf="wind_turbine.xml",
    params=PARAMS,
    effects=Effects(gravity=False, contacts=False, actuation=True),
    readouts=READOUTS,
    edit=edit,
    drive=drive,
    initial_state=initial_state,
    reference=reference,
    mechanism=mechanism,
    # RK4 on a first-order approach of time constant τ ≈ 8 s: at 30 ms (τ/260) the start
    # from rest is within 6e-13 of its closed form for a third of 10 ms's CPU (sandbox
    # bench: the cheapest run on the Pareto front under 1e-12; first-order integrators
    # are 2e-4 off at 10 ms). The 3D view carries the rotation between steps.
    integrator="rk4",
    timestep=3e-2,
    sections="6.4",
    # Round-off: the powers reach megawatts; the stored powers are 0 in steady state
    # (1e-9 W of a 5 MW chain).
    zero={"W": 1e-3, "N·m": 1e-6, "J": 1e-3},
    accuracy=Accuracy(
        key="omega",
        readouts=("omega", "P_acc", "P_ext", "P_int"),
        duration=30.0,
        error=start_error,
        invariant="energy theorem (|P_acc − P_ext − P_int| / peak P_ext)",
        drift=theorem_gap,
        values={"start": 1.0},
        rate=10.0,
        timesteps=(1e-3, 1e-2, 0.03, 0.1),
    ),
    page=Page(
        overlay={
            "P_wind": "Vent (Betz)",
            "P_gearbox_in": "Entrée du multiplicateur",
            "P_grid": "Réseau",
            "efficiency": "Rendement global",
        },  # fmt: skip
        plots=("P_wind", "P_rotor", "P_grid", "P_rotor_store"),
        camera=((-1.0, -0.9, 0.25), (0.0, 0.0, 1.0)),
        power_flow=FLOW,
        xy_presets=(
            XYPreset(
                "Puissance captée selon la vitesse, au départ",
                "omega",
                ("P_rotor", "P_generator_in"),
                values={"start": 1.0},
                hint="Le rotor part arrêté : la puissance captée suit la parabole de Cp(λ), "
                "l'alternateur en prend de plus en plus, et le rotor se stabilise là où "
                "les deux se rejoignent.",
            ),
            XYPreset(
                "Puissances au cours du temps, au départ",
                "time",
                ("P_rotor", "P_rotor_store", "P_grid"),
                values={"start": 1.0},
                hint="Au départ, la puissance captée remplit d'abord l'énergie cinétique du "
                "rotor, puis passe toute dans la chaîne.",
            ),
        ),
        study_presets=(
            StudyPreset(
                "Puissance livrée selon la charge de l'alternateur",
                ("generator_load", 50.0, 600.0, 12),
                "P_grid",
                duration=60.0,
                hint="Trop peu chargé, le rotor s'emballe au-delà de λₒₚₜ ; trop chargé, il "
                "ralentit en dessous : la puissance est la plus grande quand λ = λₒₚₜ.",
            ),
            StudyPreset(
                "Puissance du vent selon sa vitesse",
                ("wind_speed", 4.0, 14.0, 11),
                "P_wind",
                duration=0.1,
                hint="La puissance de Betz croît comme V³ : deux fois plus de vent donne huit "
                "fois plus de puissance.",
            ),
        ),
    ),
)

__all__ = ["FLOW", "SCENE", "reference"]
