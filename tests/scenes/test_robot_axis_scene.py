"""Robot axis scene (course 6.3, 6.4) against the closed forms of the linear axis.

The course's numbers (J_eq = 2.7208e-3 and 3.4568e-3 kg·m²) come out of the simulated
model within 0.5 %; the motion from rest matches the exact solution of 6.3's equations;
the hard cases (the arm driven at its resonance, top speed, a long run, the rigid arm, a
reducer with losses, braking) stay within stated tolerances.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from sandbox.mechanics.robot_axis import (
    RobotAxis,
    arm_natural_frequency,
    arm_ringing,
    chain_mass,
    equivalent_inertia,
    free_axis_frequency,
    frequency_response,
    step_response,
)
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene
from sandbox.scenes.robot_axis import (
    DEFAULTS,
    RAIL,
    RPM,
    SCENE,
    axis_of,
    default_timestep,
    move_reference,
    position_gain,
    servo_gain,
)

REL = 5e-3  # the target for the course's numbers
TORQUE = {"profile": 0.0}
SPEED = {"profile": 1.0}
SINE = {"profile": 3.0}
COURSE = RobotAxis()


def _sim(**values: float) -> Simulation:
    return Simulation(get_scene("robot_axis"), values=values)


def _run(sim: Simulation, duration: float, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Readouts after every step for ``duration`` [s] (time included)."""
    rows = []
    for _ in range(int(round(duration / sim.timestep))):
        sim.step()
        rows.append([sim.data.time, *sim.readouts(list(names)).values()])
    a = np.array(rows)
    return {"time": a[:, 0], **{n: a[:, i + 1] for i, n in enumerate(names)}}


def test_registered_with_the_course_defaults():
    assert SCENES["robot_axis"] is SCENE and SCENE.sections == "6.3, 6.4"
    assert axis_of(DEFAULTS) == COURSE
    assert SCENE.param("eta").default == 1.0 and SCENE.param("flexible").choices[1]
    # the first two commands are contracts (0, 1); the back-and-forth one is the default
    assert SCENE.param("profile").choices == (
        "Couple constant", "Consigne de vitesse", "Aller-retour", "Couple sinusoïdal"
    )  # fmt: skip
    assert DEFAULTS["profile"] == 2.0 and SCENE.control is not None


@pytest.mark.parametrize(("flexible", "j_eq"), [(1.0, 2.7208e-3), (0.0, 3.4568e-3)])
def test_course_equivalent_inertia_is_what_the_simulated_motor_feels(flexible, j_eq):
    """6.3: from rest the arm is unloaded, so the motor's first acceleration is C_m / J_eq:
    J_eq without M2 for the flexible arm (2.7208e-3), with it for the rigid one (3.4568e-3).
    Measured on the simulated chain (MuJoCo's armature and masses), not on the formula."""
    sim = _sim(flexible=flexible, torque_Nm=2.0, **TORQUE)
    r = DEFAULTS["R_p"] * DEFAULTS["k"]
    omega_dot = float(sim.data.qacc[0]) / r  # at t = 0: ω_m = 0, so f_v plays no part
    readout = sim.readouts(["J_eq", "C_m"])
    assert readout["C_m"] / omega_dot == pytest.approx(j_eq, rel=REL)
    assert readout["C_m"] / omega_dot == pytest.approx(j_eq, rel=1e-9)
    assert readout["J_eq"] == pytest.approx(j_eq, rel=REL)
    assert SCENE.reference is not None
    assert SCENE.reference({**DEFAULTS, "flexible": flexible})["J_eq"] == pytest.approx(
        j_eq, rel=REL
    )
    # T of the simulated chain (generic readout, armature included) is ½ J_eq ω_m²
    sim.advance(0.05)
    got = sim.readouts(["T", "E_c", "omega_m", "V_2"])
    assert got["E_c"] == pytest.approx(got["T"], rel=1e-12)
    if flexible == 0.0:
        assert got["T"] == pytest.approx(0.5 * j_eq * got["omega_m"] ** 2, rel=1e-9)


def test_rigid_arm_without_friction_gives_c_m_equal_j_eq_omega_dot():
    """6.3's last form: M2 in J_eq and f_v = 0: C_m = J_eq ω̇_m at every instant, so the speed
    grows linearly, ω_m = C_m t / J_eq (3.4568e-3 kg·m²)."""
    sim = _sim(flexible=0.0, f_v=0.0, torque_Nm=3.4568, **TORQUE)
    sim.advance(0.5)
    got = sim.readouts(["omega_m", "C_m_gap", "V_ch"])
    assert got["omega_m"] == pytest.approx(3.4568 * 0.5 / 3.4568e-3, rel=1e-9)  # 500 rad/s
    assert got["V_ch"] == pytest.approx(0.004 * got["omega_m"], rel=1e-12)
    assert abs(got["C_m_gap"]) < 1e-9


