"""sandbox bench: convergence orders, Pareto front, divergence, results schema.

Timings are printed by the command, never asserted here.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from sandbox.bench import (
    CSV_COLUMNS,
    Run,
    SceneResult,
    bench_scene,
    mark_pareto,
    run_one,
    to_json,
    write_results,
)
from sandbox.cli import main
from sandbox.physics.spec import Accuracy
from sandbox.scenes import SCENES
from sandbox.scenes.measures import energy_drift

OSCILLATOR = """
<mujoco>
  <worldbody>
    <body>
      <joint type="slide" axis="1 0 0" stiffness="100"/>
      <geom type="sphere" size="0.05" mass="1"/>
    </body>
  </worldbody>
  <keyframe><key qpos="0.1"/></keyframe>
</mujoco>
"""
"""m = 1 kg, k = 100 N/m, x0 = 0.1 m: p(t) = −m x0 ω sin ωt with ω = 10 rad/s."""


def _momentum_error(series, values):
    t, p = series["time"], series["kin_R_x"]
    return float(np.max(np.abs(p + 1.0 * np.sin(10.0 * t))))  # |p| peaks at 1 kg·m/s


ACC = Accuracy(
    key="kin_R_x",
    readouts=("kin_R_x", "T", "V"),
    duration=2.0,
    error=_momentum_error,
    invariant="T + V",
    drift=energy_drift(),
)


@pytest.fixture
def oscillator(tmp_path):
    path = tmp_path / "oscillator.xml"
    path.write_text(OSCILLATOR)
    return str(path)


@pytest.mark.parametrize(
    ("integrator", "low", "high"),
    [("euler", 0.8, 2.2), ("implicitfast", 0.8, 2.2), ("implicit", 0.8, 2.2), ("rk4", 3.5, 4.5)],
)
def test_error_shrinks_with_the_integrators_order(oscillator, integrator, low, high):
    """Error ∝ dt^p: first-order methods p ≥ 1 (the symplectic Euler of a linear
    oscillator even reaches 2 on this observable), RK4 p = 4."""
    dts = (1e-3, 3e-3, 1e-2)
    errors = [run_one(oscillator, ACC, integrator, dt, ACC.duration).error for dt in dts]
    slopes = [math.log(errors[i + 1] / errors[i]) / math.log(dts[i + 1] / dts[i]) for i in (0, 1)]
    assert all(low <= s <= high for s in slopes), slopes


def test_divergence_is_reported_not_hidden(diverging_xml):
    run = run_one(str(diverging_xml), ACC, "euler", 0.05, 5.0)  # ω dt ≫ 2: unstable
    assert run.diverged and "diverged" in run.detail and math.isinf(run.error)


def test_pareto_front():
    runs = [
        Run("s", "a", 1e-3, 1, error=1e-6, cpu_per_sim_s=1.0),
        Run("s", "b", 1e-3, 1, error=1e-3, cpu_per_sim_s=0.1),
        Run("s", "c", 1e-3, 1, error=1e-2, cpu_per_sim_s=0.5),  # dearer and worse than b
        Run("s", "d", 1e-3, 1, error=1e-4, cpu_per_sim_s=0.11),  # same cost as b, better
        Run("s", "e", 1e-3, 1, diverged=True),
    ]
    mark_pareto(runs)
    assert [r.pareto for r in runs] == [True, False, False, True, False]


def test_each_default_is_within_half_a_percent_and_admissible():
    """Pareto membership depends on timings, which are printed, never asserted; what must
    hold on any machine: each scene's default meets 0.5 % on its key quantity and stays
    within its drift and constraint limits."""
    for name in ("rotor", "heavy_gyroscope"):
        scene = SCENES[name]
        res = bench_scene(scene, quick=True, integrators=(scene.integrator,), factors=(1.0,))
        default = res.default
        assert default is not None and default.error <= 5e-3, name
        assert res.admissible(default), name


@pytest.mark.slow  # the whole quick grid of a scene plus its charts: 3.6-7.4 s
def test_results_schema(tmp_path, capsys):
    assert main(["bench", "rotor", "--quick", "--out", str(tmp_path)]) == 0
    doc = json.loads((tmp_path / "results.json").read_text())
    assert doc["schema"] == 1 and set(doc["machine"]) >= {"mujoco", "cpus"}
    scene = doc["scenes"]["rotor"]
    assert scene["key"] == "bearing_A" and scene["default"]["integrator"] == "implicitfast"
    integrators = {r["integrator"] for r in scene["runs"]}
    assert integrators == {"euler", "implicit", "implicitfast", "rk4", "discrete"}
    timesteps = sorted({r["timestep"] for r in scene["runs"]})
    assert len(timesteps) >= 5 and timesteps[-1] / timesteps[0] >= 99
    keys = set(CSV_COLUMNS) - {"scene", "integrator", "timestep", "duration"}
    assert all(keys <= set(r) for r in scene["runs"])
    for name in ("results.csv", "results.md", "rotor.png"):
        assert (tmp_path / name).stat().st_size > 100, name
    assert (tmp_path / "rotor.png").read_bytes()[:4] == b"\x89PNG"
    assert "Pareto front" in capsys.readouterr().out


def test_json_encodes_infinities(diverging_xml):
    run = run_one(str(diverging_xml), ACC, "euler", 0.05, 5.0)
    from sandbox.bench import SceneResult

    doc = to_json([SceneResult("osc", "p", "T+V", "euler", 0.5, [run])], quick=True)
    text = json.dumps(doc, allow_nan=False)
    assert '"error": "inf"' in text


def test_effects_and_overhead_print_their_ratios(capsys):
    assert main(["bench", "rotor", "--effects", "--overhead", "--quick"]) == 0
    out = capsys.readouterr().out
    assert "speed ratio" in out and "run / bare" in out


def test_unknown_scene_is_refused(capsys):
    assert main(["bench", "nope"]) == 2


def test_write_results_makes_one_png_per_scene(tmp_path):
    res = bench_scene(SCENES["rotor"], quick=True, integrators=("euler",))
    paths = write_results([res], tmp_path, quick=True)
    assert tmp_path / "rotor.png" in paths


def test_switching_every_effect_on_costs_time_and_energy_in_the_compressor():
    """Links that may touch dissipate the motor's power (the course's 'no contact
    between links' hypothesis is what keeps the energy theorem)."""
    from sandbox.bench import bench_effects

    res = bench_effects(SCENES["compressor"], quick=True)
    assert res.all_on.drift > 100 * res.declared.drift
    assert res.speed_ratio > 1.0  # printed by the command; only its sign is asserted


