"""The inertia scene against the course (5.4 block, 5.5 Huygens, 5.6 shapes, 5.7 rod and
crankshaft) and against Euler's torque-free motion (stable axes, intermediate-axis flip).

The matrices are read from the simulated model (MuJoCo integrates the geoms); the
expected values are written out by hand from the course's formulas, not taken from the
scene's own reference.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.errors import BadParameter
from sandbox.mechanics.inertia import torque_free_period
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene
from sandbox.scenes.inertia import (
    BLOCK,
    CRANKSHAFT,
    CYLINDER,
    HOLLOW,
    ROD,
    SPHERE,
    SQUARE_BLOCK,
    flip_period,
    flip_times,
    parts,
)
from sandbox.scenes.inertia.params import choice_index

SCENE = SCENES["inertia"]
TOL = 5e-3  # the 0.5 %
MATRIX = ("A", "B", "C", "D", "E", "F")


def _matrix(values: dict[str, float]) -> dict[str, float]:
    sim = Simulation(get_scene("inertia"), values=values)
    return sim.readouts(list(MATRIX) + ["I_1", "I_2", "I_3", "gap"])


def _close(read: dict[str, float], expected: dict[str, float], scale: float) -> None:
    """Each term within 0.5 % of the largest one (products that must be 0 included)."""
    for name, value in expected.items():
        assert abs(read[name] - value) <= TOL * scale, (name, read[name], value)


def test_course_5_4_square_block_at_O():
    """5.4: base a × a, height b, O at the centre of the base: A = B = m (a²/12 + b²/3),
    C = m a²/6 (= m (a² + a²)/12), D = E = F = 0 by the two planes of symmetry.
    m = 2 kg, a = 0.3 m, b = 0.5 m: A = 2 (0.0075 + 0.083333) = 0.181667 kg·m²,
    C = 2 × 0.09 / 6 = 0.03 kg·m²."""
    read = _matrix({"solid": SQUARE_BLOCK, "mass": 2.0, "a": 0.3, "b": 0.5, "point": 0})
    expected = {"A": 0.181667, "B": 0.181667, "C": 0.03, "D": 0.0, "E": 0.0, "F": 0.0}
    _close(read, expected, 0.181667)
    assert read["A"] == pytest.approx(2 * (0.3**2 / 12 + 0.5**2 / 3), rel=1e-9)


def test_course_5_5_huygens_from_O_to_G_for_the_square_block():
    """At G (GO = (0, 0, −b/2)) A loses m b²/4: 0.181667 − 2 × 0.0625 = 0.056667 kg·m²
    = m (a² + b²)/12; the Huygens term read is that m b²/4 = 0.125 kg·m²."""
    values = {"solid": SQUARE_BLOCK, "mass": 2.0, "a": 0.3, "b": 0.5, "point": 0}
    sim = Simulation(get_scene("inertia"), values=values)
    at_o = sim.readouts(["A", "C", "huygens_A", "huygens_C"])
    assert at_o["huygens_A"] == pytest.approx(0.125, rel=1e-9)
    assert at_o["huygens_C"] == pytest.approx(0.0, abs=1e-15)
    sim.set_value("point", 1)
    at_g = sim.readouts(["A", "C", "huygens_A"])
    assert at_g["A"] == pytest.approx(2 * (0.09 + 0.25) / 12, rel=TOL)
    assert at_o["A"] - at_g["A"] == pytest.approx(0.125, rel=1e-9)
    assert at_g["C"] == pytest.approx(at_o["C"], rel=1e-12) and at_g["huygens_A"] == 0.0


def test_course_5_5_huygens_to_any_point_with_products():
    """Block a, b, c at G; P = (0.1, −0.2, 0.05) so GP = (a, b, c) = P: the products gain
    −m a b etc. D = ∫ y z dm = m b c = 1.5 × (−0.2 × 0.05) = −0.015 kg·m², E = m a c =
    0.0075, F = m a b = −0.03; A = m (b²+c²)/12 + m (0.04 + 0.0025)."""
    m, a, b, c = 1.5, 0.1, 0.2, 0.3
    p = (0.1, -0.2, 0.05)
    read = _matrix(
        {"solid": BLOCK, "mass": m, "a": a, "b": b, "c": c, "point": 2}
        | {"point_x": p[0], "point_y": p[1], "point_z": p[2]}
    )
    expected = {
        "A": m * (b * b + c * c) / 12 + m * (p[1] ** 2 + p[2] ** 2),
        "B": m * (a * a + c * c) / 12 + m * (p[0] ** 2 + p[2] ** 2),
        "C": m * (a * a + b * b) / 12 + m * (p[0] ** 2 + p[1] ** 2),
        "D": m * p[1] * p[2],
        "E": m * p[0] * p[2],
        "F": m * p[0] * p[1],
    }
    _close(read, expected, expected["A"])
    assert expected["D"] == pytest.approx(-0.015) and expected["F"] == pytest.approx(-0.03)


@pytest.mark.parametrize(
    ("solid", "dims", "diagonal"),
    [
        # 5.6.1 block a, b, c at G: m (b²+c²)/12, m (a²+c²)/12, m (a²+b²)/12
        (BLOCK, {"a": 0.1, "b": 0.2, "c": 0.3}, (0.13 / 12, 0.10 / 12, 0.05 / 12)),
        # 5.6.2 cylinder R = 0.1, h = 0.2: m (R²/4 + h²/12) = 0.005833, m R²/2 = 0.005
        (CYLINDER, {"a": 0.1, "b": 0.2}, (0.0025 + 0.04 / 12, 0.0025 + 0.04 / 12, 0.005)),
        # 5.6.3 sphere R = 0.1: 2 m R²/5 = 0.004
        (SPHERE, {"a": 0.1}, (0.004, 0.004, 0.004)),
    ],
    ids=["block", "cylinder", "sphere"],
)
def test_course_5_6_shapes_at_G(solid, dims, diagonal):
    read = _matrix({"solid": solid, "mass": 1.0, "point": 0, **dims})
    expected = dict(zip("ABC", diagonal, strict=True)) | {"D": 0.0, "E": 0.0, "F": 0.0}
    _close(read, expected, max(diagonal))
    assert sorted(diagonal) == pytest.approx([read["I_1"], read["I_2"], read["I_3"]], rel=TOL)


def test_course_5_7_rod_at_A():
    """5.7: the rod AB = L y as a thin rod, at A: A = C = ∫ y² dm = m L²/3, B = 0 (no mass
    off its own axis), no product. Compressor's rod: m₂ = 0.06 kg, L = 0.055 m:
    m L²/3 = 6.05e-5 kg·m². The simulated rod is a cylinder of radius L/100: 0.02 % off."""
    read = _matrix({"solid": ROD, "mass": 0.06, "b": 0.055, "point": 0})
    expected = {"A": 6.05e-5, "B": 0.0, "C": 6.05e-5, "D": 0.0, "E": 0.0, "F": 0.0}
    _close(read, expected, 6.05e-5)
    assert 0 < read["gap"] < 1e-3


def _crankshaft_by_hand(mass: float) -> dict[str, float]:
    """5.7: the crankshaft as three cylinders, each from the formulary at its centre, moved
    to O by Huygens (GO of each written out), then summed."""
    journal_v = math.pi * 0.008**2 * 0.030
    web_v = math.pi * 0.005**2 * 0.015
    pin_v = math.pi * 0.005**2 * 0.012
    rho = mass / (journal_v + web_v + pin_v)
    mj, mw, mp = rho * journal_v, rho * web_v, rho * pin_v
    # journal: axis z, centre (0, 0, −0.020)
    tj = mj * (0.008**2 / 4 + 0.030**2 / 12)
    a = tj + mj * 0.020**2
    b = tj + mj * 0.020**2
    c = mj * 0.008**2 / 2
    # web: axis x, centre (0.0075, 0, 0)
    tw = mw * (0.005**2 / 4 + 0.015**2 / 12)
    a += mw * 0.005**2 / 2
    b += tw + mw * 0.0075**2
    c += tw + mw * 0.0075**2
    # pin: axis z, centre (0.015, 0, 0.011)
    tp = mp * (0.005**2 / 4 + 0.012**2 / 12)
    a += tp + mp * 0.011**2
    b += tp + mp * (0.015**2 + 0.011**2)
    c += mp * 0.005**2 / 2 + mp * 0.015**2
    e = mp * 0.015 * 0.011  # ∫ x z dm: the pin only (journal x = 0, web z = 0)
    return {"A": a, "B": b, "C": c, "D": 0.0, "E": e, "F": 0.0}


def test_course_5_7_crankshaft_at_O():
    expected = _crankshaft_by_hand(1.0)
    read = _matrix({"solid": CRANKSHAFT, "mass": 1.0, "point": 0})
    _close(read, expected, max(expected.values()))
    assert read["E"] == pytest.approx(expected["E"], rel=TOL)  # the one product, itself
    assert read["E"] > 0 and read["gap"] < 1e-9


def test_a_quarter_turn_of_the_basis_swaps_A_and_B_and_45_degrees_gives_F():
    """Basis turned by ψ about z: F = (A − B) sin ψ cos ψ, largest at 45°: (A − B)/2."""
    base = {"solid": BLOCK, "mass": 1.0, "a": 0.1, "b": 0.2, "c": 0.3, "point": 1}
    turned = _matrix(base | {"basis_z_deg": 90.0})
    assert (turned["A"], turned["B"]) == pytest.approx((0.10 / 12, 0.13 / 12), rel=1e-9)
    half = _matrix(base | {"basis_z_deg": 45.0})
    assert half["F"] == pytest.approx((0.13 - 0.10) / 24, rel=1e-9)
    assert half["A"] == pytest.approx(half["B"], rel=1e-9)
    tilted = _matrix(base | {"basis_z_deg": 30, "basis_y_deg": 20, "basis_x_deg": -40})
    trace = tilted["A"] + tilted["B"] + tilted["C"]
    assert trace == pytest.approx(0.28 / 12, rel=1e-12)  # invariant of a change of basis
    assert [tilted["I_1"], tilted["I_2"], tilted["I_3"]] == pytest.approx(
        [0.05 / 12, 0.10 / 12, 0.13 / 12], rel=1e-9
    )


def test_the_parts_of_the_crankshaft_do_not_overlap():
    """Journal below z = −0.005, web in |z| ≤ 0.005 for 0 ≤ x ≤ R, pin above z = 0.005:
    MuJoCo adds the geoms' inertias, so an overlap would count mass twice."""
    journal, web, pin = parts({"solid": CRANKSHAFT, "mass": 1.0, "a": 0, "b": 0, "c": 0})
    assert journal.centre[2] + journal.size[1] / 2 == pytest.approx(-web.size[0])
    assert pin.centre[2] - pin.size[1] / 2 == pytest.approx(web.size[0])


