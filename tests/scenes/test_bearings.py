"""The scenes' plain bearings (issue 39, course appendix B.2): the pressure and friction
readouts from the live radial load against the closed forms, the speed at which the
unbalanced rotor passes 200 bar in bearing A, and the bearing parameters' guards."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.errors import SandboxError
from sandbox.mechanics.bearing import LIMIT_PA
from sandbox.physics.bearings import radial
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene


def _rotor(**values: float) -> Simulation:
    sim = Simulation(get_scene("rotor"), values=values)
    sim.advance(0.05)
    return sim


@pytest.mark.parametrize("model", [0.0, 1.0, 2.0])
def test_the_rotors_pressures_follow_the_bearing_forces(model):
    """p₀ = F/(2RL); the cosine's peak (4/π) p₀; C_f = (π/2) f R F under hypothesis 3
    only; to round-off, from the simulated bearing forces and from the course's."""
    sim = _rotor(bearing_model=model, bearing_R=12.0, bearing_L=20.0, bearing_f=0.15)
    r = sim.readouts()
    ref = sim.reference()
    for name in ("A", "B"):
        force = r[f"bearing_{name}"]
        p0 = force / (2 * 0.012 * 0.02)
        expected = p0 * (4 / math.pi if model == 1.0 else 1.0)
        assert r[f"bearing_{name}_pmax"] == pytest.approx(expected, rel=1e-12)
        torque = math.pi / 2 * 0.15 * 0.012 * force if model == 2.0 else 0.0
        assert r[f"bearing_{name}_Cf"] == pytest.approx(torque, rel=1e-12, abs=1e-15)
        assert r[f"bearing_{name}_pmax"] == pytest.approx(ref[f"bearing_{name}_pmax"], rel=1e-9)
        assert r[f"bearing_{name}_Cf"] == pytest.approx(ref[f"bearing_{name}_Cf"], rel=1e-9)


def test_the_unbalanced_rotor_passes_200_bar_in_bearing_a_near_5519_rpm():
    """The lesson's question: 200 g of defect, pressure in cosine, R = L = 10 mm. The load
    grows as ω², so p_max = 200 bar at ω* = ω √(200 bar / p_max(ω)): 5519 rpm."""
    base = {"defect_mass_g": 200.0, "bearing_model": 1.0}
    at_6000 = _rotor(speed_rpm=6000.0, **base).readouts()["bearing_A_pmax"]
    crossing = 6000.0 * math.sqrt(LIMIT_PA / at_6000)
    assert crossing == pytest.approx(5519.0, abs=1.0)
    assert _rotor(speed_rpm=5500.0, **base).readouts()["bearing_A_pmax"] < LIMIT_PA
    assert _rotor(speed_rpm=5550.0, **base).readouts()["bearing_A_pmax"] > LIMIT_PA
    assert _rotor(speed_rpm=6000.0, defect_mass_g=200.0).readouts()["bearing_A_pmax"] < LIMIT_PA


def test_a_balanced_rotor_loads_no_bearing():
    """The course's balancing solution: no rotating force, so no pressure and no torque."""
    scene = get_scene("rotor")
    sim = Simulation(scene)
    assert scene.solutions is not None
    solution = scene.solutions["balancing_solution"](sim.values)
    sim = _rotor(**solution, bearing_model=2.0)
    r = sim.readouts()
    assert r["bearing_A_pmax"] <= sim.scene.zero["Pa"]  # type: ignore[union-attr]
    assert abs(r["bearing_A_Cf"]) < 1e-9


def test_only_the_radial_part_loads_a_plain_bearing():
    axis = np.array([1.0, 0.0, 0.0])
    assert radial(np.array([5.0, 3.0, -4.0]), axis) == pytest.approx([0.0, 3.0, -4.0])


@pytest.mark.parametrize(
    "name, value", [("bearing_R", 0.0), ("bearing_L", -1.0), ("bearing_f", 3.0)]
)
def test_bearing_parameters_out_of_range_are_refused(name, value):
    with pytest.raises(SandboxError, match=name):
        Simulation(get_scene("rotor"), values={name: value})


# -- « Paliers avec frottement »: the friction torque in the simulation itself ----------------
FRICTION = {"bearing_friction": 1.0, "bearing_model": 2.0, "bearing_f": 0.1}


