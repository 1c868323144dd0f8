"""The sampling loop shared by ``sandbox run`` and ``sandbox bench``, and its writers."""

from __future__ import annotations

import csv
import json

import pytest

from sandbox.errors import BadOption, Diverged
from sandbox.physics.simulation import Simulation
from sandbox.runner import (
    MAX_ROWS,
    MAX_STEPS,
    RowWriter,
    check_out,
    check_run,
    chunks,
    csv_cell,
    simulate,
    write_rows,
)


def test_chunks_sample_at_the_rate_with_at_least_one_step():
    assert chunks(1.0, 100.0, 1e-3) == (1000, 10)
    assert chunks(0.0, 100.0, 1e-3) == (0, 10)
    assert chunks(1.0, 1e4, 1e-3) == (1000, 1)  # faster than the timestep: every step


def test_rows_at_the_rate_with_every_column(pendulum_xml):
    sim = Simulation(pendulum_xml)
    frames = []

    class Sink:
        def frame(self, values):
            frames.append(dict(values))

    columns, rows, error = simulate(sim, 0.5, 20.0, progress=False, recorder=Sink())
    assert error is None and columns == sim.readout_names()
    assert len(rows) == 11 and all(len(r) == len(columns) for r in rows)
    assert [r[0] for r in rows] == pytest.approx([0.05 * k for k in range(11)])
    assert len(frames) == 11 and list(frames[-1]) == columns


def test_chosen_names_only(pendulum_xml):
    columns, rows, _ = simulate(
        Simulation(pendulum_xml), 0.1, 100.0, progress=False, names=("time", "T")
    )
    assert columns == ["time", "T"] and len(rows) == 11 and len(rows[0]) == 2


def test_divergence_stops_and_keeps_the_rows(diverging_xml):
    columns, rows, error = simulate(Simulation(diverging_xml), 5.0, 20.0, progress=False)
    assert isinstance(error, Diverged) and error.exit_code == 3
    assert 1 <= len(rows) < 101


def test_writers_csv_and_json(tmp_path, pendulum_xml):
    sim = Simulation(pendulum_xml)
    columns, rows, _ = simulate(sim, 0.1, 100.0, progress=False)
    write_rows(tmp_path / "a.csv", sim, columns, rows)
    with (tmp_path / "a.csv").open() as fh:
        table = list(csv.reader(fh))
    assert table[0] == columns and len(table) == 1 + len(rows)
    write_rows(tmp_path / "a.json", sim, columns, rows)
    doc = json.loads((tmp_path / "a.json").read_text())
    assert set(doc) == {"scene", "params", "integrator", "timestep", "columns", "units", "rows"}
    assert doc["columns"] == columns and doc["units"]["T"] == "J"


def test_simulate_refuses_over_budget_before_stepping(pendulum_xml):
    sim = Simulation(pendulum_xml)  # dt = 1 ms
    with pytest.raises(BadOption, match="takes 1e\\+300 steps"):
        simulate(sim, 1e297, 100.0, progress=False)
    with pytest.raises(BadOption, match="--rate 5e-324 is outside"):
        simulate(sim, 1.0, 5e-324, progress=False)
    assert sim.data.time == 0.0


@pytest.mark.parametrize(
    "duration, rate, words",
    [
        (float("nan"), 100.0, "--duration must be zero or a positive number"),
        (-1.0, 100.0, "--duration must be zero or a positive number"),
        (1.0, float("inf"), "--rate inf is outside"),
        (MAX_STEPS * 1e-3 + 1, 1.0, f"(max {MAX_STEPS:,})"),
        (MAX_ROWS / 100.0, 100.0, f"(max {MAX_ROWS:,})"),
    ],
)
def test_check_run_refusals(duration, rate, words):
    with pytest.raises(BadOption) as info:
        check_run(duration, rate, 1e-3)
    assert words in str(info.value)


def test_keep_false_holds_only_the_last_row(pendulum_xml, tmp_path):
    sim = Simulation(pendulum_xml)
    writer = RowWriter(tmp_path / "p.csv", sim, sim.readout_names())
    columns, rows, error = simulate(sim, 0.5, 20.0, progress=False, recorder=writer, keep=False)
    writer.close()
    assert error is None and len(rows) == 1 and rows[0][0] == pytest.approx(0.5)
    with (tmp_path / "p.csv").open() as fh:
        table = list(csv.reader(fh))
    assert writer.count == 11 and len(table) == 12 and table[-1][0] == "0.5"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.csv", "pendulum.xml"]


def test_row_writer_json_nulls_and_discard(tmp_path, pendulum_xml):
    sim = Simulation(pendulum_xml)
    writer = RowWriter(tmp_path / "r.json", sim, ["time", "T"])
    assert not (tmp_path / "r.json").exists()  # under a temporary name until closed
    writer.frame({"time": 0.0, "T": float("nan"), "V": 1.0})
    writer.row([0.1, float("inf")])
    writer.close()
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["rows"] == [[0.0, None], [0.1, None]] and doc["columns"] == ["time", "T"]
    other = RowWriter(tmp_path / "r.json", sim, ["time"])
    other.row([1.0])
    other.discard()
    assert json.loads((tmp_path / "r.json").read_text()) == doc  # the old file is kept
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pendulum.xml", "r.json"]


@pytest.mark.parametrize(
    "name, words",
    [
        ("r.txt", "must end in .csv or .json"),
        ("plain/r.csv", "is a file, not a folder"),
        ("missing/r.csv", "does not exist; create it first"),
        ("d.csv", "is a directory"),
        ("z" * 5000 + ".csv", "File name too long; give another path"),
    ],
)
def test_check_out_refusals(name, words, tmp_path):
    (tmp_path / "plain").write_text("x")
    (tmp_path / "d.csv").mkdir()
    with pytest.raises(BadOption) as info:
        check_out(tmp_path / name)
    assert words in str(info.value)


def test_every_csv_writes_a_number_the_same_way():
    assert csv_cell(0.1 + 0.2) == "0.3"  # the round-off of the last digits is not written
    assert csv_cell(1.0 / 3.0) == "0.3333333333"
    assert csv_cell(float("nan")) == "" and csv_cell(float("inf")) == ""
    assert csv_cell("ok") == "ok" and csv_cell(3) == 3