# -- torque-free motion ----------------------------------------------------------------------
def _record(sim: Simulation, duration: float, every: float = 0.02):
    names = ["spin_angle", "T", "sigma_G", "omega"]
    rows = [sim.readouts(names) | {"time": sim.data.time}]
    for _ in range(int(round(duration / every))):
        sim.advance(every)
        rows.append(sim.readouts(names) | {"time": sim.data.time})
    return {k: np.array([r[k] for r in rows]) for k in rows[0]}


def _drift(x: np.ndarray) -> float:
    return float(np.max(np.abs(x - x[0])) / abs(x[0]))


def test_intermediate_axis_flips_with_eulers_period_and_conserves_T_and_sigma():
    """Block 0.1 × 0.2 × 0.3 m, 1 kg, launched at 120 rpm 1° off its intermediate axis:
    the angle rises through 90° once per period, 3.3584 s from Euler's equations (Jacobi
    functions, K(k) by the AGM), the first time a quarter period after the launch (0.84 s);
    measured within 0.5 % over three periods."""
    sim = Simulation(get_scene("inertia"))
    assert sim.timestep == SCENE.timestep == 0.01 and sim.integrator == "rk4"
    expected = flip_period(sim.values)
    assert expected == pytest.approx(3.358373, rel=1e-6)
    run = _record(sim, 11.0)
    times = flip_times(run["time"], run["spin_angle"])
    assert len(times) == 4 and times[0] == pytest.approx(expected / 4, rel=0.01)
    assert np.diff(times) == pytest.approx([expected] * 3, rel=TOL)
    assert run["spin_angle"].max() > 178.0  # a full flip: ω ends opposite to the axis
    assert _drift(run["T"]) < 1e-6 and _drift(run["sigma_G"]) < 1e-6
    assert _drift(run["omega"]) > 0.01  # |ω| itself is not conserved (T and σ are)