@pytest.mark.parametrize(
    "values",
    [
        {"torque_Nm": 2.0},
        {"torque_Nm": -5.0, "eta": 0.8},
        {"torque_Nm": 1.0, "flexible": 0.0},
        {"torque_Nm": 4.0, "M2": 120.0, "K_t": 30000.0, "mu_t": 0.0},
    ],
)
def test_torque_step_follows_the_exact_motion_of_6_3(values):
    """Constant C_m from rest: the simulated ω_m and V_2 match the exact solution of the
    linear equations (matrix exponential) within 1e-5 of their peak, over 1.5 s (9 periods
    of the arm) on the rail; the carriage, C_m_ref and the theorem residual too."""
    sim = _sim(**TORQUE, **values)
    if values["torque_Nm"] < 0:  # start at the far end, to run back along the rail
        sim.data.qpos[0] = 2.0
        mujoco.mj_forward(sim.model, sim.data)
    v = {**DEFAULTS, **TORQUE, **values}
    names = ("omega_m", "V_2", "V_ch", "deflection", "C_m_gap", "energy_residual", "F_stop")
    got = _run(sim, 1.5, names)
    assert not got["F_stop"].any()  # the end stops play no part
    ref = step_response(
        axis_of(v), got["time"], v["torque_Nm"], flexible=v["flexible"] > 0.5, rho=v["eta"]
    )
    for key, ref_key in (("omega_m", "omega_m"), ("V_2", "V_2"), ("V_ch", "V_ch")):
        peak = np.max(np.abs(ref[ref_key]))
        assert np.max(np.abs(got[key] - ref[ref_key])) < 1e-5 * peak, key
    assert np.max(np.abs(got["deflection"] - ref["y"])) < 1e-5 * np.max(np.abs(ref["y"]) + 1e-12)
    # ρ = 1: the course's torque is the applied one. ρ < 1: the same while the motor
    # drives; near the top speed the ringing arm briefly drives the reducer back, where
    # the course's braking ρ differs from the simulated one (gap 1e-4 of C_m)
    gap = 1e-9 if v["eta"] == 1.0 else 1e-3
    assert np.max(np.abs(got["C_m_gap"])) < gap * abs(v["torque_Nm"])
    assert np.max(np.abs(got["C_m_gap"][got["time"] < 1.0])) < 1e-9 * abs(v["torque_Nm"])
    power = abs(v["torque_Nm"]) * np.max(np.abs(got["omega_m"]))
    assert np.max(np.abs(got["energy_residual"])) < 1e-9 * power


def test_speed_servo_reaches_the_set_point_and_matches_its_closed_form():
    """Speed set point as a step (τ = 0): the servo C_m = K_v (ω_c − ω_m) + f_v ω_c is linear,
    so the motion is still exact; the speed settles on the set point itself."""
    values = {"ramp_s": 0.0, "speed_rpm": 800.0, **SPEED}
    sim = _sim(**values)
    v = {**DEFAULTS, **values}
    got = _run(sim, 1.0, ("omega_m", "V_2"))
    ref = step_response(axis_of(v), got["time"], 800 * RPM, servo_gain=servo_gain(v))
    assert np.max(np.abs(got["V_2"] - ref["V_2"])) < 1e-5 * np.max(ref["V_2"])
    sim.advance(4.0)
    assert sim.readouts(["omega_m"])["omega_m"] == pytest.approx(800 * RPM, rel=1e-6)


def test_high_speed_is_stable_and_keeps_the_kinematics():
    """Top set point 3000 tr/min reached in 50 ms, over 1.55 s (1.9 m of the rail): V_ch =
    R_p k ω_m, the arm settles back on the carriage, C_m = f_v ω_m in steady state, the
    theorem residual stays at round-off."""
    sim = _sim(speed_rpm=3000.0, ramp_s=0.05, **SPEED)
    got = _run(sim, 1.55, ("omega_m", "energy_residual", "P_motor", "deflection", "F_stop"))
    assert not got["F_stop"].any()
    assert np.isfinite(got["omega_m"]).all()
    assert np.max(np.abs(got["energy_residual"])) < 1e-9 * np.max(np.abs(got["P_motor"]))
    end = sim.readouts(["omega_m", "V_ch", "V_2", "deflection", "C_m"])
    assert end["omega_m"] == pytest.approx(3000 * RPM, rel=1e-3)  # 314.16 rad/s, arm ringing
    assert end["V_ch"] == pytest.approx(0.004 * end["omega_m"], rel=1e-12)  # 1.2566 m/s
    assert end["V_2"] == pytest.approx(end["V_ch"], rel=1e-4)
    # the start bends the arm by ~3.6 mm; it rings down to a hundredth of that
    peak = np.max(np.abs(got["deflection"]))
    assert peak > 1e-3 and np.max(np.abs(got["deflection"][-100:])) < 1e-2 * peak
    assert end["C_m"] == pytest.approx(0.0171 * end["omega_m"], rel=1e-2)  # servo on ringing


