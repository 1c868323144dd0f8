"""The sampling loop shared by ``sandbox run`` and ``sandbox bench``, and its writers."""

from __future__ import annotations

import csv
import json

import pytest

from sandbox.errors import Diverged
from sandbox.physics.simulation import Simulation
from sandbox.runner import chunks, simulate, write_rows


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
