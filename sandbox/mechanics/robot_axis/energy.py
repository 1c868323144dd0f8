"""The kinetic-energy theorem of the robot axis (course 6.3): its kinetic energy, the
powers of the motor, the friction and the arm, and the theorem's residual."""

from __future__ import annotations

from dataclasses import dataclass

from sandbox.mechanics.robot_axis.axis import Real, RobotAxis, equivalent_inertia, speeds

# --- 6.3: kinetic-energy theorem -------------------------------------------------------------


def kinetic_energy(
    axis: RobotAxis, omega_m: Real, V_2: Real = 0.0, *, flexible: bool = True
) -> Real:
    """T of the whole axis [J]: ½ J_eq ω_m² + ½ M2 V_2² (rigid arm: ½ J_eq ω_m², V_2 ignored)."""
    j_eq = equivalent_inertia(axis, flexible=flexible)
    t = 0.5 * j_eq * omega_m**2
    return t + 0.5 * axis.M2 * V_2**2 if flexible else t


def kinetic_energy_rate(
    axis: RobotAxis,
    omega_m: Real,
    omega_m_dot: Real,
    V_2: Real = 0.0,
    V_2_dot: Real = 0.0,
    *,
    flexible: bool = True,
) -> Real:
    """dT/dt [W] = J_eq ω_m ω̇_m + M2 V_2 V̇_2 (rigid arm: J_eq ω_m ω̇_m)."""
    rate = equivalent_inertia(axis, flexible=flexible) * omega_m * omega_m_dot
    return rate + axis.M2 * V_2 * V_2_dot if flexible else rate


@dataclass(frozen=True)
class Powers:
    """Powers of the theorem of 6.3 [W] (arrays when the inputs are).

    Attributes:
        P_ext: Motor, C_m ω_m.
        P_friction: Viscous friction, -f_v ω_m².
        P_damper: Arm damper, -μ_t (V_2 - V_ch)².
        P_spring: Arm spring, -K_t (y_2 - y_ch)(V_2 - V_ch).
    """

    P_ext: Real
    P_friction: Real
    P_damper: Real
    P_spring: Real

    @property
    def P_int(self) -> Real:
        """Power of the inter-efforts, P_friction + P_damper + P_spring."""
        return self.P_friction + self.P_damper + self.P_spring


def powers(axis: RobotAxis, C_m: Real, omega_m: Real, *, y: Real = 0.0, v: Real = 0.0) -> Powers:
    """The powers of the theorem for a motor torque C_m [N·m] (course 6.3).

    Args:
        y, v: Arm deflection y_2 - y_ch [m] and its rate [m/s] (0 for the rigid arm).
    """
    return Powers(
        P_ext=C_m * omega_m,
        P_friction=-axis.f_v * omega_m**2,
        P_damper=-axis.mu_t * v**2,
        P_spring=-axis.K_t * y * v,
    )


def energy_balance(
    axis: RobotAxis,
    C_m: Real,
    omega_m: Real,
    omega_m_dot: Real,
    *,
    y: Real = 0.0,
    V_2: Real = 0.0,
    V_2_dot: Real = 0.0,
    flexible: bool = True,
) -> Real:
    """Residual dT/dt - (P_ext + P_int) [W] of the theorem of 6.3; zero on a true motion.

    Args:
        C_m: Motor torque [N·m].
        omega_m, omega_m_dot: Motor speed [rad/s] and acceleration [rad/s²].
        y: Arm deflection y_2 - y_ch [m].
        V_2, V_2_dot: Arm speed [m/s] and acceleration [m/s²] (flexible arm).
        flexible: False for the rigid arm (V_2 = V_ch, no spring or damper power).
    """
    rate = kinetic_energy_rate(axis, omega_m, omega_m_dot, V_2, V_2_dot, flexible=flexible)
    if flexible:
        _, v_ch = speeds(axis, omega_m)
        p = powers(axis, C_m, omega_m, y=y, v=V_2 - v_ch)
    else:
        p = powers(axis, C_m, omega_m)
    return rate - (p.P_ext + p.P_int)