def test_arm_driven_at_its_resonance_reaches_the_closed_form_amplitude():
    """C_m = 1 N·m × sin(ω t) at the arm's frequency against the free chain,
    √(K_t (1/M2 + (R_p k)²/J_eq)) = 58.52 rad/s: after 15 s (17 time constants of the
    lightly damped mode, ζ ≈ 0.015) the deflection's amplitude is the closed-form steady
    state |y| = 8.08 mm within 0.5 %, 25 times the quasi-static deflection at 5 rad/s, and
    it exceeds the arm's own ω_n = √(K_t/M2) = 51.9 rad/s response (the carriage moves)."""
    omega = free_axis_frequency(COURSE)
    assert omega == pytest.approx(58.52, rel=1e-3)
    assert arm_natural_frequency(COURSE) == pytest.approx(51.92, rel=1e-3)
    amplitude = abs(frequency_response(COURSE, omega)[1])
    assert amplitude == pytest.approx(8.08e-3, rel=2e-3)
    assert amplitude > 25 * abs(frequency_response(COURSE, 5.0)[1])
    assert amplitude > 3 * abs(frequency_response(COURSE, arm_natural_frequency(COURSE))[1])
    # the "Couple sinusoïdal" command, tuned to that frequency (9.314 Hz)
    sim = _sim(sine_Nm=1.0, sine_Hz=omega / (2 * math.pi), **SINE)
    ys = []
    for _ in range(15000):  # 15 s at 1 ms
        sim.step()
        assert sim.data.ctrl[0] == math.sin(omega * sim.data.time)  # C_m of the next step
        ys.append(float(sim.data.qpos[1]))
    tail = np.abs(np.array(ys[-1000:]))  # the last 9 periods
    assert np.max(tail) == pytest.approx(amplitude, rel=5e-3)
    # the arm_swing readout is the envelope of that steady oscillation at any instant
    assert sim.readouts(["arm_swing"])["arm_swing"] == pytest.approx(amplitude, rel=5e-3)
    # Without f_v the relative motion is one damped oscillator of reduced mass
    # M2 m_c / (M2 + m_c), m_c = J_eq / (R_p k)² = 170 kg, forced by (M2 / (M2 + m_c)) C_m /
    # (R_p k): at its resonance |y| = that force / (μ_t ω) = 14.2 mm. The chain's friction
    # f_v / (R_p k)² = 1069 N·s/m also damps this mode and brings it down to 8.08 mm.
    free = dataclasses.replace(COURSE, f_v=0.0)
    m_c = chain_mass(free)
    single = (1 / free.ratio) * free.M2 / (free.M2 + m_c) / (free.mu_t * omega)
    assert abs(frequency_response(free, omega)[1]) == pytest.approx(single, rel=1e-9)
    assert single == pytest.approx(14.21e-3, rel=1e-3)


@pytest.mark.slow  # 60 000 steps with the readouts after each: ~5 s
def test_default_back_and_forth_stays_on_its_rail_and_keeps_the_theorem():
    """60 s of the default back-and-forth (a lossy reducer, ρ = 0.9: seven moves, the motor
    driving and braking): the carriage stays between 0 and the 1.5 m stroke within 2 mm,
    away from the end stops, and follows the trapezoid within 3 mm; the theorem's residual
    (with the reducer's simulated, driving-mode loss) stays at round-off at every step."""
    sim = _sim(eta=0.9)
    got = _run(sim, 60.0, ("y_ch", "F_stop", "energy_residual", "P_motor"))
    y = got["y_ch"]
    assert -2e-3 < np.min(y) and np.max(y) < 1.5 + 2e-3 and RAIL == (-0.05, 2.05)
    assert not got["F_stop"].any()
    ref = np.array([move_reference(sim.values, t)[0] for t in got["time"]])
    assert np.max(np.abs(y - ref)) < 3e-3
    assert np.max(y) > 1.5 - 1e-4 and np.min(y[got["time"] > 10]) < 1e-4  # both ends
    assert np.max(np.abs(got["energy_residual"])) < 1e-9 * np.max(np.abs(got["P_motor"]))


