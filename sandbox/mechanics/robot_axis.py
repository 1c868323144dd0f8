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
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, fields
from typing import TypeAlias

import numpy as np

Real: TypeAlias = "float | np.ndarray"


@dataclass(frozen=True)
class RobotAxis:
    """Data of the robot's y axis, with the course's names and numbers (6.3) as defaults.

    Attributes:
        J_m: Inertia of the motor shaft [kg·m²].
        J_r: Inertia of the reducer referred to the motor shaft [kg·m²].
        J_p: Inertia of one pulley (there are two) [kg·m²].
        R_p: Pitch radius of a toothed pulley [m].
        k: Reduction ratio ω_p / ω_m [-].
        M1: Equivalent mass of the rigid parts (carriage ``ch``) [kg].
        M2: Equivalent mass of the flexible parts (arm z) [kg].
        K_t: Equivalent stiffness of the arm [N/m].
        mu_t: Equivalent internal damping of the arm, μ_t [N·s/m].
        f_v: Viscous friction referred to the motor shaft [N·m·s/rad].

    Raises:
        ValueError: a mass, inertia, radius, ratio or stiffness is not > 0, or a damping
            or friction coefficient is < 0; the message names the field.
    """

    J_m: float = 4.2e-4
    J_r: float = 1.2e-4
    J_p: float = 6e-5
    R_p: float = 0.020
    k: float = 1 / 5
    M1: float = 136.0
    M2: float = 46.0
    K_t: float = 124_000.0
    mu_t: float = 64.0
    f_v: float = 0.0171

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            if not math.isfinite(value):
                raise ValueError(f"{field.name} must be finite, got {value!r}")
            if field.name in ("mu_t", "f_v"):
                if value < 0:
                    raise ValueError(f"{field.name} must be >= 0, got {value!r}")
            elif value <= 0:
                raise ValueError(f"{field.name} must be > 0, got {value!r}")

    @property
    def ratio(self) -> float:
        """V_ch / ω_m = R_p k [m/rad]: the belt's displacement per motor radian."""
        return self.R_p * self.k


def _real(value: Real) -> Real:
    """A float for a scalar (0-d array) result, the array otherwise."""
    return float(value) if np.ndim(value) == 0 else np.asarray(value)


def _check_rho(rho: float) -> None:
    if not 0.0 < rho <= 1.0:
        raise ValueError(f"rho (efficiency) must be in (0, 1], got {rho!r}")


# --- 6.3: equivalent inertia and kinematics ------------------------------------------------


def inertia_terms(axis: RobotAxis) -> dict[str, float]:
    """Each part's share of the inertia seen by the motor [kg·m²] (course 6.3).

    Returns:
        ``motor_reducer`` J_m + J_r, ``pulleys`` 2 J_p k², ``carriage`` M1 (R_p k)²,
        ``arm`` M2 (R_p k)² (counted in J_eq only when the arm is rigid).
    """
    r2 = axis.ratio**2
    return {
        "motor_reducer": axis.J_m + axis.J_r,
        "pulleys": 2 * axis.J_p * axis.k**2,
        "carriage": axis.M1 * r2,
        "arm": axis.M2 * r2,
    }


def equivalent_inertia(axis: RobotAxis, *, flexible: bool = True) -> float:
    """J_eq seen by the motor [kg·m²] (course 6.3).

    Flexible arm: J_m + J_r + 2 J_p k² + M1 (R_p k)² (2.7208e-3 with the course's data);
    rigid arm: M2 (R_p k)² added (3.4568e-3).
    """
    terms = inertia_terms(axis)
    j_eq = terms["motor_reducer"] + terms["pulleys"] + terms["carriage"]
    return j_eq if flexible else j_eq + terms["arm"]


def speeds(axis: RobotAxis, omega_m: Real) -> tuple[Real, Real]:
    """(ω_p [rad/s], V_ch [m/s]) from the motor speed ω_m [rad/s]: ω_p = k ω_m, V_ch = R_p ω_p.

    For a rigid arm V_2 = V_ch; for the flexible arm V_2 is a state of its own.
    """
    omega_p = axis.k * omega_m
    return omega_p, axis.R_p * omega_p


def arm_force(axis: RobotAxis, y: Real, v: Real) -> Real:
    """Force of the arm on the carriage along y [N]: K_t (y_2 - y_ch) + μ_t (V_2 - V_ch).

    Args:
        y: Deflection y_2 - y_ch [m].
        v: Its rate V_2 - V_ch [m/s].
    """
    return axis.K_t * y + axis.mu_t * v


def arm_acceleration(axis: RobotAxis, y: Real, v: Real) -> Real:
    """V̇_2 [m/s²] from the arm's own PFD, M2 V̇_2 = -K_t (y_2 - y_ch) - μ_t (V_2 - V_ch)."""
    return -arm_force(axis, y, v) / axis.M2


