"""The robot's y axis (course 6.3, 6.4): the course's numbers, the theorem on a motion, limits."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from sandbox.mechanics.robot_axis import (
    RobotAxis,
    arm_acceleration,
    arm_damping_ratio,
    arm_natural_frequency,
    arm_ringing,
    back_and_forth,
    chain_mass,
    energy_balance,
    equivalent_inertia,
    expm,
    free_axis_frequency,
    frequency_response,
    inertia_terms,
    kinetic_energy,
    motor_torque,
    power_loss,
    powers,
    reducer_loss,
    series_efficiency,
    speeds,
    state_matrices,
    step_response,
)

AXIS = RobotAxis()
REL = 5e-3  # the target: the course's numbers within 0.5 %


def test_equivalent_inertia_is_the_course_sum_with_two_pulleys_after_the_reducer():
    # J_m + J_r = 5.4e-4; 2 J_p k² = 1.2e-4/25 = 4.8e-6; M1 (R_p k)² = 136 × 0.004² = 2.176e-3
    assert equivalent_inertia(AXIS) == pytest.approx(2.7208e-3, rel=REL)
    assert equivalent_inertia(AXIS) == pytest.approx(2.7208e-3, rel=1e-12)
    # rigid arm: + M2 (R_p k)² = 46 × 1.6e-5 = 7.36e-4
    assert equivalent_inertia(AXIS, flexible=False) == pytest.approx(3.4568e-3, rel=REL)
    assert equivalent_inertia(AXIS, flexible=False) == pytest.approx(3.4568e-3, rel=1e-12)
    terms = inertia_terms(AXIS)
    # "l'inertie de la poulie ... divisée par 25": k² = 1/25
    assert terms["pulleys"] == pytest.approx(2 * 6e-5 / 25, rel=1e-12)
    assert terms == pytest.approx(
        {"motor_reducer": 5.4e-4, "pulleys": 4.8e-6, "carriage": 2.176e-3, "arm": 7.36e-4},
        rel=1e-12,
    )


def test_speeds_follow_the_reducer_and_the_pulley():
    omega_m = 1500 * 2 * math.pi / 60  # 1500 tr/min = 157.08 rad/s
    omega_p, v_ch = speeds(AXIS, omega_m)
    assert omega_p == pytest.approx(31.4159, rel=1e-5)  # k ω_m
    assert v_ch == pytest.approx(0.628319, rel=1e-5)  # R_p ω_p
    assert AXIS.ratio == pytest.approx(0.004)


def test_rigid_arm_without_friction_gives_c_m_equal_j_eq_omega_dot():
    """Course 6.3: M2 in J_eq and f_v = 0 give C_m = J_eq ω̇_m."""
    frictionless = dataclasses.replace(AXIS, f_v=0.0)
    c_m = motor_torque(frictionless, 80.0, 1000.0, flexible=False)
    assert c_m == pytest.approx(3.4568e-3 * 1000.0, rel=1e-12)  # 3.4568 N·m
    # with friction: + f_v ω_m = 0.0171 × 80 = 1.368 N·m
    assert motor_torque(AXIS, 80.0, 1000.0, flexible=False) == pytest.approx(4.8248, rel=1e-12)


def _motion(duration: float = 0.5, omega_max: float = 150.0, dt: float = 1e-4):
    """A start-stop motion ω_m = Ω sin²(π t / τ) and the flexible arm it drives (RK4).

    Returns t, ω_m, ω̇_m, y = y_2 - y_ch, v = V_2 - V_ch on the grid.
    """
    t = np.arange(0.0, duration + dt / 2, dt)

    def omega_dot(time: float) -> float:
        return omega_max * math.pi / duration * math.sin(2 * math.pi * time / duration)

    def rates(time: float, state: np.ndarray) -> np.ndarray:
        y, v = state
        # v̇ = V̇_2 - V̇_ch, the arm's PFD minus the carriage's acceleration R_p k ω̇_m
        return np.array([v, arm_acceleration(AXIS, y, v) - AXIS.ratio * omega_dot(time)])

    states = np.zeros((t.size, 2))
    for i in range(t.size - 1):
        s, h = states[i], dt
        k1 = rates(t[i], s)
        k2 = rates(t[i] + h / 2, s + h / 2 * k1)
        k3 = rates(t[i] + h / 2, s + h / 2 * k2)
        k4 = rates(t[i] + h, s + h * k3)
        states[i + 1] = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    omega = omega_max * np.sin(math.pi * t / duration) ** 2
    omega_d = np.array([omega_dot(time) for time in t])
    return t, omega, omega_d, states[:, 0], states[:, 1]


def test_kinetic_energy_theorem_holds_on_a_motion_numerically():
    """dT/dt by finite differences of T equals P_ext + P_int with C_m from the theorem."""
    t, omega, omega_d, y, v = _motion()
    _, v_ch = speeds(AXIS, omega)
    v_2 = v_ch + v
    energy = kinetic_energy(AXIS, omega, v_2)
    dT_dt = np.gradient(energy, t)
    c_m = motor_torque(AXIS, omega, omega_d, y=y, v=v)
    p = powers(AXIS, c_m, omega, y=y, v=v)
    scale = float(np.max(np.abs(p.P_ext)))  # ~ 100 W
    inner = slice(1, -1)  # np.gradient is one-sided (first order) at the ends
    assert np.max(np.abs(dT_dt - p.P_ext - p.P_int)[inner]) < 1e-4 * scale
    # the arm is really moving: its spring power is not negligible
    assert np.max(np.abs(p.P_spring)) > 1e-3 * scale
    # the torque of the rigid-arm J_eq (no spring term) misses the balance
    c_rigid_terms = motor_torque(AXIS, omega, omega_d)
    wrong = powers(AXIS, c_rigid_terms, omega, y=y, v=v)
    assert np.max(np.abs(dT_dt - wrong.P_ext - wrong.P_int)[inner]) > 1e-2 * scale


def test_energy_balance_is_zero_with_the_arm_pfd_and_not_otherwise():
    omega, omega_d, y, v = 120.0, -800.0, 1.2e-3, -0.05
    v_2 = speeds(AXIS, omega)[1] + v
    v_2_dot = arm_acceleration(AXIS, y, v)
    c_m = motor_torque(AXIS, omega, omega_d, y=y, v=v)
    residual = energy_balance(AXIS, c_m, omega, omega_d, y=y, V_2=v_2, V_2_dot=v_2_dot)
    assert residual == pytest.approx(0.0, abs=1e-9)
    # 0.1 N·m too much at 120 rad/s leaves -12 W unbalanced
    off = energy_balance(AXIS, c_m + 0.1, omega, omega_d, y=y, V_2=v_2, V_2_dot=v_2_dot)
    assert off == pytest.approx(-12.0, rel=1e-9)
    rigid = motor_torque(AXIS, omega, omega_d, flexible=False)
    assert energy_balance(AXIS, rigid, omega, omega_d, flexible=False) == pytest.approx(
        0.0, abs=1e-9
    )


def test_flexible_and_rigid_torques_agree_when_the_arm_moves_with_the_carriage():
    omega, omega_d = 100.0, 600.0
    rigid = motor_torque(AXIS, omega, omega_d, flexible=False)
    # steady speed, spring relaxed: both are f_v ω_m = 1.71 N·m
    assert motor_torque(AXIS, omega, 0.0) == pytest.approx(1.71, rel=1e-12)
    assert motor_torque(AXIS, omega, 0.0, flexible=False) == pytest.approx(1.71, rel=1e-12)
    # accelerating with the spring relaxed: the arm is not pushed yet, M2 (R_p k)² ω̇_m less
    relaxed = motor_torque(AXIS, omega, omega_d)
    assert rigid - relaxed == pytest.approx(7.36e-4 * omega_d, rel=1e-12)  # 0.4416 N·m
    # the spring stretched so that the arm accelerates with the carriage (V̇_2 = V̇_ch):
    # K_t y = -M2 R_p k ω̇_m, y = -46 × 0.004 × 600 / 124000 = -0.890 mm
    y = -AXIS.M2 * AXIS.ratio * omega_d / AXIS.K_t
    assert arm_acceleration(AXIS, y, 0.0) == pytest.approx(AXIS.ratio * omega_d)
    assert motor_torque(AXIS, omega, omega_d, y=y) == pytest.approx(rigid, rel=1e-12)


def test_efficiency_driving_and_braking():
    """ρ = 0.95 (the course's reducer): C_s / ρ when driving, ρ C_s when braking."""
    rho = 0.95
    # rigid arm, ω_m = 100 rad/s, ω̇_m = ±500 rad/s²:
    # C_s = (4.8e-6 + 2.176e-3 + 7.36e-4) × 500 = 1.4584 N·m; (J_m + J_r) ω̇ = 0.27; f_v ω = 1.71
    drive = motor_torque(AXIS, 100.0, 500.0, flexible=False, rho=rho)
    assert drive == pytest.approx(0.27 + 1.71 + 1.4584 / 0.95, rel=1e-12)  # 3.5152 N·m
    brake = motor_torque(AXIS, 100.0, -500.0, flexible=False, rho=rho)
    assert brake == pytest.approx(-0.27 + 1.71 - 1.4584 * 0.95, rel=1e-12)  # 0.05452 N·m
    loss_drive = reducer_loss(AXIS, 100.0, 500.0, flexible=False, rho=rho)
    loss_brake = reducer_loss(AXIS, 100.0, -500.0, flexible=False, rho=rho)
    assert loss_drive == pytest.approx(145.84 / 0.95 * 0.05, rel=1e-12)  # 7.676 W
    assert loss_brake == pytest.approx(145.84 * 0.05, rel=1e-12)  # 7.292 W
    # power balance of the reducer: what the motor gives minus what it keeps, minus C_s ω
    for omega_d, c_m, loss in ((500.0, drive, loss_drive), (-500.0, brake, loss_brake)):
        upstream = 0.27 * np.sign(omega_d) + 1.71
        p_s = 1.4584 * np.sign(omega_d) * 100.0
        assert (c_m - upstream) * 100.0 - p_s == pytest.approx(loss, rel=1e-9)


def test_efficiency_one_loses_nothing_and_vectorises():
    omega = np.array([50.0, 100.0, -80.0])
    omega_d = np.array([300.0, -700.0, 200.0])
    y, v = np.array([1e-4, -2e-4, 0.0]), np.array([0.01, 0.0, -0.02])
    ideal = motor_torque(AXIS, omega, omega_d, y=y, v=v)
    assert motor_torque(AXIS, omega, omega_d, y=y, v=v, rho=1.0) == pytest.approx(ideal)
    assert reducer_loss(AXIS, omega, omega_d, y=y, v=v, rho=1.0) == pytest.approx([0, 0, 0])
    lossy = reducer_loss(AXIS, omega, omega_d, y=y, v=v, rho=0.9)
    assert np.all(lossy > 0)


def test_wind_turbine_numbers_of_6_4():
    """Propeller 0.75, gearbox 0.9, alternator 0.9, transformer 0.9, lines 0.95: about 0.52."""
    overall = series_efficiency([0.75, 0.9, 0.9, 0.9, 0.95])
    assert overall == pytest.approx(0.52, rel=REL)  # 0.5194: the course rounds (gap 0.12 %)
    p_1 = 5e6  # W, Betz power of a large offshore turbine
    p_gearbox_in = p_1 * 0.75
    assert p_gearbox_in == pytest.approx(3.75e6, rel=1e-12)
    assert power_loss(p_gearbox_in, 0.9) == pytest.approx(375e3, rel=1e-12)  # 375 kW of heat
    assert power_loss(1.0e3, 1.0) == 0.0


def test_arm_natural_frequency_and_damping():
    # √(124000 / 46) = √2695.65 = 51.92 rad/s = 8.263 Hz
    assert arm_natural_frequency(AXIS) == pytest.approx(51.9197, rel=1e-5)
    assert arm_natural_frequency(AXIS) / (2 * math.pi) == pytest.approx(8.2633, rel=1e-4)
    # 64 / (2 √(124000 × 46)) = 64 / 4776.6 = 0.01340: a lightly damped arm
    assert arm_damping_ratio(AXIS) == pytest.approx(0.013399, rel=1e-4)
    # free chain: M_eq = 2.7208e-3 / 1.6e-5 = 170.05 kg, √(124000 (1/46 + 1/170.05)) = 58.52
    assert free_axis_frequency(AXIS) == pytest.approx(58.523, rel=1e-4)
    assert free_axis_frequency(AXIS) > arm_natural_frequency(AXIS)


@pytest.mark.parametrize(
    "name", ["J_m", "J_r", "J_p", "R_p", "k", "M1", "M2", "K_t", "mu_t", "f_v"]
)
def test_bad_axis_data_raise_naming_the_field(name):
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        RobotAxis(**{name: -1.0})
    with pytest.raises(ValueError, match=rf"^{name} must be finite"):
        RobotAxis(**{name: math.nan})
    if name in ("mu_t", "f_v"):
        assert getattr(RobotAxis(**{name: 0.0}), name) == 0.0  # no damping, no friction: fine
    else:
        with pytest.raises(ValueError, match=rf"^{name} must be > 0"):
            RobotAxis(**{name: 0.0})


@pytest.mark.parametrize("rho", [0.0, -0.1, 1.2, math.nan])
def test_efficiency_outside_zero_one_raises_naming_rho(rho):
    with pytest.raises(ValueError, match=r"^rho \(efficiency\) must be in \(0, 1\]"):
        motor_torque(AXIS, 1.0, 1.0, rho=rho)
    with pytest.raises(ValueError, match=r"^rho"):
        reducer_loss(AXIS, 1.0, 1.0, rho=rho)
    with pytest.raises(ValueError, match=r"^rho"):
        power_loss(1.0, rho)
    with pytest.raises(ValueError, match=r"^rho\[1\]"):
        series_efficiency([0.9, rho])
    with pytest.raises(ValueError, match="empty"):
        series_efficiency([])


# --- the linear motion of the axis -----------------------------------------------------------


def test_expm_matches_closed_exponentials():
    """e^{A t} of a rotation generator is the rotation; of a nilpotent matrix, I + N."""
    angle = 7.3  # large: several squarings
    gen = np.array([[0.0, -angle], [angle, 0.0]])
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    assert expm(gen) == pytest.approx(rot, abs=1e-12)
    nil = np.array([[0.0, 3.0], [0.0, 0.0]])
    assert expm(nil) == pytest.approx(np.eye(2) + nil, abs=1e-15)
    assert expm(np.diag([-50.0, 2.0])) == pytest.approx(np.diag([math.exp(-50), math.exp(2)]))


def test_chain_mass_is_j_eq_over_the_ratio_squared_and_loses_rho_upstream():
    """J_eq / (R_p k)² = 2.7208e-3 / 1.6e-5 = 170.05 kg; with ρ the motor and the reducer
    (5.4e-4 kg·m² = 33.75 kg on the belt) count for ρ times that."""
    assert chain_mass(AXIS) == pytest.approx(170.05, rel=1e-12)
    assert chain_mass(AXIS, flexible=False) == pytest.approx(216.05, rel=1e-12)
    assert chain_mass(AXIS, rho=0.8) == pytest.approx(170.05 - 0.2 * 33.75, rel=1e-12)


def test_rigid_step_response_is_the_first_order_start_of_the_course():
    """Rigid arm, constant C_m: J_eq ω̇ = C_m − f_v ω, so ω = (C_m/f_v)(1 − e^{−f_v t/J_eq})
    (J_eq = 3.4568e-3 kg·m², time constant 0.2022 s, 58.48 rad/s for 1 N·m)."""
    t = np.array([0.0, 0.05, 0.2022, 1.0, 3.0])
    got = step_response(AXIS, t, 1.0, flexible=False)
    tau = 3.4568e-3 / 0.0171
    expected = (1 / 0.0171) * (1 - np.exp(-t / tau))
    assert got["omega_m"] == pytest.approx(expected, rel=1e-10, abs=1e-12)
    assert got["V_ch"] == pytest.approx(0.004 * expected, rel=1e-10, abs=1e-14)
    assert got["V_2"] == pytest.approx(got["V_ch"]) and not got["y"].any()


def test_flexible_step_response_starts_on_j_eq_alone_and_ends_on_the_same_speed():
    """At t → 0 the arm is unloaded: ω ≈ C_m t / J_eq with the flexible J_eq (2.7208e-3);
    in the end the arm rides along (y → 0) at the common speed C_m / f_v."""
    early = step_response(AXIS, [1e-5], 2.0)
    assert early["omega_m"][0] == pytest.approx(2.0 * 1e-5 / 2.7208e-3, rel=1e-4)
    late = step_response(AXIS, [20.0], 2.0)
    assert late["omega_m"][0] == pytest.approx(2.0 / 0.0171, rel=1e-9)
    assert late["V_2"][0] == pytest.approx(late["V_ch"][0], rel=1e-9)
    assert abs(late["y"][0]) < 1e-12


def test_frequency_response_peaks_at_the_free_axis_frequency():
    """The deflection per N·m is largest near √(K_t (1/M2 + (R_p k)²/J_eq)) = 58.5 rad/s,
    and at low frequency it is the quasi-static −M2 a / K_t of the chain's acceleration."""
    freqs = np.linspace(40.0, 80.0, 401)
    amps = np.array([abs(frequency_response(AXIS, w)[1]) for w in freqs])
    assert freqs[np.argmax(amps)] == pytest.approx(free_axis_frequency(AXIS), rel=5e-3)
    w = 0.5  # rad/s, far below: the chain's speed follows C_m / (f_v + i ω J_rigid)
    omega_m, y = frequency_response(AXIS, w)
    speed = 1 / (0.0171 + 1j * w * equivalent_inertia(AXIS, flexible=False))
    assert omega_m == pytest.approx(speed, rel=1e-3)
    accel = 1j * w * omega_m * AXIS.ratio
    assert y == pytest.approx(-AXIS.M2 * accel / AXIS.K_t, rel=1e-3)


def test_back_and_forth_is_a_trapezoid_whose_speed_integrates_to_the_stroke():
    """1.5 m at 0.2094 m/s (500 tr/min), ramps of 0.05 s, pauses of 1 s: each move lasts
    1.5 / 0.2094 + 0.05 = 7.212 s; the speed is the position's derivative; the cycle goes
    0 -> 1.5 -> 0 every 16.42 s and repeats."""
    v_top = 500 * 2 * math.pi / 60 * 0.004
    args = (1.5, v_top, 0.05, 1.0)
    move = 1.5 / v_top + 0.05
    assert move == pytest.approx(7.2120, abs=1e-4)
    t = np.linspace(0.0, 2 * (2 * (move + 1.0)), 200_001)
    got = np.array([back_and_forth(ti, *args) for ti in t])
    x, v = got[:, 0], got[:, 1]
    assert np.min(x) == 0.0 and np.max(x) == pytest.approx(1.5, rel=1e-12)
    assert np.max(np.abs(v)) == pytest.approx(v_top, rel=1e-12)
    assert np.max(np.abs(np.diff(v))) <= v_top / 0.05 * (t[1] - t[0]) * (1 + 1e-9)  # ramps
    dxdt = np.gradient(x, t)
    assert np.max(np.abs(dxdt - v)[1:-1]) < 1e-3 * v_top  # one-sided at the ends
    assert back_and_forth(move, *args) == (1.5, 0.0)  # stopped at the far end
    assert back_and_forth(move + 1.0 + 0.5 * move, *args)[1] == pytest.approx(-v_top)
    period = 2 * (move + 1.0)
    assert back_and_forth(3.3 + period, *args) == pytest.approx(back_and_forth(3.3, *args))
    # a stroke too short for the top speed: a triangle of peak √(stroke a), a = v_top/t_a
    peak = math.sqrt(0.005 * v_top / 0.05)
    assert peak < v_top
    tri = np.array([back_and_forth(ti, 0.005, v_top, 0.05, 0.2)[1] for ti in t[t < 0.2]])
    assert np.max(tri) <= peak * (1 + 1e-12)
    assert back_and_forth(0.005 / peak, 0.005, v_top, 0.05, 0.2)[1] == pytest.approx(peak)
    assert back_and_forth(2 * 0.005 / peak, 0.005, v_top, 0.05, 0.2) == (0.005, 0.0)
    # at rest: zero speed, zero stroke, before the start; a speed step without ramp
    assert back_and_forth(1.0, 1.5, 0.0, 0.05, 1.0) == (0.0, 0.0)
    assert back_and_forth(1.0, 0.0, v_top, 0.05, 1.0) == (0.0, 0.0)
    assert back_and_forth(-1.0, *args) == (0.0, 0.0)
    assert back_and_forth(1.0, 1.5, v_top, 0.0, 1.0) == pytest.approx((v_top, v_top))


def test_arm_ringing_is_the_oscillating_eigenvalue_between_its_two_limits():
    """Torque command: the arm rings against the free chain at √(ω² − σ²) with
    ω = 58.52 rad/s; a stiff speed servo (K_v = J_eq,rigid / 10 ms) nearly holds the
    carriage, so the arm rings close to its own ω_n √(1 − ζ²) = 51.91 rad/s, and the
    servo's damping on the carriage adds to μ_t's (σ = 3.46 instead of ζ ω_n = 0.70 1/s)."""
    sigma, wd = arm_ringing(AXIS)
    assert wd == pytest.approx(free_axis_frequency(AXIS), rel=2e-3)
    kv = equivalent_inertia(AXIS, flexible=False) / 0.01
    sigma, wd = arm_ringing(AXIS, servo_gain=kv, position_gain=10.0)
    zeta = arm_damping_ratio(AXIS)
    held = arm_natural_frequency(AXIS) * math.sqrt(1 - zeta**2)
    assert held == pytest.approx(51.91, rel=1e-3)
    assert wd == pytest.approx(52.31, rel=1e-3) and wd == pytest.approx(held, rel=1e-2)
    assert sigma == pytest.approx(3.463, rel=1e-3) and sigma > 4 * zeta * held
    # the position loop is ten times slower than the servo: it moves the arm's mode < 1 %
    assert arm_ringing(AXIS, servo_gain=kv)[1] == pytest.approx(wd, rel=1e-2)
    a, _ = state_matrices(AXIS, servo_gain=kv, position_gain=10.0)
    assert np.all(np.linalg.eigvals(a).real < 0)  # the loop is stable


def test_as_real_gives_a_float_for_a_scalar_and_the_array_otherwise():
    from sandbox.mechanics.robot_axis import as_real

    scalar = as_real(np.float64(2.5) * np.ones(()))
    assert type(scalar) is float and scalar == 2.5
    array = as_real(np.array([1.0, 2.0]))
    assert isinstance(array, np.ndarray) and list(array) == [1.0, 2.0]


@pytest.mark.parametrize("rho", [0.0, -0.1, 1.0001, math.nan])
def test_check_rho_refuses_an_efficiency_outside_0_1(rho):
    from sandbox.mechanics.robot_axis import check_rho

    with pytest.raises(ValueError, match="rho"):
        check_rho(rho)


@pytest.mark.parametrize("rho", [1e-9, 0.5, 1.0])
def test_check_rho_accepts_an_efficiency_in_0_1(rho):
    from sandbox.mechanics.robot_axis import check_rho

    check_rho(rho)