def _resonance_energy_gap(dt: float, duration: float) -> tuple[np.ndarray, float]:
    """|E_c(t) − E_c(0) − (W_motor − W_loss − W_diss)| for the sinusoidal torque at the
    arm's resonance through a lossy reducer (ρ = 0.9), and max E_c. The torque is held over
    each step, so W_motor = Σ C_m Δθ_m exactly and W_loss = (1 − ρ)(W_motor − ½ (J_m + J_r)
    ω_m² − ∫ f_v ω_m² dt); ∫ f_v ω_m² and W_diss = ∫ (f_v ω_m² + μ_t v² + K_t y v) dt by
    trapezoids."""
    omega = free_axis_frequency(COURSE)
    sim = Simulation(
        get_scene("robot_axis"),
        values={"eta": 0.9, "sine_Hz": omega / (2 * math.pi), **SINE},
        timestep=dt,
    )
    names = ["E_c", "C_m", "P_diss", "omega_m"]
    rows = [[0.0, 0.0, *sim.readouts(names).values()]]
    for _ in range(int(round(duration / dt))):
        sim.step()
        rows.append([sim.data.time, float(sim.data.qpos[0]), *sim.readouts(names).values()])
    t, y_ch, e, c_m, p_diss, w = np.array(rows).T
    rho, j_up, f_v = 0.9, 5.4e-4, 0.0171
    # C_m read before a step is the torque held over it (its work over the angle turned)
    motor = np.concatenate([[0.0], np.cumsum(c_m[:-1] * np.diff(y_ch) / 0.004)])
    w2 = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] ** 2 + w[:-1] ** 2) * np.diff(t))])
    diss = np.concatenate([[0.0], np.cumsum(0.5 * (p_diss[1:] + p_diss[:-1]) * np.diff(t))])
    loss = (1 - rho) * (motor - 0.5 * j_up * w**2 - f_v * w2)
    assert np.max(np.abs(y_ch)) < 1e-2  # the carriage stays within a centimetre
    return np.abs(e - e[0] - (motor - loss - diss)), float(np.max(e))


@pytest.mark.slow  # 30 000 steps with the readouts after each: ~2 s
def test_resonance_keeps_the_integrated_energy_theorem():
    """10 s at the arm's resonance (the ringing built up, E_c up to 3.6 J): the integrated
    theorem holds within 1 % of max E_c at 1 ms, and the gap shrinks 4 times at 0.5 ms. A
    torque held over each step makes ω̇ jump at every step, so the trapezoids of the
    dissipated powers miss −dt²/12 of those jumps: an O(dt²) sampling error of the check,
    which the model itself does not have (without damping the balance closes to 1e-9 J)."""
    coarse, top = _resonance_energy_gap(1e-3, 10.0)
    fine, _ = _resonance_energy_gap(5e-4, 10.0)
    assert top > 3.0
    assert np.max(coarse) < 1e-2 * top
    assert np.max(fine) == pytest.approx(np.max(coarse) / 4, rel=0.1)
    values = {"mu_t": 0.0, "f_v": 0.0, "sine_Hz": 3.0, **SINE}
    sim = _sim(**values)
    work, y_ch = 0.0, 0.0
    for _ in range(5000):
        c_m = sim.readouts(["C_m"])["C_m"]  # the torque held over the next step
        sim.step()
        work += c_m * (float(sim.data.qpos[0]) - y_ch) / 0.004
        y_ch = float(sim.data.qpos[0])
    got = sim.readouts(["E_c", "deflection"])
    assert got["E_c"] + 0.5 * 124_000 * got["deflection"] ** 2 == pytest.approx(work, abs=1e-7)