@pytest.mark.parametrize("axis", [0, 2], ids=["smallest", "largest"])
def test_smallest_and_largest_axes_stay_stable(axis):
    """1° off the axis of I₁ or I₃, ω stays within a few degrees of it (20 s)."""
    sim = Simulation(get_scene("inertia"), values={"spin_axis": axis})
    run = _record(sim, 20.0)
    assert run["spin_angle"].max() < 3.0
    assert _drift(run["T"]) < 1e-6 and _drift(run["sigma_G"]) < 1e-6


def test_long_run_keeps_G_still_and_sigma_fixed_in_R0():
    """120 s (36 flips): σ_G keeps its direction in R₀, G stays where it was, T and |σ_G|
    drift by 2e-6 (RK4 at 10 ms, 1.7e-8 per second)."""
    sim = Simulation(get_scene("inertia"))
    arrow = {a.name: a for a in SCENE.page.arrows}["sigma_G"]
    from sandbox.physics.snapshot import Snapshot

    def sigma() -> tuple[np.ndarray, np.ndarray]:
        sim.readouts(["T"])
        return arrow.fn(Snapshot(sim.model, sim.data, sim.values))

    g0, s0 = sigma()
    t0 = sim.readouts(["T"])["T"]
    sim.advance(120.0)
    g1, s1 = sigma()
    assert np.linalg.norm(g1 - g0) < 1e-9
    assert np.linalg.norm(s1 - s0) < 1e-5 * np.linalg.norm(s0)
    assert sim.readouts(["T"])["T"] == pytest.approx(t0, rel=1e-5)