def motor_torque(
    axis: RobotAxis,
    omega_m: Real,
    omega_m_dot: Real,
    *,
    y: Real = 0.0,
    v: Real = 0.0,
    flexible: bool = True,
    rho: float = 1.0,
) -> Real:
    """Motor torque C_m [N·m] that gives ω_m(t) (course 6.3, with 6.4's efficiency ρ).

    With ρ = 1 this is the kinetic-energy theorem solved for C_m, the arm's PFD giving
    M2 V_2 V̇_2 = -(K_t y + μ_t v) V_2::

        C_m = J_eq ω̇_m + f_v ω_m - R_p k (K_t y + μ_t v)      (flexible arm)
        C_m = J_eq ω̇_m + f_v ω_m                              (rigid arm, y and v ignored)

    With ρ < 1 the torque the reducer's output needs, referred to the motor shaft,
    C_s = (2 J_p k² + M1 (R_p k)² [+ M2 (R_p k)²]) ω̇_m - R_p k (K_t y + μ_t v), is divided
    by ρ when driving (C_s ω_m > 0) and multiplied by ρ when braking; (J_m + J_r) ω̇_m and
    f_v ω_m are added as they are.

    Args:
        omega_m: Motor speed [rad/s].
        omega_m_dot: Motor acceleration [rad/s²].
        y: Arm deflection y_2 - y_ch [m] (flexible arm only).
        v: Its rate V_2 - V_ch [m/s] (flexible arm only).
        flexible: False for the rigid arm (M2 in J_eq).
        rho: Reducer efficiency in (0, 1].

    Raises:
        ValueError: rho outside (0, 1].
    """
    _check_rho(rho)
    upstream = (axis.J_m + axis.J_r) * omega_m_dot + axis.f_v * omega_m
    c_s = _output_torque(axis, omega_m_dot, y, v, flexible)
    if rho == 1.0:
        return upstream + c_s
    driving = np.asarray(c_s * omega_m) > 0
    return _real(upstream + np.where(driving, c_s / rho, c_s * rho))


def _output_torque(axis: RobotAxis, omega_m_dot: Real, y: Real, v: Real, flexible: bool) -> Real:
    """C_s: torque needed downstream of the reducer, referred to the motor shaft [N·m]."""
    terms = inertia_terms(axis)
    j_out = terms["pulleys"] + terms["carriage"]
    if not flexible:
        return (j_out + terms["arm"]) * omega_m_dot
    return j_out * omega_m_dot - axis.ratio * arm_force(axis, y, v)


def reducer_loss(
    axis: RobotAxis,
    omega_m: Real,
    omega_m_dot: Real,
    *,
    y: Real = 0.0,
    v: Real = 0.0,
    flexible: bool = True,
    rho: float = 1.0,
) -> Real:
    """P_loss [W] (>= 0) dissipated in the reducer (course 6.4): (1 - ρ) P_e.

    P_e is the power entering the reducer: C_s ω_m / ρ from the motor when driving,
    -C_s ω_m from the load side when braking (C_s as in :func:`motor_torque`).
    Same arguments as :func:`motor_torque`; zero when ρ = 1.
    """
    _check_rho(rho)
    p_s = _output_torque(axis, omega_m_dot, y, v, flexible) * omega_m
    p_e = np.where(np.asarray(p_s) > 0, p_s / rho, -p_s)
    return _real((1.0 - rho) * p_e)


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


# --- 6.4: efficiency of components in series -------------------------------------------------


def series_efficiency(rhos: Iterable[float]) -> float:
    """Overall efficiency of components in series: the product of their ρ (course 6.4).

    Raises:
        ValueError: a ρ outside (0, 1] (the message gives its index), or no component.
    """
    product, count = 1.0, 0
    for index, rho in enumerate(rhos):
        if not 0.0 < rho <= 1.0:
            raise ValueError(f"rho[{index}] (efficiency) must be in (0, 1], got {rho!r}")
        product *= rho
        count += 1
    if count == 0:
        raise ValueError("rhos is empty: give at least one efficiency")
    return product


def power_loss(P_e: Real, rho: float) -> Real:
    """Power lost in a component [W]: P_e (1 - ρ), P_e the power entering it (course 6.4).

    Raises:
        ValueError: rho outside (0, 1].
    """
    _check_rho(rho)
    return P_e * (1.0 - rho)


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
    _check_rho(rho)
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


# --- the back-and-forth move of a transfer robot ---------------------------------------------


def back_and_forth(
    t: float, stroke: float, top_speed: float, accel_time: float, pause: float
) -> tuple[float, float]:
    """(position [m], speed [m/s]) of a point-to-point cycle between 0 and ``stroke``.

    Trapezoidal speed profile: accelerate at a = top_speed / accel_time, cruise at
    ``top_speed``, decelerate at −a, stand still for ``pause``; then the same move back
    to 0 and a pause; the cycle repeats for ever (period 2 (t_move + pause)). A stroke too
    short to reach ``top_speed`` gives a triangle of peak √(stroke a). Zero top speed or
    stroke: at rest at 0.

    Args:
        t: Time [s] since the start of the first move (t < 0: at rest at 0).
        stroke: Distance of one move [m] (>= 0).
        top_speed: Cruise speed [m/s] (its magnitude is used).
        accel_time: Time to reach ``top_speed`` from rest [s] (0: a speed step).
        pause: Standstill at each end [s] (>= 0).
    """
    v_top = abs(top_speed)
    if stroke <= 0 or v_top <= 0 or t <= 0:
        return 0.0, 0.0
    ramp = max(accel_time, 0.0)
    if ramp > 0 and stroke < v_top * ramp:  # triangle: never reaches v_top
        v_top = math.sqrt(stroke * v_top / ramp)
        ramp = stroke / v_top
    move = stroke / v_top + ramp  # two half ramps add one ramp to stroke / v_top
    t = t % (2.0 * (move + pause))
    back = t >= move + pause
    if back:
        t -= move + pause
    if t >= move:
        x, v = stroke, 0.0
    elif ramp > 0 and t < ramp:
        x, v = 0.5 * v_top * t * t / ramp, v_top * t / ramp
    elif ramp > 0 and t > move - ramp:
        left = move - t
        x, v = stroke - 0.5 * v_top * left * left / ramp, v_top * left / ramp
    else:
        x, v = v_top * (t - 0.5 * ramp), v_top
    return (stroke - x, -v) if back else (x, v)