def test_arm_rings_after_each_stop_at_the_closed_form_damped_frequency():
    """Default move (1.5 m at 500 tr/min, 50 ms ramps): the arm rings by ~2.8 mm after the
    carriage stops. During the pause the command is constant, so the deflection is the free
    mode of the servoed axis, y ∝ e^{−σ t} cos(ω_d t): −σ ± i ω_d the eigenvalue of the
    linear model (speed servo and position loop), ω_d = 52.31 rad/s, σ = 3.46 1/s. The
    zero crossings give ω_d within 0.2 % and the peaks σ within 2 %, at both ends."""
    v = dict(DEFAULTS)
    sigma, wd = arm_ringing(axis_of(v), servo_gain=servo_gain(v), position_gain=position_gain(v))
    assert wd == pytest.approx(52.31, rel=1e-3) and sigma == pytest.approx(3.463, rel=1e-3)
    sim = _sim()
    move = 1.5 / (500 * RPM * 0.004) + 0.05  # 7.212 s, then a pause of 1 s
    for stop in (move, 2 * move + 1.0):  # at the far end, back at the start
        sim.advance(stop - sim.data.time)
        assert move_reference(sim.values, sim.data.time)[1] == 0.0  # stopped
        got = _run(sim, 0.9, ("deflection", "y_ch"))
        t, y = got["time"] - stop, got["deflection"]
        assert 2e-3 < np.max(np.abs(y)) < 4e-3  # millimetres: the course's flexible arm
        keep = t > 0.05  # past the servo's own 10 ms transient
        t, y = t[keep], y[keep]
        i = np.nonzero(np.diff(np.sign(y)) != 0)[0]
        zeros = t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
        assert len(zeros) >= 12
        assert math.pi / np.mean(np.diff(zeros)) == pytest.approx(wd, rel=2e-3)
        spans = zip(zeros[:-1], zeros[1:], strict=True)
        peaks = [np.max(np.abs(y[(t >= a) & (t < b)])) for a, b in spans]
        mid = 0.5 * (zeros[1:] + zeros[:-1])
        assert -np.polyfit(mid, np.log(peaks), 1)[0] == pytest.approx(sigma, rel=2e-2)
        # not the arm on a carriage held still, nor against the free chain
        assert abs(wd / arm_natural_frequency(COURSE) - 1) > 5e-3
        assert abs(wd / free_axis_frequency(COURSE) - 1) > 0.1


def test_back_and_forth_is_pure_and_recovers_from_a_live_change():
    """The command depends on the time and the state only: after a reset the same steps
    give the same motion bit for bit. A stroke shortened mid-move (live) brings the carriage
    back within the new stroke at the top speed, without reaching an end stop."""
    sim = _sim()
    sim.advance(3.0)
    first = sim.data.qpos.copy(), sim.data.qvel.copy()
    sim.reset()
    sim.advance(1.0)
    sim.advance(2.0)
    assert np.array_equal(sim.data.qpos, first[0]) and np.array_equal(sim.data.qvel, first[1])
    sim.advance(2.0)  # 5 s: the carriage at ~1 m
    sim.set_value("stroke", 0.5)
    got = _run(sim, 20.0, ("y_ch", "V_ch", "F_stop"))
    assert not got["F_stop"].any()
    # the new schedule's speed plus a correction held within the top speed (0.21 m/s)
    assert np.max(np.abs(got["V_ch"])) < 500 * RPM * 0.004 * 2.3
    late = got["y_ch"][got["time"] > 12.0]
    assert -2e-3 < np.min(late) and np.max(late) < 0.5 + 2e-3


def test_a_constant_command_ends_on_the_end_stops():
    """A constant torque or speed runs the carriage to the end of the rail: it stops on the
    end stop (the slide's limit, the only constraint) with its centre at 2.05 m or −0.05 m,
    a few millimetres in at most; the stop then holds the motor's push, F_stop = −ρ C_m /
    (R_p k) (−250 N for 1 N·m), and its power F_stop V_ch is exactly the gap of the course's
    energy theorem (the course has no stop)."""
    sim = _sim(torque_Nm=1.0, **TORQUE)
    got = _run(sim, 25.0, ("y_ch", "F_stop", "V_ch", "energy_residual", "P_motor"))
    assert np.max(got["y_ch"]) < RAIL[1] + 5e-3 and got["y_ch"][-1] > RAIL[1] - 1e-3
    hit = np.argmax(got["F_stop"] != 0)
    assert 8.5 < got["time"][hit] < 9.5  # ~0.23 m/s: 2.05 m in about 9 s
    # 16 s later the arm has rung down on the stopped carriage (ζ ω_n = 0.70 1/s)
    end = sim.readouts(["F_stop", "V_ch", "C_m", "C_m_gap", "F_belt", "F_arm"])
    assert end["F_stop"] == pytest.approx(-1.0 / 0.004, rel=1e-3)
    assert end["F_belt"] == pytest.approx(1.0 / 0.004, rel=1e-3) and abs(end["F_arm"]) < 0.1
    assert abs(end["V_ch"]) < 1e-4
    stop_power = got["F_stop"] * got["V_ch"]
    scale = np.max(np.abs(got["P_motor"]))
    assert np.max(np.abs(got["energy_residual"] - stop_power)) < 1e-9 * scale
    assert np.max(np.abs(stop_power)) > 1e-2 * scale  # the impact shows
    assert end["C_m_gap"] == pytest.approx(-0.004 * end["F_stop"], rel=1e-3)  # the stop's share
    back = _sim(speed_rpm=-3000.0, **SPEED)  # the servo pushes hard into the first stop
    back.advance(2.0)
    assert np.isfinite(back.data.qvel).all()
    assert RAIL[0] - 5e-3 < back.readouts(["y_ch"])["y_ch"] < RAIL[0]