@pytest.mark.parametrize(
    "scene, values",
    [
        ("rotor", {}),
        ("rotor", {"defect_mass_g": 200.0, "speed_rpm": 6000.0}),
        ("rotor", {"bearing_model": 1.0}),  # the cosine's (4/π) f R F
        ("wheel_balancer", {"speed_rpm": 1000.0}),
    ],
)
def test_bearing_friction_costs_cf_omega_and_the_energy_theorem_still_closes(scene, values):
    """P_int = −(C_fA + C_fB) ω; the motor gives ΣC_f on top (it holds ω: T stays
    constant); P_acc = P_ext + P_int to round-off."""
    sim = Simulation(get_scene(scene), values={**FRICTION, **values}, motion="free")
    sim.advance(1.0)
    r = sim.readouts()
    torque = r["bearing_A_Cf"] + r["bearing_B_Cf"]
    assert torque > 0
    w = r["omega"]
    assert w == pytest.approx(sim.values["speed_rpm"] * math.pi / 30, rel=1e-9)
    assert r["P_int"] == pytest.approx(-torque * w, rel=1e-9)
    assert r["P_ext"] == pytest.approx(torque * w, rel=1e-6)
    assert abs(r["P_acc"] - r["P_ext"] - r["P_int"]) < 1e-9 * r["P_ext"]
    factor = 4 / math.pi if sim.values["bearing_model"] == 1.0 else math.pi / 2
    radius = sim.values["bearing_R"] * 1e-3
    forces = (
        (r["bearing_A"], r["bearing_B"])
        if scene == "rotor"
        else (r["bearing_inner"], r["bearing_outer"])
    )
    assert torque == pytest.approx(factor * 0.1 * radius * sum(forces), rel=1e-9)


def test_perfect_bearings_switch_mujocos_friction_off():
    """Off by default: the course's perfect joints, MuJoCo's dry friction not computed."""
    import mujoco

    sim = Simulation(get_scene("rotor"))
    assert sim.model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS
    sim.advance(0.5)
    assert sim.readouts(["P_int"])["P_int"] == 0.0
    assert not sim.model.dof_frictionloss.any()
    on = Simulation(get_scene("rotor"), values=FRICTION)
    assert not on.model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS
    scene = get_scene("rotor")
    lines = scene.effects_at(on.values).hypotheses()
    assert "Frottement sec dans les paliers : couple Cf selon leur charge" in lines
    assert "Liaisons parfaites" not in lines
    assert "Liaisons parfaites" in scene.effects_at(sim.values).hypotheses()


@pytest.mark.parametrize(
    "scene, torques",
    [
        ("rotor", ("bearing_A_Cf", "bearing_B_Cf")),
        ("wheel_balancer", ("bearing_A_Cf", "bearing_B_Cf")),
        ("compressor", ("bearing_O_Cf",)),
        ("engine", ("bearing_A_Cf", "bearing_B_Cf")),
    ],
)
def test_imposed_and_free_motions_carry_the_same_friction(scene, torques):
    """Imposed (inverse dynamics, the friction on top) or simulated (MuJoCo's dry friction
    set before each step): the same torque ΣC_f from the loads, the motor giving it on top
    of the perfect joints' torque, P_int = −ΣC_f ω, and the energy theorem to round-off
    (free: within the loops' own closure power, 1e-3 of the motor's)."""
    out = {}
    for motion in ("imposed", "free"):
        perfect = Simulation(get_scene(scene), values={"bearing_model": 2.0}, motion=motion)
        sim = Simulation(get_scene(scene), values=FRICTION, motion=motion)
        for s in (perfect, sim):
            s.advance(0.2)
        r, r0 = sim.readouts(), perfect.readouts()
        torque = sum(r[n] for n in torques)
        w = float(sim.data.qvel[0])
        extra = float(sim.data.actuator_force[0] - perfect.data.actuator_force[0])
        assert torque > 0 and extra == pytest.approx(torque, rel=1e-6), motion
        closure = 1e-9 if motion == "imposed" else 1e-3
        assert r["P_int"] == pytest.approx(-torque * w, rel=closure), motion
        assert abs(r["P_acc"] - r["P_ext"] - r["P_int"]) < 1e-9 * abs(r["P_ext"]) + 1e-9
        assert r0["P_int"] == pytest.approx(0.0, abs=1e-3 * abs(r0["P_ext"]) + 1e-9)
        out[motion] = torque
    assert out["imposed"] == pytest.approx(out["free"], rel=1e-3)


def test_the_friction_costs_no_per_step_python_while_it_is_off():
    """Perfect bearings step in one batched call; the friction's control acts only while
    it is on."""
    for scene in ("rotor", "wheel_balancer", "compressor", "engine"):
        spec = get_scene(scene)
        assert spec.control_at(Simulation(spec).values) is None, scene
        assert spec.control_at({**Simulation(spec).values, **FRICTION}) is not None, scene


def test_a_minute_at_6000_rpm_with_friction_stays_on_the_energy_theorem():
    """A hard case: 200 g of defect at 6000 rpm, the friction torque ~10 N·m each step."""
    hard = {**FRICTION, "defect_mass_g": 200.0, "speed_rpm": 6000.0}
    sim = Simulation(get_scene("rotor"), values=hard)
    for _ in range(6):
        sim.advance(10.0)
        r = sim.readouts()
        assert abs(r["P_acc"] - r["P_ext"] - r["P_int"]) < 1e-9 * r["P_ext"]
        assert r["omega"] == pytest.approx(200 * math.pi, rel=1e-9)