def test_high_speed_spin_shrinks_the_step_and_keeps_the_period():
    """3000 rpm: the default step keeps 0.13 rad per step (3e-4 s), and the flip period
    scales as 1/ω: 3.358373 × 120/3000 = 0.134335 s, within 0.5 %."""
    sim = Simulation(get_scene("inertia"), values={"spin_rpm": 3000.0})
    assert sim.timestep == 3e-4
    run = _record(sim, 0.6, every=6e-4)
    times = flip_times(run["time"], run["spin_angle"])
    assert np.diff(times) == pytest.approx(0.134335, rel=TOL)
    assert _drift(run["T"]) < 1e-6 and _drift(run["sigma_G"]) < 1e-6


@pytest.mark.parametrize("solid", [ROD, CRANKSHAFT], ids=["rod", "crankshaft"])
def test_G_stays_at_rest_at_high_speed_when_O_is_off_G(solid):
    """The rod (O = A at its end) tumbling at 3000 rpm: G does not move, so m V(G) and
    the dynamic resultant stay at round-off (the free joint's origin is at G)."""
    sim = Simulation(
        get_scene("inertia"), values={"solid": solid, "spin_rpm": 3000.0, "spin_axis": 0}
    )
    sim.advance(2.0)
    values = sim.readouts(["kin_R_x", "kin_R_y", "kin_R_z", "dyn_R_x", "sigma_G"])
    assert max(abs(values[f"kin_R_{c}"]) for c in "xyz") < 1e-15
    assert abs(values["dyn_R_x"]) < 1e-12 and values["sigma_G"] > 1e-3
    assert np.linalg.norm(sim.data.xipos[1]) < 1e-15


def test_crankshaft_flip_period_matches_euler():
    """Any solid with three distinct principal moments flips about the middle one; the
    crankshaft (E ≠ 0: principal axes tilted from R_S) as well."""
    values = {"solid": CRANKSHAFT, "spin_rpm": 600.0, "perturbation_deg": 2.0}
    sim = Simulation(get_scene("inertia"), values=values)
    moments = [sim.readouts([f"I_{k}"])[f"I_{k}"] for k in (1, 2, 3)]
    assert moments[0] < moments[1] < moments[2]
    expected = flip_period(sim.values)
    run = _record(sim, 2.6 * expected, every=sim.timestep)
    times = flip_times(run["time"], run["spin_angle"])
    assert len(times) >= 2
    assert np.diff(times) == pytest.approx(expected, rel=TOL)


