"""The linear motion of the robot axis (closed form of the simulated model): the arm's
oscillation, the driving-mode state equations, the step and frequency responses and the
ringing after a stop."""

from __future__ import annotations

import math

import numpy as np

from sandbox.mechanics.robot_axis.axis import Real, RobotAxis, check_rho, equivalent_inertia

# --- the arm's oscillation -------------------------------------------------------------------


def arm_natural_frequency(axis: RobotAxis) -> float:
    """ω_n = √(K_t / M2) [rad/s]: the arm on a carriage held still (rigid carriage)."""
    return math.sqrt(axis.K_t / axis.M2)


def arm_damping_ratio(axis: RobotAxis) -> float:
    """ζ = μ_t / (2 √(K_t M2)) [-] of the arm on a carriage held still."""
    return axis.mu_t / (2.0 * math.sqrt(axis.K_t * axis.M2))


def free_axis_frequency(axis: RobotAxis) -> float:
    """ω [rad/s] of the arm against the free chain (motor torque imposed, f_v and μ_t aside).

    The chain seen from the belt is a mass J_eq / (R_p k)² (flexible J_eq), so the two
    masses on K_t oscillate at √(K_t (1/M2 + (R_p k)²/J_eq)).
    """
    m_chain = equivalent_inertia(axis) / axis.ratio**2
    return math.sqrt(axis.K_t * (1.0 / axis.M2 + 1.0 / m_chain))


# --- the linear motion of the axis (closed form of the simulated model) ---------------------


def chain_mass(axis: RobotAxis, *, flexible: bool = True, rho: float = 1.0) -> float:
    """Mass [kg] of the chain seen from the belt in the driving-mode model.

    The motor always drives the load (C_s ω_m > 0): the reducer's input equation
    C_m − (J_m + J_r) ω̇_m − f_v ω_m = C_s / ρ, multiplied by ρ, makes the chain a single
    degree of freedom of mass (ρ (J_m + J_r) + 2 J_p k²) / (R_p k)² + M1 (+ M2 for a rigid
    arm), pushed by ρ C_m / (R_p k) and braked by ρ f_v / (R_p k)² (ρ = 1: J_eq / (R_p k)²).

    Raises:
        ValueError: rho outside (0, 1].
    """
    check_rho(rho)
    upstream = rho * (axis.J_m + axis.J_r) + 2 * axis.J_p * axis.k**2
    mass = upstream / axis.ratio**2 + axis.M1
    return mass if flexible else mass + axis.M2