def test_rigid_and_flexible_arms_share_the_steady_speed_not_the_transient():
    """Same torque: the flexible arm starts faster (the motor sees 2.7208e-3 instead of
    3.4568e-3 kg·m²) and rings; both end at ω_m = C_m / f_v; the rigid arm never deflects."""
    runs = {}
    for flex in (0.0, 1.0):
        sim = _sim(flexible=flex, torque_Nm=2.0, **TORQUE)
        runs[flex] = _run(sim, 1.5, ("omega_m", "deflection", "J_eq"))
    assert runs[1.0]["omega_m"][5] > 1.2 * runs[0.0]["omega_m"][5]  # 3.4568 / 2.7208 = 1.27
    assert np.all(runs[0.0]["deflection"] == 0.0)
    y = runs[1.0]["deflection"]
    crossings = np.count_nonzero(np.diff(np.sign(y[:600])) != 0)  # 0.6 s: 5.6 periods
    assert 9 <= crossings <= 13
    assert runs[0.0]["J_eq"][0] == pytest.approx(3.4568e-3, rel=REL)
    assert runs[1.0]["J_eq"][0] == pytest.approx(2.7208e-3, rel=REL)
    for run in runs.values():
        assert run["omega_m"][-1] == pytest.approx(2.0 / 0.0171, rel=2e-2)


def test_reducer_loss_is_the_efficiency_share_of_the_power_entering_it():
    """6.4 while the motor drives: P_loss = (1 − ρ) P_e with P_e = C_m ω_m − (J_m + J_r) ω_m
    ω̇_m − f_v ω_m², and the loss slows the start (the reducer passes on ρ of its torque)."""
    lossy, ideal = _sim(eta=0.9, **TORQUE), _sim(**TORQUE)
    lossy.advance(0.1)
    ideal.advance(0.1)
    got = lossy.readouts(["P_loss", "P_motor", "omega_m", "E_c", "P_diss"])
    r = 0.004
    omega_dot = float(lossy.data.qacc[0]) / r
    p_e = got["P_motor"] - (5.4e-4 * omega_dot + 0.0171 * got["omega_m"]) * got["omega_m"]
    assert got["P_loss"] == pytest.approx(0.1 * p_e, rel=1e-9)
    assert got["P_loss"] > 0
    assert got["omega_m"] < ideal.readouts(["omega_m"])["omega_m"]


def test_braking_through_a_lossy_reducer_shows_the_gap_to_the_course():
    """The simulated reducer keeps its driving-mode loss; when the load drives the motor back
    (a lower set point) the course's ρ multiplies instead of dividing: C_m_gap says so,
    while it stays at round-off as long as the motor drives."""
    sim = _sim(eta=0.8, speed_rpm=1000.0, ramp_s=0.05, **SPEED)
    driving = _run(sim, 0.1, ("C_m_gap", "C_m"))
    assert np.max(np.abs(driving["C_m_gap"])) < 1e-9
    sim.advance(0.4)
    sim.set_value("speed_rpm", 0.0)
    braking = _run(sim, 0.2, ("C_m_gap", "C_m", "P_loss"))
    assert np.max(np.abs(braking["C_m_gap"])) > 0.05 * np.max(np.abs(braking["C_m"]))
    assert np.min(braking["P_loss"]) < 0  # the driving-mode loss turns into a gain


def test_default_timestep_follows_the_fastest_mode():
    """1 ms at the course's numbers (fastest mode 58.5 rad/s: 0.06 rad per step); a stiff
    light arm or a strong damper shrinks the step so that the run stays stable."""
    assert default_timestep(DEFAULTS) == 1e-3
    stiff = {**DEFAULTS, "K_t": 1e7, "M2": 0.5}
    dt = default_timestep(stiff)
    assert dt * math.sqrt(1e7 * (1 / 0.5 + 0.004**2 / 2.7208e-3)) <= 0.3
    sim = _sim(K_t=1e7, M2=0.5, mu_t=5000.0, torque_Nm=20.0, **TORQUE)
    sim.advance(0.5)
    assert np.isfinite(sim.data.qvel).all()


def test_arrows_are_the_carriage_forces():
    """The belt's and the arm's forces on the carriage add up to M1 a_ch (the carriage's PFD)."""
    sim = _sim(torque_Nm=2.0, **TORQUE)
    sim.advance(0.03)
    snap = sim.snapshot()
    arrows = {a.name: a.fn(snap) for a in SCENE.page.arrows}
    belt, arm = arrows["F_belt"][1][1], arrows["F_arm"][1][1]
    assert belt + arm == pytest.approx(136.0 * float(sim.data.qacc[0]), rel=1e-9)
    got = sim.readouts(["F_belt", "F_arm"])
    assert (got["F_belt"], got["F_arm"]) == pytest.approx((belt, arm), rel=1e-12)