def test_a_new_launch_parameter_relaunches_but_the_point_does_not():
    """Changing the axis relaunches the spin at once (stable axis: angle back to ε); the
    point and basis only change the readouts."""
    sim = Simulation(get_scene("inertia"))
    sim.advance(1.7)  # mid-flip
    assert sim.readouts(["spin_angle"])["spin_angle"] > 45.0
    sim.set_value("point", 2)
    assert sim.readouts(["spin_angle"])["spin_angle"] > 45.0
    sim.set_value("spin_axis", 2)
    assert sim.readouts(["spin_angle"])["spin_angle"] == pytest.approx(1.0, abs=1e-9)
    sim.set_value("solid", SPHERE)  # a rebuild: the new solid is launched too
    assert sim.readouts(["omega"])["omega"] == pytest.approx(120 * 2 * math.pi / 60)


def test_the_reference_gives_the_course_values_and_the_period():
    ref = SCENE.reference(SCENE.defaults())  # type: ignore[misc]
    assert ref["A"] == pytest.approx(0.13 / 12) and ref["F"] == 0.0
    assert ref["flip_period"] == pytest.approx(
        torque_free_period(
            [0.05 / 12, 0.10 / 12, 0.13 / 12],
            [0.0, 4 * math.pi * math.cos(math.radians(1)), 4 * math.pi * math.sin(math.radians(1))],
        )
    )
    assert math.isnan(flip_period(SCENE.defaults() | {"solid": SPHERE}))


def test_a_bad_solid_number_is_refused():
    with pytest.raises(BadParameter, match="lower solid"):
        parts({"solid": 9, "mass": 1.0, "a": 0.1, "b": 0.1, "c": 0.1})


def test_crankshaft_principal_axis_is_tilted_in_its_plane_of_symmetry():
    """E ≠ 0: the principal axes at G turn in the plane (x, z), y stays one of them. The
    hand matrix at O, brought to G (G from the three centres by hand), gives the tilt."""
    from sandbox.mechanics import huygens_to_G, inertia_matrix, principal_axes

    by_hand = _crankshaft_by_hand(1.0)
    volumes = np.array([0.008**2 * 0.030, 0.005**2 * 0.015, 0.005**2 * 0.012])
    centres = np.array([[0.0, 0.0, -0.020], [0.0075, 0.0, 0.0], [0.015, 0.0, 0.011]])
    g = volumes @ centres / volumes.sum()
    i_g = huygens_to_G(inertia_matrix(*(by_hand[n] for n in MATRIX)), 1.0, -g)
    _, axes = principal_axes(i_g)
    e1 = axes[:, 0] * np.sign(axes[2, 0])
    sim = Simulation(get_scene("inertia"), values={"solid": CRANKSHAFT, "spin_axis": 0})
    read = sim.readouts(["axis_x", "axis_y", "axis_z"])
    assert read["axis_y"] == pytest.approx(0.0, abs=1e-12)
    assert [read["axis_x"], read["axis_z"]] == pytest.approx([e1[0], e1[2]], abs=1e-3)
    assert math.degrees(math.atan2(read["axis_x"], read["axis_z"])) == pytest.approx(19.3, abs=0.1)


def test_exactly_on_the_intermediate_axis_nothing_grows_but_the_least_tilt_flips():
    """ε = 0: Euler's equations keep ω on e₂ exactly (the lesson's remark); ε = 0.001°
    grows (rate 0.48 ω) into a flip within 4 s."""
    still = Simulation(get_scene("inertia"), values={"perturbation_deg": 0.0})
    still.advance(30.0)
    assert still.readouts(["spin_angle"])["spin_angle"] == 0.0
    tiny = Simulation(get_scene("inertia"), values={"perturbation_deg": 0.001})
    run = _record(tiny, 4.0)
    assert run["spin_angle"].max() > 170.0


