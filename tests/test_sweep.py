"""Parameter studies (``sandbox sweep``): the course's laws through a grid of runs,
the same rows on one process or two, and every bad input refused before a run."""

from __future__ import annotations

import csv
import json
import math

import pytest

import sandbox.scenes  # noqa: F401  (the registry)
from sandbox.cli import main
from sandbox.errors import BadOption, SandboxError
from sandbox.sweep import Measure, Study, Vary, parse_measure, parse_vary, reduce, run_study


def _rotor(count: int = 7, **kw: object) -> Study:
    return Study(
        "rotor",
        (Vary("speed_rpm", 0.0, 6000.0, count),),
        Measure("bearing_A"),
        duration=0.2,
        **kw,  # type: ignore[arg-type]
    )


def test_bearing_forces_follow_the_square_of_the_speed():
    """Course 7.2: the bearing forces of an unbalanced rotor grow as ω²; each run's
    force equals the closed form to 1e-6 (relative), and F(ω)/ω² is one constant."""
    rows = run_study(_rotor())
    assert [r["speed_rpm"] for r in rows] == [0, 1000, 2000, 3000, 4000, 5000, 6000]
    for r in rows[1:]:
        assert r["status"] == "ok"
        assert r["measure"] == pytest.approx(r["closed_form"], rel=1e-6)
    k = [r["measure"] / r["speed_rpm"] ** 2 for r in rows[1:]]
    assert max(k) == pytest.approx(min(k), rel=1e-6)


def test_one_process_or_two_give_the_same_rows():
    study = Study(
        "compressor",
        (Vary("L", 0.04, 0.1, 3), Vary("speed_rpm", 2000.0, 3000.0, 2)),
        Measure("pilon", "amplitude"),
        duration=0.05,
        settle=0.01,
    )
    one, two = run_study(study, jobs=1), run_study(study, jobs=2)
    assert repr(one) == repr(two) and len(one) == 6  # bit for bit (repr: NaN equals NaN)
    assert [(r["L"], r["speed_rpm"]) for r in one][:2] == [(0.04, 2000.0), (0.04, 3000.0)]


def test_the_second_order_of_the_pilon_matches_the_course():
    """Compressor, course 7.3: the pilon's order-2 amplitude, fitted on the last simulated
    revolution, against the course's (pilon_h2) within 0.5 %, and falling as R/L does."""
    study = Study(
        "compressor", (Vary("L", 0.04, 0.1, 3),), Measure("pilon", "order2"), 0.1, settle=0.02
    )
    rows = run_study(study)
    for r in rows:
        assert r["measure"] == pytest.approx(r["closed_form"], rel=5e-3)
    assert rows[0]["measure"] > rows[1]["measure"] > rows[2]["measure"]


def test_the_statistics_of_a_known_signal():
    theta = [2 * math.pi * k / 64 for k in range(200)]
    y = [3 + 2 * math.cos(t) + 0.5 * math.sin(2 * t) for t in theta]
    import numpy as np

    values, angles = np.array(y), np.array(theta)
    assert reduce("order1", values, angles) == pytest.approx(2.0, rel=1e-9)
    assert reduce("order2", values, angles) == pytest.approx(0.5, rel=1e-9)
    assert reduce("final", values, angles) == y[-1] and reduce("max", values, None) == max(y)
    assert math.isnan(reduce("order2", values[:30], angles[:30]))  # under a revolution


def test_a_period_and_an_event_time():
    """``period``: mean time between rises through mid-range; ``onset``: the first
    instant a readout leaves its starting value by 1 % of its largest departure."""
    import numpy as np

    t = np.linspace(0.0, 10.0, 10_001)
    assert reduce("period", np.sin(2 * np.pi * t / 2.5), None, t) == pytest.approx(2.5, rel=1e-6)
    assert math.isnan(reduce("period", t, None, t))  # no oscillation
    slip = np.where(t < 3.0, 0.0, (t - 3.0) * 0.2)  # starts slipping at 3 s
    assert reduce("onset", slip, None, t) == pytest.approx(3.0 + 0.01 * 1.4 / 0.2, abs=2e-3)
    assert math.isnan(reduce("onset", np.full_like(t, 2.0), None, t))  # never
    assert math.isnan(reduce("onset", 1e-5 * t, None, t))  # a creep under 1e-3: no event
    lifted = np.where(t < 4.2, 1.0, 0.0)  # a contact flag that drops
    assert reduce("onset", lifted, None, t) == pytest.approx(4.2, abs=1e-3)