def state_matrices(
    axis: RobotAxis,
    *,
    flexible: bool = True,
    rho: float = 1.0,
    servo_gain: float = 0.0,
    position_gain: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(A, b) of ẋ = A x + b u for the driving-mode model of the axis.

    State x = (y_ch, V_ch, y, v) with y = y_2 − y_ch, v = V_2 − V_ch (rigid arm: (y_ch, V_ch)).
    Input u: the motor torque C_m [N·m], or with ``servo_gain`` K_v > 0 [N·m·s/rad] the
    speed set point ω_c [rad/s] of a speed servo with friction feedforward,
    C_m = K_v (ω_c − ω_m) + f_v ω_c (its steady speed is ω_c itself). A ``position_gain``
    K_p [1/s] adds a position loop to that set point, ω_c = u − K_p y_ch / (R_p k): u is
    then the speed feedforward plus K_p y_ref / (R_p k) for a reference position y_ref.
    """
    r = axis.ratio
    m = chain_mass(axis, flexible=flexible, rho=rho)
    drag = rho * (axis.f_v + servo_gain) / r**2  # N·s/m on V_ch
    push = rho * (servo_gain + axis.f_v if servo_gain > 0 else 1.0) / r
    hold = push * position_gain / r if servo_gain > 0 else 0.0  # N/m on y_ch
    if not flexible:
        return np.array([[0.0, 1.0], [-hold / m, -drag / m]]), np.array([0.0, push / m])
    k, mu = axis.K_t, axis.mu_t
    a_ch = np.array([-hold, -drag, k, mu]) / m
    a = np.zeros((4, 4))
    a[0, 1] = a[2, 3] = 1.0
    a[1] = a_ch
    a[3] = np.array([0.0, 0.0, -k, -mu]) / axis.M2 - a_ch
    b = np.array([0.0, push / m, 0.0, -push / m])
    return a, b


def expm(matrix: np.ndarray) -> np.ndarray:
    """Matrix exponential (scaling and squaring of a 20-term Taylor series), numpy only."""
    norm = float(np.max(np.sum(np.abs(matrix), axis=1)))
    squarings = max(0, int(math.ceil(math.log2(norm))) + 1) if norm > 0.5 else 0
    scaled = matrix / 2.0**squarings
    term = np.eye(len(matrix))
    total = term.copy()
    for n in range(1, 21):
        term = term @ scaled / n
        total = total + term
    for _ in range(squarings):
        total = total @ total
    return total


def step_response(
    axis: RobotAxis,
    t: Real,
    u: float,
    *,
    flexible: bool = True,
    rho: float = 1.0,
    servo_gain: float = 0.0,
) -> dict[str, np.ndarray]:
    """Motion of the axis from rest under a constant input ``u`` (see :func:`state_matrices`).

    Exact solution x(t) = ∫₀ᵗ e^{A s} b u ds of the linear equations of 6.3 (ρ < 1: the
    driving-mode model), from the exponential of the augmented matrix [[A, b u], [0, 0]].

    Returns:
        Arrays over ``t`` [s]: ``omega_m`` [rad/s], ``V_ch``, ``V_2`` [m/s], ``y`` the arm's
        deflection y_2 − y_ch [m] (0 for a rigid arm) and ``y_ch`` [m].
    """
    a, b = state_matrices(axis, flexible=flexible, rho=rho, servo_gain=servo_gain)
    n = len(a)
    aug = np.zeros((n + 1, n + 1))
    aug[:n, :n] = a
    aug[:n, n] = b * u
    times = np.atleast_1d(np.asarray(t, dtype=float))
    states = np.array([expm(aug * ti)[:n, n] for ti in times])
    v_ch = states[:, 1]
    y = states[:, 2] if flexible else np.zeros_like(v_ch)
    v = states[:, 3] if flexible else np.zeros_like(v_ch)
    return {
        "omega_m": v_ch / axis.ratio,
        "V_ch": v_ch,
        "V_2": v_ch + v,
        "y": y,
        "y_ch": states[:, 0],
    }


def frequency_response(
    axis: RobotAxis, omega: float, *, rho: float = 1.0
) -> tuple[complex, complex]:
    """Complex amplitudes (ω_m [rad/s], y [m]) per N·m of a motor torque C_m = Re(e^{iωt}).

    Steady state of the flexible axis driven at ``omega`` [rad/s] > 0: x = (iω I − A)⁻¹ b.
    The deflection peaks near :func:`free_axis_frequency` (the arm against the free chain).
    """
    a, b = state_matrices(axis, rho=rho)
    x = np.linalg.solve(1j * omega * np.eye(4) - a, b.astype(complex))
    return complex(x[1] / axis.ratio), complex(x[2])


def arm_ringing(
    axis: RobotAxis, *, rho: float = 1.0, servo_gain: float = 0.0, position_gain: float = 0.0
) -> tuple[float, float]:
    """(σ [1/s], ω_d [rad/s]) of the arm's free oscillation y ∝ e^{−σ t} cos(ω_d t) once the
    command is constant (e.g. after a stop): the complex eigenvalue −σ ± i ω_d of
    :func:`state_matrices` (flexible arm) with the largest imaginary part.

    With a stiff speed servo the carriage is nearly held still and ω_d nears the arm's own
    ω_n √(1 − ζ²) (:func:`arm_natural_frequency`, :func:`arm_damping_ratio`); with the
    torque command it is the arm against the free chain (:func:`free_axis_frequency`).
    """
    a, _ = state_matrices(axis, rho=rho, servo_gain=servo_gain, position_gain=position_gain)
    eig = np.linalg.eigvals(a)
    top = eig[int(np.argmax(eig.imag))]
    return float(-top.real), float(top.imag)