def test_mass_of_the_chain_seen_from_the_belt():
    """J_eq / (R_p k)² = 170.05 kg: the motor's 5.4e-4 kg·m² weighs 33.75 kg on the belt."""
    assert chain_mass(COURSE) == pytest.approx(2.7208e-3 / 0.004**2, rel=1e-12)
    lossy = dataclasses.replace(COURSE)
    assert chain_mass(lossy, rho=0.5) == pytest.approx(170.05 - 0.5 * 33.75, rel=1e-12)
    assert equivalent_inertia(COURSE) / COURSE.ratio**2 == pytest.approx(170.05, rel=1e-12)


def test_a_lossy_reducer_makes_the_motor_feel_more_than_the_course_j_eq():
    """ρ = 0.8 in driving mode: C_m − (J_m + J_r) ω̇ = C_s / ρ, so the motor's first
    acceleration is C_m / (5.4e-4 + 2.1808e-3 / 0.8) = C_m / 3.266e-3; the J_eq readout
    (read from the compiled model) says so, the course's J_eq (no ρ in 6.3) stays 2.7208e-3."""
    sim = _sim(eta=0.8, torque_Nm=2.0, **TORQUE)
    omega_dot = float(sim.data.qacc[0]) / 0.004
    felt = 5.4e-4 + (2.7208e-3 - 5.4e-4) / 0.8
    got = sim.readouts(["J_eq", "C_m"])
    assert got["C_m"] / omega_dot == pytest.approx(felt, rel=1e-9)
    assert got["J_eq"] == pytest.approx(felt, rel=1e-9)
    assert SCENE.reference is not None
    assert SCENE.reference(sim.values)["J_eq"] == pytest.approx(2.7208e-3, rel=1e-9)


def test_a_recording_of_the_time_varying_commands_replays_bit_for_bit(tmp_path):
    """The per-step control is a pure function of the time and the state: a recording with
    live changes of the move, a switch to the sinusoidal torque and a reset re-simulates
    with a deviation of exactly 0."""
    from sandbox.recording import Recorder, load
    from sandbox.replay import resimulate

    sim = _sim()
    path = tmp_path / "robot.sbx"
    rec = Recorder(path, sim)
    changes = {
        10: lambda: sim.set_value("stroke", 0.4),
        20: lambda: sim.set_value("accel_s", 0.2),
        30: lambda: sim.set_value("profile", 3),
        40: lambda: sim.set_value("sine_Hz", 9.3),
        50: sim.reset,
    }
    for k in range(70):
        sim.step(37)
        rec.frame(sim.readouts())
        if k in changes:
            changes[k]()
    rec.close()
    worst, frames = resimulate(load(path))
    assert frames == 70 and worst == 0.0


def _closed_form_powers(v: dict[str, float], t: float) -> dict[str, float]:
    """T, P_ext, P_int and dT/dt of the mechanism (course 6.3 with 6.4's reducer, driving
    mode) from the two-mass closed form of a torque step at time ``t``, derivatives by
    central differences of the exact solution."""
    axis, rho, c = axis_of(v), v["eta"], v["torque_Nm"]
    h = 1e-6
    s = step_response(axis, [t - h, t, t + h], c, flexible=True, rho=rho)
    w, w_dot = s["omega_m"][1], (s["omega_m"][2] - s["omega_m"][0]) / (2 * h)
    y = s["y"][1]
    arm_v = (s["V_2"] - s["V_ch"])[1]
    j_eq = equivalent_inertia(axis, flexible=True)
    kinetic = 0.5 * j_eq * s["omega_m"] ** 2 + 0.5 * v["M2"] * s["V_2"] ** 2
    loss = (1 - rho) * (c - (v["J_m"] + v["J_r"]) * w_dot - v["f_v"] * w) * w
    return {
        "T": float(kinetic[1]),
        "P_ext": c * w,
        "P_int": -v["f_v"] * w**2 - v["mu_t"] * arm_v**2 - v["K_t"] * y * arm_v - loss,
        "dT/dt": float((kinetic[2] - kinetic[0]) / (2 * h)),
        "P_loss": loss,
    }


