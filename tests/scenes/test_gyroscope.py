"""Gyrometer (course 1): the spinning rotor keeps its axis; hard cases of issue #5."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from sandbox.errors import Diverged
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.scenes.gyroscope import LOCK_DEG, pivot_moment

N = ("spin", "gimbal_outer", "gimbal_inner", "axis_drift", "gimbal_lock", "sigma_G_x",
     "sigma_G_y", "sigma_G_z", "pivot_moment_inner", "pivot_moment_outer")  # fmt: skip
C = 4e-4  # rotor's inertia about its axis in gyroscope.xml [kg·m²]
TILTED = {"case_yaw_deg": 30.0, "case_pitch_deg": 20.0, "case_roll_deg": 10.0}


def _sigma(r):
    return math.sqrt(r["sigma_G_x"] ** 2 + r["sigma_G_y"] ** 2 + r["sigma_G_z"] ** 2)


def _still_case(integrator: str | None = None, timestep: float | None = None) -> Simulation:
    """30,000 rpm, the case held at a tilted attitude, the gimbals nudged by 0.01 rad/s.

    Level and unperturbed, every term that couples the spin to the gimbals is exactly 0
    and any integrator would pass; the tilt and the nudge excite the nutation.
    """
    sim = Simulation(
        get_scene("gyroscope"),
        values={"spin_rpm": 30000.0, "manoeuvre": 0.0, **TILTED},
        integrator=integrator,
        timestep=timestep,
    )
    sim.data.qvel[3:5] = 0.01
    return sim


def _warnings(sim: Simulation) -> int:
    return sum(int(w.number) for w in sim.data.warning)


def test_30000_rpm_for_10_seconds_with_the_case_still():
    sim = _still_case()
    r0 = sim.readouts(N)
    assert _sigma(r0) == pytest.approx(C * 30000 * 2 * math.pi / 60, rel=1e-4)  # ≈ C r
    sim.advance(10.0)
    r = sim.readouts(N)
    assert r["axis_drift"] < 1e-3
    assert _sigma(r) == pytest.approx(_sigma(r0), rel=1e-6)
    assert r["spin"] == pytest.approx(r0["spin"], rel=1e-4)
    assert _warnings(sim) == 0


@pytest.mark.parametrize("integrator", ["euler", "implicitfast"])
def test_first_order_integrators_throw_the_axis_away_where_rk4_holds_it(integrator):
    """The reason for the default: the same hard case, 2 s, all at 0.5 ms."""
    sim = _still_case(integrator=integrator, timestep=5e-4)
    s0 = _sigma(sim.readouts(N))
    try:
        sim.advance(2.0)
    except Diverged:
        pass  # blowing up is also losing the axis
    else:
        r = sim.readouts(N)
        assert abs(_sigma(r) / s0 - 1) > 1e-2 and r["axis_drift"] > 0.1
    rk4 = _still_case(integrator="rk4", timestep=5e-4)
    rk4.advance(2.0)
    assert abs(_sigma(rk4.readouts(N)) / s0 - 1) < 1e-6


def _reading(case_rot: np.ndarray, axis: np.ndarray) -> tuple[float, float]:
    """Gimbal angles (outer about the case's z, inner about x) that point y at ``axis``.

    In the case's frame R_z(ψ) R_x(φ) y = (−sin ψ cos φ, cos ψ cos φ, sin φ).
    """
    a = case_rot.T @ axis
    return math.atan2(-a[0], a[1]), math.asin(a[2])


def test_spinning_the_axis_holds_and_the_gimbals_read_the_case():
    """Turn the case to (40°, 25°, -15°): the axis stays, the gimbals give the attitude."""
    sim = Simulation(get_scene("gyroscope"), values={"spin_rpm": 12000.0, "manoeuvre": 0.0})
    for name, deg in (("case_yaw_deg", 40.0), ("case_pitch_deg", 25.0), ("case_roll_deg", -15.0)):
        sim.set_value(name, deg)
    sim.advance(1.5)
    r = sim.readouts(N)
    assert r["axis_drift"] < 1e-2
    case = sim.data.xmat[sim.model.body("case").id].reshape(3, 3)
    psi, phi = _reading(case, np.array([0.0, 1.0, 0.0]))  # the axis at reset
    assert r["gimbal_outer"] == pytest.approx(psi, abs=1e-2)
    assert r["gimbal_inner"] == pytest.approx(phi, abs=1e-2)
    assert r["gimbal_outer"] == pytest.approx(-math.radians(40.0), abs=0.05)


def test_at_spin_zero_the_rotor_follows_the_case():
    """Pivot friction drags a still rotor along; with perfect pivots nothing does."""
    sim = Simulation(get_scene("gyroscope"), values={"spin_rpm": 0.0, "manoeuvre": 0.0})
    sim.set_value("case_yaw_deg", 40.0)
    sim.advance(3.0)
    r = sim.readouts(N)
    assert r["axis_drift"] > 0.5 * math.radians(40.0)
    assert r["spin"] == 0.0 and math.isfinite(r["pivot_moment_outer"])
    perfect = Simulation(
        get_scene("gyroscope"), values={"spin_rpm": 0.0, "pivot_damping": 0.0, "manoeuvre": 0.0}
    )
    perfect.set_value("case_yaw_deg", 40.0)
    perfect.advance(3.0)
    assert perfect.readouts(N)["axis_drift"] < 1e-6


def test_spinning_rotor_resists_the_pivot_friction():
    """The same yaw at 12,000 rpm: the drift is 1/100 of the still rotor's."""
    still, fast = (
        Simulation(get_scene("gyroscope"), values={"spin_rpm": rpm, "manoeuvre": 0.0})
        for rpm in (0.0, 12000.0)
    )
    for sim in (still, fast):
        sim.set_value("case_yaw_deg", 40.0)
        sim.advance(3.0)
    assert fast.readouts(N)["axis_drift"] < 1e-2 * still.readouts(N)["axis_drift"]


def test_the_page_opens_on_a_manoeuvre_the_axis_holds_through():
    """At the defaults the case turns by itself within seconds (manoeuvre 2): the gimbal
    angles change while the rotor's axis keeps its direction."""
    sim = Simulation(get_scene("gyroscope"))
    assert sim.values["manoeuvre"] == 2.0
    sim.advance(3.0)
    r = sim.readouts(N)
    assert abs(r["gimbal_outer"]) > math.radians(30.0)  # the case has visibly turned
    assert r["axis_drift"] < 1e-2


@pytest.mark.parametrize("spin", [12000.0, 30000.0])
def test_gimbal_lock_is_traversed_without_warning_and_flagged(spin):
    """Manoeuvre 1 rolls the case through 90°: the rotor's axis meets the outer pivot."""
    sim = Simulation(get_scene("gyroscope"), values={"spin_rpm": spin, "manoeuvre": 0.0})
    sim.set_value("manoeuvre", 1.0)
    outer = sim.model.joint("outer").id
    rows = []
    for _ in range(300):
        sim.advance(0.02)  # Diverged would be raised on a bad-state warning or NaN
        r = sim.readouts(N)
        assert all(math.isfinite(v) for v in r.values())
        axis = sim.data.xmat[sim.model.body("rotor").id].reshape(3, 3)[:, 1]
        rows.append((abs(axis @ sim.data.xaxis[outer]), r["gimbal_lock"]))
    alignment, flags = np.array(rows).T
    closest = int(np.argmax(alignment))
    assert alignment[closest] > math.cos(math.radians(LOCK_DEG))  # lock is reached
    assert flags[closest] == 1.0  # and flagged at that moment
    assert np.array_equal(flags == 1.0, alignment > math.cos(math.radians(LOCK_DEG)))
    assert flags[-1] == 0.0 and _warnings(sim) == 0
    assert r["spin"] == pytest.approx(spin * 2 * math.pi / 60, rel=1e-4)


def _sigma_o(model: mujoco.MjModel, data: mujoco.MjData, root: str) -> np.ndarray:
    """Angular momentum at O of ``root`` and the bodies it carries, in R0: Σ I_G ω.

    Every centre of mass of the gimbals and the rotor is at O (no m OG ∧ V(G) term).
    """
    out = np.zeros(3)
    for b in _carried(model, root):
        assert np.linalg.norm(data.xipos[b]) < 1e-12
        rot = data.ximat[b].reshape(3, 3)
        out += rot @ np.diag(model.body_inertia[b]) @ rot.T @ data.cvel[b, :3]
    return out


def _carried(model: mujoco.MjModel, root: str) -> list[int]:
    ids = [model.body(root).id]
    for b in range(ids[0] + 1, model.nbody):  # children come after their parent
        if model.body_parentid[b] in ids:
            ids.append(b)
    return ids


@pytest.mark.parametrize("gimbal", ["inner", "outer"])
def test_pivot_moment_is_the_rate_of_the_carried_angular_momentum(gimbal):
    """Moment relation at O (2.2.2) on what the pivot carries: M_O = dσ_O/dt across the axis.

    The readout comes from MuJoCo's cfrc_int; the reference differentiates σ_O by finite
    differences (fine timestep). Manoeuvre 1 at 30,000 rpm near gimbal lock, where the case
    drags the rotor's axis and the pivots transmit up to ~0.9 N·m.
    """
    dt = 5e-5
    sim = Simulation(
        get_scene("gyroscope"), values={"spin_rpm": 30000.0, "manoeuvre": 1.0}, timestep=dt
    )
    m, d = sim.model, sim.data
    axis_id = m.joint(gimbal).id
    sim.advance(1.2)
    peak, worst = 0.0, 0.0
    for _ in range(8):
        sim.advance(0.05)
        sigmas = []
        for k in range(3):
            sim.readouts(["pivot_moment_inner"])  # brings the state's quantities up to date
            sigmas.append(_sigma_o(m, d, gimbal))
            if k == 1:
                got = pivot_moment(m, d, gimbal)
                axis = d.xaxis[axis_id].copy()
            sim.step(1)
        rate = (sigmas[2] - sigmas[0]) / (2 * dt)
        want = rate - (rate @ axis) * axis
        peak = max(peak, float(np.linalg.norm(want)))
        worst = max(worst, float(np.linalg.norm(got - want)))
    assert peak > 0.3  # the case forces the rotor's axis to turn
    assert worst < 1e-5 * peak


def test_gimbals_absorb_a_turn_of_the_case_away_from_lock():
    """Manoeuvre 2 (no lock): the pivots transmit only their friction's effect, < 1e-2 N·m,
    against ~0.9 N·m when the case drags the axis at lock."""
    sim = Simulation(get_scene("gyroscope"), values={"spin_rpm": 30000.0, "manoeuvre": 2.0})
    peak = 0.0
    for _ in range(40):
        sim.advance(0.05)
        r = sim.readouts(N)
        peak = max(peak, r["pivot_moment_inner"], r["pivot_moment_outer"])
        assert r["gimbal_lock"] == 0.0
    assert 1e-4 < peak < 1e-2
    assert r["axis_drift"] < 5e-3


def test_a_new_spin_relaunches_the_rotor_and_keeps_the_reference_axis():
    sim = Simulation(get_scene("gyroscope"), values={"manoeuvre": 0.0})
    sim.set_value("case_yaw_deg", 30.0)
    sim.advance(0.5)
    before = sim.readouts(N)
    sim.set_value("spin_rpm", 30000.0)
    after = sim.readouts(N)
    assert after["spin"] == pytest.approx(30000 * 2 * math.pi / 60)
    assert after["axis_drift"] == pytest.approx(before["axis_drift"], abs=1e-12)
    sim.set_value("case_pitch_deg", 10.0)  # another slider leaves the free spin alone
    sim.advance(0.5)
    assert sim.readouts(N)["spin"] == pytest.approx(after["spin"], rel=1e-4)
    sim.reset()
    assert sim.readouts(N)["spin"] == pytest.approx(30000 * 2 * math.pi / 60)