def test_a_cylinder_past_the_slip_threshold_slips_at_once():
    """Course: with μ below tan α / 3 the cylinder slips from the start (onset ~0);
    below the threshold the slip velocity never leaves 0 (NaN: no event)."""

    def study(mu: float) -> Study:
        return Study(
            "rolling_cylinder",
            (Vary("slope_deg", 50.0, 50.0, 1),),
            Measure("slip_velocity", "onset"),
            0.3,
            fixed=(("mu", repr(mu)),),
        )

    (slips,) = run_study(study(0.1))
    assert slips["measure"] < 0.01
    (rolls,) = run_study(study(1.0))
    assert math.isnan(rolls["measure"])  # a creep of 10⁻⁶ m/s is no slip


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--vary", "speed_rpm=0:1", "--measure", "bearing_A"], "NAME=START:STOP:COUNT"),
        (["--vary", "speed_rpm=0:x:3", "--measure", "bearing_A"], "must be numbers"),
        (
            ["--vary", "speed_rpm=0:1:3", "--vary", "speed_rpm=0:1:2", "--measure", "bearing_A"],
            "given twice",
        ),  # fmt: skip
        (["--vary", "speed_rpm=0:9000:3", "--measure", "bearing_A"], "out of range"),
        (["--vary", "speed_rpm=0:100:3", "--measure", "nope"], "unknown readout 'nope'"),
        (["--vary", "speed_rpm=0:100:3", "--measure", "bearing_A:median"], "final, mean, max"),
        (["--vary", "speed_rpm=0:100:1001", "--measure", "bearing_A"], "at most 1000"),
        (
            ["--vary", "speed_rpm=0:100:3", "--measure", "bearing_A", "--set", "speed_rpm=3"],
            "both varied and --set",
        ),  # fmt: skip
        (["--measure", "bearing_A"], "at least one --vary"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, argv, words):
    assert main(["sweep", "rotor", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("sandbox: error: ") and words in err, err


def test_too_many_steps_in_all_is_refused_before_a_run(capsys):
    argv = ["sweep", "compressor", "--vary", "speed_rpm=0:100:100", "--measure", "pilon"]
    assert main([*argv, "--duration", "60"]) == 2
    assert "max 10,000,000" in capsys.readouterr().err


def test_a_diverged_run_is_a_row_and_the_study_exits_3(tmp_path, capsys):
    out = tmp_path / "study.csv"
    argv = ["sweep", "compressor", "--vary", "speed_rpm=3000:17000:2", "--measure", "pilon"]
    argv += ["--timestep", "0.004", "--duration", "0.5", "--jobs", "1", "--out", str(out)]
    argv += [
        "--motion",
        "free",
    ]  # the simulated crank diverges at this step; the imposed one is exact
    assert main(argv) == 3
    rows = list(csv.DictReader(out.open(encoding="utf-8")))
    assert [r["status"] for r in rows] == ["ok", "diverged"] and rows[1]["measure"] == ""
    assert "1 of 2 runs diverged" in capsys.readouterr().err


def test_the_output_files_hold_the_contract_columns(tmp_path, capsys):
    argv = ["sweep", "rotor", "--vary", "speed_rpm=1000:2000:2", "--measure", "bearing_B"]
    assert main([*argv, "--duration", "0.1", "--jobs", "1", "--out", str(tmp_path / "a.csv")]) == 0
    header = (tmp_path / "a.csv").read_text(encoding="utf-8").splitlines()[0]
    assert header == "speed_rpm,measure,closed_form,gap,status"
    assert main([*argv, "--duration", "0.1", "--jobs", "1", "--out", str(tmp_path / "a.json")]) == 0
    data = json.loads((tmp_path / "a.json").read_text(encoding="utf-8"))
    assert data["measure"] == "bearing_B:final" and len(data["rows"]) == 2
    assert "2 runs of 0.1 s, bearing_B:final" in capsys.readouterr().out


def test_parsers_name_their_form():
    assert parse_vary("R=0.01:0.02:3").values == pytest.approx([0.01, 0.015, 0.02])
    assert parse_measure("pilon:order2") == Measure("pilon", "order2")
    with pytest.raises(BadOption):
        parse_vary("1R=0:1:2")
    with pytest.raises(SandboxError, match="valid parameters: angle1_deg"):
        run_study(Study("rotor", (Vary("nope", 0, 1, 2),), Measure("bearing_A"), 0.1))


def test_the_chart_is_a_png_and_a_bad_chart_path_costs_no_run(tmp_path, capsys):
    argv = ["sweep", "rotor", "--vary", "speed_rpm=0:3000:4", "--vary", "mass1_g=0:20:2"]
    argv += ["--measure", "bearing_A", "--duration", "0.1"]
    assert main([*argv, "--plot", str(tmp_path / "a.png")]) == 0
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    assert main([*argv, "--plot", str(tmp_path / "a.svg")]) == 2
    assert "must end in .png" in capsys.readouterr().err


@pytest.mark.slow  # a Dask cluster of two worker processes: ~10 s
def test_a_dask_cluster_gives_the_local_rows_bit_for_bit():
    distributed = pytest.importorskip("distributed")
    study = Study(
        "compressor",
        (Vary("L", 0.04, 0.1, 3),),
        Measure("pilon", "order2"),
        duration=0.05,
        settle=0.02,
    )
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        remote = run_study(study, scheduler=cluster.scheduler_address)
    assert repr(remote) == repr(run_study(study))


def test_an_unreachable_scheduler_is_one_line(capsys, monkeypatch):
    pytest.importorskip("distributed")
    from sandbox.sweep import runs

    monkeypatch.setattr(runs, "CLUSTER_TIMEOUT", 1.0)
    argv = ["sweep", "rotor", "--vary", "speed_rpm=0:100:2", "--measure", "bearing_A"]
    assert main([*argv, "--scheduler", "tcp://127.0.0.1:9"]) == 2
    err = capsys.readouterr().err
    assert "cannot reach the Dask scheduler" in err and err.count("\n") == 1


def test_the_sweep_benchmark_prints_both_times_and_their_ratio(capsys, monkeypatch):
    from sandbox import sweep

    small = sweep.bench_study("rotor", runs=4, duration=0.1)
    monkeypatch.setattr(sweep, "bench_study", lambda target: small)
    monkeypatch.setattr("sandbox.cli.bench.default_workers", lambda: 2)
    assert main(["bench", "--sweep"]) == 0
    out = capsys.readouterr().out
    assert "rotor: 4 runs of 0.1 s, omega:max over speed_rpm from 0 to 6000" in out
    assert "1 process" in out and "2 processes" in out
    assert "time in one process / time on 2: ×" in out