@pytest.mark.parametrize("eta", [1.0, 0.8, 0.5])
def test_generic_energies_are_the_mechanisms_for_any_efficiency(eta):
    """Issue 21: with a lossy reducer the simulated chain carries ρ (J_m + J_r), ρ f_v and
    ρ C_m; the page's T, P_ext, P_int are nevertheless the mechanism's: T = ½ J_eq ω_m² +
    ½ M2 V_2² whatever ρ (J_eq the course's), P_ext = C_m ω_m, P_int with the reducer's
    loss, against the two-mass closed form at 0.1, 0.3 and 0.5 s; the theorem closes to
    1e-3 W with them (and dT/dt − P_ext − P_int, the frame's power, is 0)."""
    values = {"torque_Nm": 2.0, "eta": eta, **TORQUE}
    sim = _sim(**values)
    v = {**DEFAULTS, **values}
    for t in (0.1, 0.3, 0.5):
        sim.advance(t - sim.data.time)
        got = sim.readouts(["T", "P_ext", "P_int", "P_acc", "E_c", "P_loss", "C_m"])
        ref = _closed_form_powers(v, t)
        scale = abs(ref["P_ext"])
        assert got["T"] == pytest.approx(ref["T"], rel=1e-6)
        assert got["T"] == pytest.approx(got["E_c"], rel=1e-12)
        assert got["P_ext"] == pytest.approx(got["C_m"] * ref["P_ext"] / 2.0, rel=1e-6)
        assert got["P_ext"] == pytest.approx(ref["P_ext"], rel=1e-6)
        assert got["P_int"] == pytest.approx(ref["P_int"], abs=1e-6 * scale)
        assert got["P_loss"] == pytest.approx(ref["P_loss"], abs=1e-6 * scale)
        assert abs(ref["dT/dt"] - got["P_ext"] - got["P_int"]) < 1e-3  # [W]
        assert abs(got["P_acc"] - got["P_ext"] - got["P_int"]) < 1e-9 * scale
    if eta < 1:  # the loss is real power: P_int holds it beyond the friction and the arm
        got = sim.readouts(["P_int", "P_diss", "P_loss"])
        assert got["P_loss"] > 0
        assert got["P_int"] == pytest.approx(-got["P_diss"] - got["P_loss"], rel=1e-9)


def test_every_row_is_one_instant_the_motor_power_is_its_torque_times_its_speed():
    """Issue 36: a row holds one instant. C_m is the torque applied from it on (what
    MuJoCo applies in the step starting there): it read the previous step's, so that
    P_motor = P_ext differed from C_m ω_m by 5 % of the peak with the 9 Hz sine (C_m
    0,7246 N·m at 0,05 s where the torque applied is 2 sin(2π·9·0,05) = 0,618) and the
    servo's C_m by 8 % from the torque its step's motion takes. Now C_m ω_m is P_motor
    and P_ext on every row (sine, speed servo, back-and-forth, lossy reducer), and the
    course's C_m_ref from the same instant's motion matches it to round-off while the
    motor drives; a servo's torque held over a step depends on the timestep (default
    move's peak 4.98 N·m at 1 ms, 4.80 at 0.1 ms)."""
    cases = {
        "sine": {"profile": 3.0, "sine_Nm": 2.0, "sine_Hz": 9.0},
        "sine, ρ = 0,8": {"profile": 3.0, "sine_Nm": 2.0, "sine_Hz": 9.0, "eta": 0.8},
        "servo": {"profile": 1.0, "ramp_s": 0.0},
        "move": {},
    }
    for case, values in cases.items():
        sim = _sim(**values)
        got = _run(sim, 0.2, ("C_m", "omega_m", "P_motor", "P_ext", "C_m_gap"))
        power = got["C_m"] * got["omega_m"]
        peak = np.max(np.abs(got["P_ext"]))
        assert np.max(np.abs(got["P_motor"] - power)) <= 1e-12 * peak, case
        assert np.max(np.abs(got["P_ext"] - power)) <= 1e-12 * peak, case
        if values.get("eta", 1.0) == 1.0:
            assert np.max(np.abs(got["C_m_gap"])) < 1e-9 * np.max(np.abs(got["C_m"])), case
    sim = _sim(**cases["sine"])
    sim.advance(0.05)
    applied = 2.0 * math.sin(2 * math.pi * 9.0 * sim.data.time)
    assert sim.readouts(["C_m"])["C_m"] == pytest.approx(applied, rel=1e-12)
    peaks = {}
    for dt in (1e-3, 1e-4):
        peaks[dt] = float(
            np.max(_run(Simulation(get_scene("robot_axis"), timestep=dt), 0.3, ("C_m",))["C_m"])
        )
    assert peaks[1e-3] == pytest.approx(4.98, rel=1e-2) and peaks[1e-4] == pytest.approx(
        4.80, rel=1e-2
    )
