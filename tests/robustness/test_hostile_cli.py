"""Hostile command lines: every case is refused in one line (exit 2), never a traceback.

Each case runs the installed ``sandbox`` console script as a child process with a 20 s
timeout; its peak memory is read from ``wait4`` and must stay under 1 GB. The refusal
names the fix; an output file is created before the first step (under a temporary name
renamed at the end), so a refusal or an interruption leaves no file behind.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from hostile import SANDBOX, TIMEOUT, assert_refused, run_cli

from sandbox.cli import DEBUG_ENV, MAX_WORKERS, main
from sandbox.errors import BadOption, choices
from sandbox.physics.limits import MIN_TIMESTEP
from sandbox.runner import MAX_ROWS, MAX_STEPS, check_run
from sandbox.scenes import SCENES

DIVERGING = """<mujoco><option timestep="0.05" integrator="Euler"/><worldbody><body>
<joint type="slide" axis="1 0 0" stiffness="1e6"/><geom type="sphere" size="0.1" mass="0.001"/>
</body></worldbody><keyframe><key qpos="0.1"/></keyframe></mujoco>"""


# -- names ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "target, words",
    [
        ("a" * 5000, ["(5000 characters)", "too long for a file name", "rotor"]),
        ("a/" * 2500, ["(5000 characters)", "rotor"]),
        ("a/../b", ["unknown scene or file 'a/../b'", "rotor"]),
        ("..", ["'..' is a directory", "MJCF file"]),
        ("/", ["'/' is a directory"]),
        ("x\ny", ["'x\\ny'", "unknown scene or file"]),
        ("", ["unknown scene or file ''"]),
        ("/dev/zero", ["'/dev/zero' is not a regular file"]),
        ("/proc/self/mem", ["cannot read '/proc/self/mem'"]),
    ],
    ids=[
        "5000-chars",
        "5000-slashes",
        "dotdot-inside",
        "dotdot",
        "root",
        "newline",
        "empty",
        "dev-zero",
        "proc-mem",
    ],
)
def test_hostile_scene_names(target, words, tmp_path):
    line = assert_refused(run_cli("run", target, cwd=tmp_path), *words)
    assert len(line) < 400


@pytest.mark.parametrize("command", ["run", "describe"])
def test_nul_in_a_name(command, capsys):
    """A NUL cannot cross argv; main() gets it from a script or a wrapper."""
    assert main([command, "rot\x00or"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "sandbox: error: unknown scene or file 'rot\\x00or'; scenes: "
        f"{choices(SCENES)}, or give the path of an MJCF file"
    )
    assert "compressor, engine, gyroscope" in err  # every scene, in alphabetical order


# -- numbers ----------------------------------------------------------------------------
BUDGET = f"max {MAX_STEPS:,}"


@pytest.mark.parametrize(
    "options, words",
    [
        (["--duration", "1e308"], [BUDGET, "simulate at most 100000 s"]),
        (["--duration", "1e300"], [BUDGET, "1e+302 steps"]),
        (["--duration", "nan"], ["--duration must be a finite", "'nan'"]),
        (["--duration", "inf"], ["--duration must be a finite", "'inf'"]),
        (["--duration", "1e999"], ["--duration must be a finite"]),
        (["--duration", "-1"], ["--duration must be a finite zero or positive number"]),
        (["--duration", "soon"], ["--duration must be a number, got 'soon'"]),
        (["--timestep", "1e-300"], ["too small (min 1e-06 s)", "--timestep 0.001"]),
        (["--timestep", "5e-324"], ["too small (min 1e-06 s)"]),
        (["--timestep", "1e-9"], ["too small (min 1e-06 s)"]),
        (["--timestep", "1"], ["too large"]),
        (["--timestep", "nan"], ["--timestep must be a finite positive number"]),
        (["--timestep", "-0.001"], ["--timestep must be a finite positive number"]),
        (["--timestep", "1e-6", "--duration", "20"], [BUDGET, "simulate at most 10 s"]),
        (["--rate", "5e-324"], ["--rate 5e-324 is outside [0.001, 1e+06]", "--rate 100"]),
        (["--rate", "1e308"], ["is outside [0.001, 1e+06]"]),
        (["--rate", "0"], ["--rate must be a finite positive number, got '0'"]),
        (["--rate", "-5"], ["--rate must be a finite positive number"]),
        (["--rate", "nan"], ["--rate must be a finite positive number"]),
        (["--duration", "100000", "--rate", "100"], [f"max {MAX_ROWS:,}", "smaller --rate"]),
        (["--set", "x" * 5000 + "=1"], ["(5002 characters)", "sandbox describe"]),
        (["--set", "speed_rpm=nan"], ["speed_rpm"]),
        (["--set", "speed_rpm=1e308"], ["speed_rpm", "6000"]),
        (["--integrator", "x" * 5000], ["invalid choice"]),
        (["--bogus"], ["unrecognized arguments: --bogus"]),
    ],
    ids=lambda v: " ".join(v)[:30] if isinstance(v, list) else None,
)
def test_hostile_numbers(options, words, tmp_path):
    assert_refused(run_cli("run", "rotor", *options, cwd=tmp_path), *words)


def test_check_run_bounds_what_a_run_costs():
    assert check_run(1.0, 100.0, 1e-3) == (1000, 10)
    assert check_run(MAX_STEPS * 1e-3, 1.0, 1e-3)[0] == MAX_STEPS  # the budget itself runs
    with pytest.raises(BadOption, match="simulate at most 10000 s"):
        check_run(MAX_STEPS * 1e-3 * 1.001, 1.0, 1e-3)
    with pytest.raises(BadOption, match="outside"):
        check_run(1.0, 5e-324, MIN_TIMESTEP)


# -- outputs ----------------------------------------------------------------------------
def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".part" in p.name)


@pytest.mark.parametrize(
    "out, words",
    [
        ("/proc/r.csv", ["cannot create --out '/proc/r.csv'", "give another path"]),
        ("/sys/r.csv", ["cannot create --out '/sys/r.csv'", "give another path"]),
        ("plain/r.csv", ["'plain' is a file, not a folder"]),
        ("missing/r.csv", ["folder 'missing' of --out does not exist; create it first"]),
        ("folder.csv", ["is a directory; give a file name such as run.csv"]),
        ("r.txt", ["must end in .csv or .json"]),
        ("y" * 5000 + ".csv", ["(5004 characters)", "give another path"]),
    ],
    ids=["proc", "sys", "under-a-file", "missing-folder", "a-directory", "suffix", "long"],
)
def test_hostile_outputs_are_refused_before_simulating(out, words, tmp_path):
    (tmp_path / "plain").write_text("a file\n")
    (tmp_path / "folder.csv").mkdir()
    res = run_cli(
        "run",
        "rotor",
        "--duration",
        "1e4",
        "--rate",
        "1",
        "--timestep",
        "1e-3",
        "--out",
        out,
        cwd=tmp_path,
    )
    assert_refused(res, *words)
    assert res.seconds < 10  # 10^7 steps were not simulated first
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.csv", "plain"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in a read-only folder")
def test_unwritable_folder(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir(mode=0o555)
    assert_refused(run_cli("run", "rotor", "--out", "ro/r.csv", cwd=tmp_path), "cannot be written")


def test_record_under_a_file(tmp_path):
    (tmp_path / "plain").write_text("x")
    res = run_cli("run", "rotor", "--record", "plain/r.sbx", cwd=tmp_path)
    assert_refused(res, "--record 'plain/r.sbx'", "not a folder")


def test_a_refusal_keeps_the_existing_output(tmp_path):
    old = tmp_path / "r.csv"
    old.write_text("keep me\n")
    res = run_cli("run", "rotor", "--set", "speed_rpm=99999", "--out", "r.csv", cwd=tmp_path)
    assert_refused(res, "speed_rpm")
    assert old.read_text() == "keep me\n" and _leftovers(tmp_path) == []


def test_rows_are_streamed_and_renamed(tmp_path):
    res = run_cli(
        "run", "rotor", "--duration", "2", "--rate", "50", "--out", "r.json", cwd=tmp_path
    )
    assert res.code == 0 and "101 rows written to r.json" in res.out, res.err
    import json

    doc = json.loads((tmp_path / "r.json").read_text())
    assert len(doc["rows"]) == 101 and doc["rows"][-1][0] == pytest.approx(2.0)
    assert _leftovers(tmp_path) == []


def test_interrupt_exits_130_quietly_and_leaves_no_file(tmp_path):
    proc = subprocess.Popen(
        [SANDBOX, "run", "rotor", "--duration", "90", "--timestep", "1e-5", "--out", "r.csv"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + TIMEOUT
    while not _leftovers(tmp_path) and time.monotonic() < deadline:
        time.sleep(0.05)  # the output is open: the simulation runs
    assert _leftovers(tmp_path), "the output was not opened before simulating"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=TIMEOUT)
    assert proc.returncode == 130 and "Traceback" not in err and "error" not in err
    assert list(tmp_path.iterdir()) == []


def test_divergence_still_exits_3(tmp_path):
    (tmp_path / "d.xml").write_text(DIVERGING)
    res = run_cli("run", "d.xml", "--duration", "5", "--out", "d.csv", cwd=tmp_path)
    assert_refused(res, "diverged at t =", "--timestep", code=3)
    assert (tmp_path / "d.csv").read_text().count("\n") >= 2  # header and rows kept


# -- serve ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "options, words",
    [
        (["--workers", "100000"], [f"between 1 and {MAX_WORKERS}", "100000"]),
        (["--workers", "0"], [f"between 1 and {MAX_WORKERS}"]),
        (["--port", "99999999"], ["--port must be between 0 and 65535"]),
        (["--public-url", "javascript:" + "a" * 5000], ["--public-url must be an http://"]),
    ],
    ids=["workers-huge", "workers-0", "port", "public-url"],
)
def test_hostile_serve_options(options, words, tmp_path):
    assert_refused(run_cli("serve", "rotor", *options, cwd=tmp_path), *words)


def test_serve_of_a_zero_timestep_file_exits_at_start(tmp_path):
    (tmp_path / "z.xml").write_text(
        '<mujoco><option timestep="0"/><worldbody><body><freejoint/>'
        '<geom size="0.1"/></body></worldbody></mujoco>'
    )
    res = run_cli("serve", "z.xml", "--port", "0", cwd=tmp_path)
    assert_refused(res, '<option timestep="0">', "[1e-06, 0.1] s", 'timestep="0.001"')


# -- the last resort --------------------------------------------------------------------
def test_unexpected_exception_is_one_line_exit_1(monkeypatch, capsys):
    def broken() -> int:
        raise RuntimeError("kaboom\nsecond line")

    monkeypatch.setattr("sandbox.cli.command.cmd_list", broken)
    monkeypatch.delenv(DEBUG_ENV, raising=False)
    assert main(["list"]) == 1
    err = capsys.readouterr().err
    assert err == (
        "sandbox: error: internal error: RuntimeError: kaboom second line — please report it "
        f"(with the command; {DEBUG_ENV}=1 shows the traceback)\n"
    )


def test_memory_error_is_one_line_and_debug_reraises(monkeypatch, capsys):
    def broken() -> int:
        raise MemoryError()

    monkeypatch.setattr("sandbox.cli.command.cmd_list", broken)
    monkeypatch.delenv(DEBUG_ENV, raising=False)
    assert main(["list"]) == 1
    assert capsys.readouterr().err.startswith("sandbox: error: internal error: MemoryError: ")
    monkeypatch.setenv(DEBUG_ENV, "1")
    with pytest.raises(MemoryError):
        main(["list"])


def test_keyboard_interrupt_in_a_command_is_130(monkeypatch, capsys):
    def interrupted() -> int:
        raise KeyboardInterrupt

    monkeypatch.setattr("sandbox.cli.command.cmd_list", interrupted)
    assert main(["list"]) == 130
    assert capsys.readouterr().err == ""


# -- folders and files of the other commands --------------------------------------------
def test_bench_out_with_a_name_too_long(tmp_path):
    res = run_cli("bench", "rotor", "--out", "b" * 5000, cwd=tmp_path)
    assert_refused(res, "--out 'bbbb", "(5000 characters): File name too long")


@pytest.mark.parametrize(
    "options, words",
    [
        (
            ["--csv", "c" * 5000 + ".csv"],
            ["(5004 characters)", "give a file in an existing folder"],
        ),
        (["--csv", "plain/r.csv"], ["--csv 'plain/r.csv': give a file in an existing folder"]),
        (["--export", "plain"], ["--export 'plain' is a file; give a folder"]),
    ],
    ids=["csv-long", "csv-under-a-file", "export-a-file"],
)
def test_replay_outputs(options, words, tmp_path):
    (tmp_path / "plain").write_text("x")
    made = run_cli("run", "rotor", "--duration", "0.1", "--record", "r.sbx", cwd=tmp_path)
    assert made.code == 0, made.err
    assert_refused(run_cli("replay", "r.sbx", *options, cwd=tmp_path), *words)


@pytest.mark.parametrize(
    "options, line",
    [
        (["--out", "r\x00.csv"], "--out 'r\\x00.csv' contains a NUL character; give another path"),
        (
            ["--record", "r\x00.sbx"],
            "--record 'r\\x00.sbx' contains a NUL character; give another path",
        ),
        (
            ["--out", "same.csv", "--record", "same.csv"],
            "--out and --record name the same file 'same.csv'; give two names",
        ),
    ],
    ids=["nul-out", "nul-record", "same-file"],
)
def test_output_names_in_process(options, line, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["run", "rotor", *options]) == 2
    assert capsys.readouterr().err == f"sandbox: error: {line}\n"
    assert list(tmp_path.iterdir()) == []
