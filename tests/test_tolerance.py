"""``sandbox run X --tolerance E``: the cheapest measured setting that reaches E."""

from __future__ import annotations

import pytest

import sandbox.scenes  # noqa: F401  (the registry)
from sandbox.accuracy import cheapest
from sandbox.bench import load_results
from sandbox.cli import main


def test_the_cheapest_admissible_run_reaching_the_tolerance_is_chosen():
    result = load_results("compressor")
    assert result is not None
    for tol in (1e-2, 1e-4, 5e-5):
        run = cheapest(result, tol)
        assert run is not None and run.error <= tol and result.admissible(run)
        cheaper = [r for r in result.runs if r.cpu_per_sim_s < run.cpu_per_sim_s]
        assert all(r.error > tol or not result.admissible(r) for r in cheaper)
    assert cheapest(result, 1e-9) is None


def test_run_says_what_it_chose_and_uses_it(capsys):
    argv = ["run", "compressor", "--motion", "free", "--tolerance", "1e-4", "--duration", "0.01"]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert "--tolerance 0.0001: rk4 at dt = 0.0001 s (error 6.2e-05 on pilon" in err
    assert "compressor: 0.01 s simulated (rk4, dt = 0.0001 s)" in out  # and it ran so


def test_an_imposed_motion_meets_any_tolerance_exactly(capsys):
    """The compressor's default is the imposed motion: nothing to choose, it is exact."""
    assert main(["run", "compressor", "--tolerance", "1e-6", "--duration", "0.01"]) == 0
    out, err = capsys.readouterr()
    assert "--tolerance 1e-06: the imposed motion is exact" in err
    assert "imposed motion, exact" in out


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--tolerance", "1e-9"], "no measured setting of compressor reaches --tolerance 1e-09"),
        (["--tolerance", "1e-4", "--timestep", "0.001"], "not both"),
        (["--tolerance", "2"], "in (0, 1)"),
    ],
)
def test_refusals_are_one_line(capsys, extra, words):
    assert main(["run", "compressor", "--motion", "free", *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and words in err, err
