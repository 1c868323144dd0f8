"""The y axis of the cartesian transfer robot: equivalent inertia and efficiency (course 6.3, 6.4).

Chain (course figure 27): motor shaft (J_m) -> reducer (J_r, referred to the motor shaft,
ratio k = ω_p/ω_m) -> two toothed pulleys (J_p each, pitch radius R_p) -> belt -> carriage
``ch`` (rigid parts, mass M1) -> flexible arm z (mass M2) tied to the carriage by a spring
K_t and a damper μ_t; viscous friction f_v referred to the motor shaft.

Kinematics (6.3): ``ω_p = k ω_m`` and ``V_ch = R_p k ω_m``; the arm's speed V_2 is a second
degree of freedom (the arm is not tied rigidly to ω_m) unless the arm is taken rigid.

Kinetic-energy theorem (6.3), with y = y_2 - y_ch and v = V_2 - V_ch the arm's deflection
and its rate::

    d/dt(½ J_eq ω_m² + ½ M2 V_2²) = -K_t y v - μ_t v² - f_v ω_m² + C_m ω_m
    J_eq = J_m + J_r + 2 J_p k² + M1 (R_p k)²                  (flexible arm)
    J_eq = J_m + J_r + 2 J_p k² + (M1 + M2) (R_p k)²           (rigid arm, C_m = J_eq ω̇_m)

Efficiency (6.4): ρ = P_s / P_e. Here ρ is the reducer's, the losses are (1 - ρ) P_e where
P_e is the power entering the reducer: from the motor when driving, from the load side when
braking (the load gives power back). J_m, J_r and f_v act on the motor side of the losses
(the course refers them to the motor shaft); the pulleys, the carriage and the arm after it.

Numpy only; every function accepts floats or arrays of the same shape (broadcast).

Modules: :mod:`.axis` (the data record, J_eq, kinematics), :mod:`.torque` (motor torque and
efficiency), :mod:`.energy` (the kinetic-energy theorem), :mod:`.motion` (the linear
motion of the simulated model), :mod:`.moves` (the back-and-forth move).
"""

from __future__ import annotations

from sandbox.mechanics.robot_axis.axis import (
    Real,
    RobotAxis,
    arm_acceleration,
    arm_force,
    as_real,
    check_rho,
    equivalent_inertia,
    inertia_terms,
    speeds,
)
from sandbox.mechanics.robot_axis.energy import (
    Powers,
    energy_balance,
    kinetic_energy,
    kinetic_energy_rate,
    powers,
)
from sandbox.mechanics.robot_axis.motion import (
    arm_damping_ratio,
    arm_natural_frequency,
    arm_ringing,
    chain_mass,
    expm,
    free_axis_frequency,
    frequency_response,
    state_matrices,
    step_response,
)
from sandbox.mechanics.robot_axis.moves import back_and_forth, back_and_forth_motion
from sandbox.mechanics.robot_axis.torque import (
    motor_torque,
    power_loss,
    reducer_loss,
    series_efficiency,
)

__all__ = [
    "Powers",
    "Real",
    "RobotAxis",
    "arm_acceleration",
    "arm_damping_ratio",
    "arm_force",
    "arm_natural_frequency",
    "arm_ringing",
    "as_real",
    "back_and_forth",
    "back_and_forth_motion",
    "chain_mass",
    "check_rho",
    "energy_balance",
    "equivalent_inertia",
    "expm",
    "free_axis_frequency",
    "frequency_response",
    "inertia_terms",
    "kinetic_energy",
    "kinetic_energy_rate",
    "motor_torque",
    "power_loss",
    "powers",
    "reducer_loss",
    "series_efficiency",
    "speeds",
    "state_matrices",
    "step_response",
]