def _integrate_cylinders(cylinders, mass: float, n: int = 48) -> dict[str, float]:
    """The course's definitions A = ∫ (y² + z²) dm ... E = ∫ x z dm, integrated numerically
    over each cylinder in its own cylindrical coordinates (ρ, φ, s), dV = ρ dρ dφ ds
    (midpoint rule, error ~1/n²), uniform density."""
    volume = sum(math.pi * r * r * h for _, r, h, _, _ in cylinders)
    sums = dict.fromkeys(MATRIX, 0.0)
    g = (np.arange(n) + 0.5) / n
    for _, r, h, centre, axis in cylinders:
        u = np.asarray(axis, dtype=float)
        v = np.cross(u, [0.0, 1.0, 0.0] if abs(u[1]) < 0.9 else [1.0, 0.0, 0.0])
        v /= np.linalg.norm(v)
        w = np.cross(u, v)
        rho, phi, s = np.meshgrid(g * r, g * 2 * math.pi, (g - 0.5) * h, indexing="ij")
        dv = rho * (r / n) * (2 * math.pi / n) * (h / n)
        p = (
            np.asarray(centre)[:, None, None, None]
            + u[:, None, None, None] * s
            + v[:, None, None, None] * rho * np.cos(phi)
            + w[:, None, None, None] * rho * np.sin(phi)
        )
        dm = mass / volume * dv
        x, y, z = p
        sums["A"] += float(np.sum((y * y + z * z) * dm))
        sums["B"] += float(np.sum((x * x + z * z) * dm))
        sums["C"] += float(np.sum((x * x + y * y) * dm))
        sums["D"] += float(np.sum(y * z * dm))
        sums["E"] += float(np.sum(x * z * dm))
        sums["F"] += float(np.sum(x * y * dm))
    return sums


def test_course_5_7_crankshaft_by_integration_agrees_with_the_formulary_and_mujoco():
    """5.7 asks for the integral and a check with the formulary: the direct integration of
    the definitions over the three cylinders, the formulary + Huygens sum by hand, and
    MuJoCo's model agree within 0.5 % (of the largest term; E within 0.5 % of itself)."""
    from sandbox.scenes.inertia import CRANKSHAFT_PARTS

    integral = _integrate_cylinders(CRANKSHAFT_PARTS, 1.0)
    by_hand = _crankshaft_by_hand(1.0)
    read = _matrix({"solid": CRANKSHAFT, "mass": 1.0, "point": 0})
    _close(integral, by_hand, by_hand["B"])
    _close(read, integral, by_hand["B"])
    assert integral["E"] == pytest.approx(by_hand["E"], rel=TOL)


def test_course_5_7_rod_by_integration():
    """The rod's integral at A: ∫₀ᴸ y² (m/L) dy = m L²/3 (midpoint rule, 1000 slices)."""
    m, length, n = 0.06, 0.055, 1000
    y = (np.arange(n) + 0.5) / n * length
    integral = float(np.sum(y * y * m / n))
    assert integral == pytest.approx(m * length**2 / 3, rel=1e-6)
    read = _matrix({"solid": ROD, "mass": m, "b": length, "point": 0})
    assert read["A"] == pytest.approx(integral, rel=TOL)
    assert read["C"] == pytest.approx(integral, rel=TOL)


@pytest.mark.parametrize("ratio", [0.05, 0.6, 0.95])
def test_course_5_6_2_hollow_cylinder_is_the_full_one_minus_the_hole(ratio):
    """5.6.2: I(tube) = I(full cylinder) − I(hole), written with the masses of a density
    ρ: R = 0.1 m, h = 0.2 m, r = ratio × R, tube mass 1 kg. MuJoCo integrates a 256-gon
    mesh (exact mesh inertia): within 2e-4 of the circles."""
    big_r, h = 0.1, 0.2
    r = ratio * big_r
    rho = 1.0 / (math.pi * (big_r**2 - r**2) * h)
    full, hole = rho * math.pi * big_r**2 * h, rho * math.pi * r**2 * h
    a = full * (big_r**2 / 4 + h**2 / 12) - hole * (r**2 / 4 + h**2 / 12)
    c = full * big_r**2 / 2 - hole * r**2 / 2
    sim = Simulation(
        get_scene("inertia"), values={"solid": HOLLOW, "a": big_r, "b": h, "hole_ratio": ratio}
    )
    read = sim.readouts(list(MATRIX) + ["gap"])
    _close(read, {"A": a, "B": a, "C": c, "D": 0.0, "E": 0.0, "F": 0.0}, max(a, c))
    assert read["gap"] < 2e-4
    assert c == pytest.approx(1.0 * (big_r**2 + r**2) / 2)  # m (R² + r²)/2
    sim.advance(1.0)  # a thin-walled tube spins as well
    assert sim.readouts(["omega"])["omega"] == pytest.approx(4 * math.pi, rel=1e-3)


def test_choice_index_rounds_a_choice_parameter_to_its_index():
    assert choice_index({"solid": 2.0}, "solid") == 2
    assert choice_index({"point": 0.6, "solid": 0.0}, "point") == 1
    assert choice_index({"spin_axis": 1.4}, "spin_axis") == 1
