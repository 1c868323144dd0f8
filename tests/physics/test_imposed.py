"""Inverse dynamics of an imposed motion (sandbox.physics.imposed), on small inline MJCF:
a pendulum driven by its motor against weight, and a slider-crank whose loop force comes
from the solve, not from MuJoCo's soft constraint."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from sandbox.physics import isolate
from sandbox.physics.energy import acceleration_power, powers
from sandbox.physics.imposed import inverse_dynamics
from sandbox.physics.torsors import support_torsor

M, L, G = 2.0, 0.5, 9.81
PENDULUM = f"""
<mujoco>
  <option gravity="0 0 -{G}"/>
  <worldbody>
    <body name="arm">
      <joint name="pivot" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 -{L}" mass="{M}" diaginertia="0.01 0.01 0.01"/>
    </body>
  </worldbody>
  <actuator><motor name="motor" joint="pivot"/></actuator>
</mujoco>
"""


def _state(model, data, q, dq, ddq):
    data.qpos[:] = q
    data.qvel[:] = dq
    data.qacc_warmstart[:] = ddq


@pytest.mark.parametrize(
    ("theta", "omega", "alpha"), [(0.3, 2.0, 5.0), (2.5, -7.0, 0.0), (0, 0, 1)]
)
def test_a_pendulum_s_motor_torque_and_pivot_force_are_the_course_s(theta, omega, alpha):
    """θ about y0, G at l below O: C = I_O θ'' + m g l sin θ (I_O = I_G + m l²) and the
    pivot's force R = m Γ(G) − m g (PFD on the arm), to 1e-12."""
    model = mujoco.MjModel.from_xml_string(PENDULUM)
    data = mujoco.MjData(model)
    _state(model, data, [theta], [omega], [alpha])
    residual = inverse_dynamics(model, data, np.array([0]))
    assert residual < 1e-12
    i_o = 0.01 + M * L * L
    torque = i_o * alpha + M * G * L * math.sin(theta)
    assert data.actuator_force[0] == pytest.approx(torque, abs=1e-12 * (1 + abs(torque)))
    # G = (-l sin θ, 0, -l cos θ) for a rotation θ about y0 of (0, 0, -l)
    g_pos = np.array([-L * math.sin(theta), 0.0, -L * math.cos(theta)])
    e_t = np.array([-L * math.cos(theta), 0.0, L * math.sin(theta)])  # dG/dθ
    accel = alpha * e_t - omega**2 * g_pos
    expected = M * accel - M * np.array([0.0, 0.0, -G])
    r, _ = support_torsor(model, data)
    np.testing.assert_allclose(r, expected, atol=1e-10)
    assert data.qacc[0] == alpha


SLIDER_CRANK = """
<mujoco>
  <option gravity="0 0 0"/>
  <worldbody>
    <body name="crank">
      <joint name="crank" type="hinge" axis="0 0 1"/>
      <inertial pos="0.01 0 0" mass="0.3" diaginertia="1e-4 1e-4 2e-4"/>
      <site name="A_crank" pos="0.02 0 0"/>
    </body>
    <body name="piston">
      <joint name="piston" type="slide" axis="0 1 0"/>
      <inertial pos="0 0 0" mass="0.1" diaginertia="1e-5 1e-5 1e-5"/>
      <body name="rod">
        <joint name="rod" type="hinge" axis="0 0 1"/>
        <inertial pos="0 -0.04 0" mass="0.05" diaginertia="3e-5 1e-6 3e-5"/>
        <site name="A_rod" pos="0 -0.07 0"/>
      </body>
    </body>
  </worldbody>
  <equality><connect site1="A_rod" site2="A_crank"/></equality>
  <actuator><motor name="motor" joint="crank"/></actuator>
</mujoco>
"""
R_, L_ = 0.02, 0.07


def _slider_crank(theta: float, omega: float, alpha: float):
    """The loop closed at θ: λ = R sin θ + √(L² − R² cos² θ), sin φ = R cos θ / L, with
    their first and second derivatives by central differences of the closed form (the
    test's own, independent of the scenes)."""

    def q(t: float) -> tuple[float, float]:
        lam = R_ * math.sin(t) + math.sqrt(L_**2 - (R_ * math.cos(t)) ** 2)
        return lam, math.asin(R_ * math.cos(t) / L_)

    h = 1e-4
    q0, qp, qm = np.array(q(theta)), np.array(q(theta + h)), np.array(q(theta - h))
    d1 = (qp - qm) / (2 * h)
    d2 = (qp - 2 * q0 + qm) / h**2
    return (
        [theta, *q0],
        [omega, *(d1 * omega)],
        [alpha, *(d2 * omega**2 + d1 * alpha)],
    )


def test_a_slider_crank_s_loop_force_comes_from_the_solve_and_every_solid_balances():
    """MuJoCo's soft constraint gives no force on exact kinematics; the solve's λ closes
    the PFD of every solid (isolate's residual), and P_acc = P_ext with P_int = 0."""
    model = mujoco.MjModel.from_xml_string(SLIDER_CRANK)
    data = mujoco.MjData(model)
    q, dq, ddq = _slider_crank(0.7, 150.0, 0.0)
    _state(model, data, q, dq, ddq)
    residual = inverse_dynamics(model, data, np.array([0]))
    assert residual < 1e-9  # the test's own kinematics hold to ~1e-8 (finite differences)
    loop = data.efc_force[: data.nefc]
    assert np.abs(loop).max() > 1.0  # a real force in the loop
    for solid in isolate.solids(model):
        dyn = isolate.dynamic_torsor(model, data, solid)
        acts = isolate.actions(model, data, solid)
        assert isolate.pfd_residual(dyn, acts, 0.1) < 1e-6, solid
    p = powers(model, data)
    p_acc = acceleration_power(model, data)
    assert p["P_int"] == pytest.approx(0.0, abs=1e-6 * abs(p_acc))
    assert p_acc == pytest.approx(p["P_ext"], rel=1e-7)


def test_a_joint_nobody_drives_shows_in_the_residual():
    """A motion the motor and the loops cannot impose (the rod free to swing, no loop)
    leaves a residual: the solve says so rather than inventing a force."""
    xml = SLIDER_CRANK.replace('<equality><connect site1="A_rod" site2="A_crank"/></equality>', "")
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    q, dq, ddq = _slider_crank(0.7, 150.0, 0.0)
    _state(model, data, q, dq, ddq)
    assert inverse_dynamics(model, data, np.array([0])) > 1e-3
