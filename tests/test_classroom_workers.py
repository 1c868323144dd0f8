"""A classroom run worker by worker (sandbox.bench.classroom.workers)."""

from __future__ import annotations

import math

import pytest

from sandbox.bench.classroom.workers import by_worker, fps_ratio, worker_lines


def test_each_browser_counts_in_the_worker_that_served_it() -> None:
    # browsers on ports 5001..5004; worker 11 served three, worker 22 one; port 5005 unknown
    fps = [36.0, 25.0, 34.0, 35.0, 50.0]
    ports = [5001, 5002, 5003, 5004, 5005]
    owner = {5001: 11, 5002: 22, 5003: 11, 5004: 11}
    cores = {(11, 1): 0.8, (11, 2): 0.13, (22, 3): 0.79, (22, 4): 0.12, (33, 5): 0.5}
    first, second = by_worker(fps, ports, owner, cores)
    assert (first["pid"], first["browsers"], second["pid"], second["browsers"]) == (11, 3, 22, 1)
    assert first["fps_median"] == 35.0 and first["fps_min"] == 34.0
    assert first["cpu_cores"] == pytest.approx(0.93)
    assert first["busiest_thread_cores"] == 0.8
    # its CPU over the frames its browsers got: 0.93 s of CPU a second for 105 frames
    assert first["cpu_ms_per_frame"] == pytest.approx(930.0 / 105.0)
    assert second["cpu_ms_per_frame"] == pytest.approx(910.0 / 25.0)


def test_browsers_without_a_known_port_and_silent_workers_are_left_out() -> None:
    assert by_worker([40.0], [None], {}, {(1, 1): 0.5}) == []
    only = by_worker([0.0], [7], {7: 3}, {})
    assert only[0]["cpu_cores"] == 0.0 and math.isnan(only[0]["cpu_ms_per_frame"])
    with pytest.raises(ValueError):  # one port per browser, or the figures would shift
        by_worker([1.0, 2.0], [7], {7: 3}, {})


def test_the_report_shows_workers_only_when_there_are_several() -> None:
    one = by_worker([50.0], [1], {1: 9}, {(9, 1): 0.4})
    assert worker_lines(one) == []
    two = by_worker([36.0, 25.0], [1, 2], {1: 9, 2: 8}, {(9, 1): 0.8, (8, 1): 0.8})
    lines = worker_lines(two)
    assert len(lines) == 2
    assert "1 browsers, frames/s median 25.0 (min 25.0), 0.80 cores" in lines[0]
    assert "32.00 ms per frame" in lines[0] and "22.22 ms per frame" in lines[1]


def test_the_workers_frame_rate_ratio_is_one_when_they_serve_alike() -> None:
    from sandbox.bench.classroom.suite import figure

    even = by_worker([50.0, 50.0], [1, 2], {1: 9, 2: 8}, {})
    uneven = by_worker([36.0, 25.0, 34.0, 26.0], [1, 2, 3, 4], {1: 9, 2: 8, 3: 9, 4: 8}, {})
    assert fps_ratio(even) == 1.0
    assert fps_ratio(uneven) == pytest.approx(25.5 / 35.0)
    assert math.isnan(fps_ratio(even[:1])) and math.isnan(fps_ratio([]))
    run = {"scene": "heavy_gyroscope", "main": {"workers": uneven}}
    assert figure(run, "worker_fps_ratio") == pytest.approx(25.5 / 35.0)
    assert math.isnan(figure({"main": {}}, "worker_fps_ratio"))  # a run saved before