def test_each_scene_default_session_cost_is_measured_and_compared_with_the_goal():
    """Stepping, a 60 Hz arrows snapshot and a 10 Hz readout row per simulated second, at
    the default parameters; the numbers are written, only their consistency is asserted."""
    from sandbox.bench import FRAME_RATE, GOAL, PANEL_RATE, session_cost, session_markdown

    cost = session_cost(SCENES["heavy_gyroscope"])
    assert cost.timestep == SCENES["heavy_gyroscope"].timestep and cost.integrator == "rk4"
    assert min(cost.step_s, cost.snapshot_s, cost.row_s) > 0
    total = cost.step_s + FRAME_RATE * cost.snapshot_s + PANEL_RATE * cost.row_s
    assert cost.per_sim_s == pytest.approx(total)
    assert cost.meets_goal == (cost.step_factor >= GOAL and cost.realtime_factor >= GOAL)
    from sandbox.bench import SceneResult

    res = SceneResult("heavy_gyroscope", "k", "T + V", "rk4", 2e-4, [], session=cost)
    doc = to_json([res], quick=True)["scenes"]["heavy_gyroscope"]["session"]
    assert doc["meets_goal"] == cost.meets_goal and doc["frame_rate"] == 60.0
    assert "session × real time" in session_markdown([res])


def test_a_speed_dependent_default_is_marked_at_the_benchmarks_speed():
    """The compressor's grid runs at 17,000 rpm, where its default step is 1e-4 s; its
    session (3000 rpm) runs at 5e-4 s."""
    res = bench_scene(SCENES["compressor"], quick=True, integrators=("rk4",))
    assert res.default is not None and res.default.timestep == 1e-4
    assert res.default_timestep == 1e-4 and res.session.timestep == 5e-4


def test_results_json_decodes_back_with_its_front(tmp_path, diverging_xml):
    """to_json -> load_results: the same runs (inf and nan restored), the front marked
    again with the scene's limits; a missing file, scene or field gives None."""
    from sandbox.bench import SceneResult, load_results

    runs = [
        Run("osc", "a", 1e-3, 1, error=1e-6, drift=0.0, cpu_per_sim_s=1.0),
        Run("osc", "b", 1e-3, 1, error=1e-3, drift=0.0, cpu_per_sim_s=0.1, default=True),
        run_one(str(diverging_xml), ACC, "euler", 0.05, 5.0),
    ]
    res = SceneResult("osc", "p", "T+V", "euler", 1e-3, runs, drift_tol=1e-3)
    path = tmp_path / "results.json"
    path.write_text(json.dumps(to_json([res], quick=True)))
    back = load_results("osc", path)
    assert back is not None and back.default is not None and back.default.integrator == "b"
    assert [r.pareto for r in back.runs] == [True, True, False]
    assert math.isinf(back.runs[2].error) and back.runs[2].diverged
    assert math.isnan(back.runs[2].cpu_per_sim_s) and back.drift_tol == 1e-3
    assert load_results("other", path) is None
    assert load_results("osc", tmp_path / "none.json") is None
    path.write_text(json.dumps({"scenes": {"osc": {"runs": [{"nope": 1}]}}}))
    assert load_results("osc", path) is None


@pytest.mark.parametrize(
    "change",
    [
        {"timestep": "fast"},
        {"error": "big"},
        {"error": [1.0]},
        {"constraint": {}},
        {"diverged": "yes"},
        {"pareto": 1},
        {"scene": 5},
        {"detail": None},
    ],
    ids=lambda c: next(iter(c)),
)
def test_a_run_field_of_the_wrong_type_gives_none(tmp_path, change):
    """A foreign results.json (a field of the wrong type) is not loaded: None, no crash,
    where the same document with the right types loads."""
    from sandbox.bench import SceneResult, load_results

    run = Run("osc", "rk4", 1e-3, 1.0, error=1e-6, drift=0.0, cpu_per_sim_s=1.0)
    doc = to_json([SceneResult("osc", "p", "T+V", "rk4", 1e-3, [run])], quick=True)
    path = tmp_path / "results.json"
    path.write_text(json.dumps(doc))
    back = load_results("osc", path)
    assert back is not None and back.runs[0].timestep == 1e-3 and back.runs[0].error == 1e-6
    doc["scenes"]["osc"]["runs"][0].update(change)
    path.write_text(json.dumps(doc))
    assert load_results("osc", path) is None
    doc["scenes"]["osc"]["runs"] = [3]
    path.write_text(json.dumps(doc))
    assert load_results("osc", path) is None


def test_merge_refreshes_the_named_scenes_and_keeps_the_others():
    """``sandbox bench SCENE --merge``: the shipped results.json keeps every other scene,
    sessions included, so one new scene does not cost a whole benchmark."""
    from sandbox.bench import merge_results
    from sandbox.data import data_dir

    path = data_dir("bench") / "results.json"
    original = json.loads(path.read_text())["scenes"]
    fresh = SceneResult(
        "rotor", "bearing_A", "T", "euler", 0.01, [Run("rotor", "euler", 0.01, 0.5, error=1e-3)]
    )
    merged = merge_results([fresh], path)
    assert merged[0] is fresh
    kept = {r.scene: r for r in merged[1:]}
    assert set(kept) == set(original) - {"rotor"}
    doc = to_json(merged, quick=False)["scenes"]
    for name in kept:
        assert doc[name]["runs"] == original[name]["runs"], name
        assert doc[name]["session"] == original[name]["session"], name
    assert doc["rotor"]["runs"][0]["error"] == 1e-3 and "session" not in doc["rotor"]


def test_a_timestep_the_scene_refuses_is_left_out_of_the_grid():
    """The wheel balancer's soft bench defaults to 3 ms and refuses more than 10 ms: its
    grid (0.1 to 10 times the default) drops 30 ms instead of failing the benchmark."""
    scene = SCENES["wheel_balancer"]
    res = bench_scene(scene, quick=True, integrators=("rk4",), factors=(1.0, 3.0, 10.0))
    steps = [r.timestep for r in res.runs]
    assert steps and max(steps) <= scene.max_timestep < 10 * res.default_timestep
    assert res.default is not None and not res.default.diverged


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_scene_ships_its_benchmark_with_the_default_on_the_front(name):
    """bench/results.json (shown in README and the accuracy panel) holds every registered
    scene at its current default: within 0.5 % on its key quantity, admissible, on the
    Pareto front of the stored measurements, its web session at least 20x real time."""
    from sandbox.bench import load_results

    scene = SCENES[name]
    res = load_results(name)
    assert res is not None, f"run: sandbox bench {name} --out bench --merge"
    assert res.default_integrator == scene.integrator
    assert scene.accuracy is not None
    assert math.isclose(res.default_timestep, scene.default_timestep(scene.accuracy.values))
    default = res.default
    assert default is not None and default.pareto and res.admissible(default), name
    assert default.error <= 5e-3, (name, default.error)
    assert res.session is not None and res.session.meets_goal, name


def test_every_scene_that_imposes_its_motion_has_an_imposed_row_saying_why_not_when_absent():
    """bench/results.md: the exact row where the benchmark's case can be imposed, else a
    row naming why (the wheel balancer's springs, the robot axis's flexible arm)."""
    from sandbox.bench.report import markdown
    from sandbox.bench.store import load_results
    from sandbox.scenes import SCENES

    for name, scene in SCENES.items():
        res = load_results(name)
        if res is None or scene.imposed is None:
            continue
        text = markdown([res])
        assert "| **imposed motion**" in text, name
        if res.imposed is None:
            assert "not this case:" in text and "simulated" in text, name
