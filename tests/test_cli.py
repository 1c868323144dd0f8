"""CLI contract: commands, flags, CSV/JSON output, one-line errors (exit 2), divergence (3)."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest
from conftest import LESSON_FILE

from sandbox.cli import main
from sandbox.scenes import get_scene


def _err(capsys) -> str:
    return capsys.readouterr().err.strip()


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_list_names_the_rotor(capsys):
    assert main(["list"]) == 0
    assert "rotor" in capsys.readouterr().out


def test_version_names_sandbox_mujoco_viser_and_python(capsys):
    import mujoco

    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    out = capsys.readouterr().out.strip()
    assert out.startswith("sandbox 0.1.0 (MuJoCo ") and f"MuJoCo {mujoco.__version__}" in out
    assert "viser " in out and f"Python {sys.version_info[0]}.{sys.version_info[1]}" in out


def test_describe_json_schema(capsys):
    assert main(["describe", "rotor", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert {"name", "title", "effects", "params", "readouts"} <= set(info)
    assert info["name"] == "rotor"
    names = [p["name"] for p in info["params"]]
    assert names[:3] == ["speed_rpm", "defect_mass_g", "skew_deg"]
    # The contract keys, plus what the French page shows (label, hint, display_unit).
    shown = {"label", "hint", "display_unit"}
    for p in info["params"]:
        assert set(p) == {"name", "value", "unit", "min", "max", "doc"} | shown
    for r in info["readouts"]:
        assert set(r) == {"name", "unit", "doc"} | shown
    speed = info["params"][0]
    assert (speed["unit"], speed["display_unit"]) == ("rpm", "tr/min")
    assert speed["label"].startswith("Vitesse de rotation") and speed["hint"].endswith(".")
    readouts = {r["name"] for r in info["readouts"]}
    assert {
        "omega",
        "bearing_A",
        "bearing_B",
        "static_unbalance",
        "products_EF",
        "F_rot",
        "M_rot",
        "T",
        "P_acc",
        "sup_M_z",
    } <= readouts


def test_run_3000_rpm_is_four_times_1500(tmp_path, capsys):
    """Acceptance: bearing forces at 3000 rpm are 4x those at 1500 rpm within 1 %."""
    fast, slow = tmp_path / "r.csv", tmp_path / "s.csv"
    assert (
        main(["run", "rotor", "--set", "speed_rpm=3000", "--duration", "1", "--out", str(fast)])
        == 0
    )
    assert (
        main(["run", "rotor", "--set", "speed_rpm=1500", "--duration", "1", "--out", str(slow)])
        == 0
    )
    f, s = _rows(fast)[-1], _rows(slow)[-1]
    for key in ("bearing_A", "bearing_B"):
        assert float(f[key]) / float(s[key]) == pytest.approx(4.0, rel=1e-2)
    assert float(f["time"]) == pytest.approx(1.0)


def test_run_rate_sets_rows(tmp_path):
    out = tmp_path / "r.csv"
    assert main(["run", "rotor", "--duration", "0.5", "--rate", "20", "--out", str(out)]) == 0
    assert len(_rows(out)) == 11  # t = 0 and 10 samples


def test_run_json_output(tmp_path):
    out = tmp_path / "r.json"
    assert (
        main(
            [
                "run",
                "rotor",
                "--duration",
                "0.05",
                "--out",
                str(out),
                "--integrator",
                "implicitfast",
                "--timestep",
                "0.0005",
            ]
        )
        == 0
    )
    doc = json.loads(out.read_text())
    assert doc["integrator"] == "implicitfast" and doc["timestep"] == 0.0005
    assert doc["columns"][0] == "time" and len(doc["rows"][0]) == len(doc["columns"])
    assert doc["units"]["bearing_A"] == "N"


def test_arbitrary_mjcf_runs_with_generic_readouts(tmp_path, pendulum_xml):
    xml = pendulum_xml
    out = tmp_path / "p.csv"
    assert main(["run", str(xml), "--duration", "0.5", "--out", str(out)]) == 0
    rows = _rows(out)
    assert list(rows[0])[:6] == ["time", "T", "V", "P_ext", "P_int", "P_acc"]
    assert float(rows[0]["T"]) == 0.0  # starts from its keyframe at rest
    assert float(rows[-1]["T"]) > 0.0  # and falls under its own gravity


@pytest.mark.parametrize(
    "argv, words",
    [
        (["run", "nope"], ["unknown scene or file 'nope'", "rotor"]),
        (["run", "rotor", "--set", "bogus=1"], ["no parameter 'bogus'", "speed_rpm"]),
        (["run", "rotor", "--set", "speed_rpm=99999"], ["out of range", "6000"]),
        (["run", "rotor", "--set", "speed_rpm=fast"], ["needs a number"]),
        (["run", "rotor", "--set", "speed_rpm"], ["NAME=VALUE"]),
        (["run", "rotor", "--duration", "-1"], ["--duration", "positive"]),
        (["run", "rotor", "--timestep", "0"], ["--timestep", "positive"]),
        (["run", "rotor", "--integrator", "leapfrog"], ["leapfrog", "rk4"]),
        (["run", "rotor", "--out", "x.txt"], [".csv or .json"]),
        (["run", "."], ["directory"]),
        (["describe", "missing.xml"], ["unknown scene or file"]),
    ],
)
def test_bad_input_is_one_line_exit_2(argv, words, capsys):
    assert main(argv) == 2
    err = _err(capsys)
    assert len(err.splitlines()) == 1, err
    assert err.startswith("sandbox: error: ")
    for word in words:
        assert word in err


def test_malformed_mjcf_is_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body><geom type='sphere'/></body></worldbody>")
    assert main(["run", str(bad)]) == 2
    err = _err(capsys)
    assert len(err.splitlines()) == 1 and "cannot load MJCF" in err


def test_parameter_on_a_file_is_refused(capsys, pendulum_xml):
    xml = pendulum_xml
    assert main(["run", str(xml), "--set", "speed_rpm=1"]) == 2
    assert "no parameter" in _err(capsys)


def test_divergence_exits_3_and_keeps_rows(tmp_path, capsys, diverging_xml):
    xml = diverging_xml
    out = tmp_path / "d.csv"
    assert main(["run", str(xml), "--duration", "5", "--out", str(out)]) == 3
    err = _err(capsys)
    assert "diverged at t =" in err and "--timestep" in err
    assert len(_rows(out)) >= 1


def test_console_script_has_no_traceback():
    proc = subprocess.run(
        [sys.executable, "-m", "sandbox.cli", "run", "rotor", "--set", "mass1_g=-5"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "mass1_g" in proc.stderr


def test_bare_sandbox_accepts_host_and_port(monkeypatch):
    calls: dict[str, object] = {}

    def fake_serve(target, **options):
        calls.update(target=target, **options)

    monkeypatch.setattr("sandbox.web.serving.app.serve", fake_serve)
    assert main(["--port", "8133"]) == 0
    assert calls["target"] == "rotor" and calls["port"] == 8133
    assert main(["serve", "equilibrage", "--port", "8134"]) == 0
    assert calls["target"] == "rotor" and calls["lesson"] == "equilibrage"


def test_a_run_longer_than_one_recording_holds_keeps_a_replayable_file_and_says_so(tmp_path):
    """A recording is never lost: past the reader's limits the file is closed, and the
    run says where it stopped (one warning line, exit 0)."""
    out = tmp_path / "r.sbx"
    code = (
        "import sys; from sandbox.recording import limits; limits.MAX_RECORDS = 200; "
        "from sandbox.cli import main; sys.exit(main(sys.argv[1:]))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, "run", "rotor", "--duration", "2", "--record", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("sandbox: warning: --record") and "stopped at t = 0.9" in line
    from sandbox.recording import load

    assert load(out).complete


def test_list_shows_every_scene_and_lesson_in_one_column(capsys):
    """The longest lesson name ("inertie-equivalente") ran into its title."""
    from sandbox.lessons import lessons
    from sandbox.scenes import SCENES

    assert main(["list"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("  ")]
    names = [row.split()[0] for row in rows]
    assert set(names) == set(SCENES) | set(lessons())
    starts = {len(row) - len(row[2:].split(" ", 1)[1].lstrip()) for row in rows}
    assert len(starts) == 1, starts  # every title starts in the same column


@pytest.mark.parametrize(
    ("item", "says"),
    [
        ("mystery=2.5", "takes whole values, got '2.5'; give 0, 1, 2 or 3"),
        ("mystery=\uff12", "digits 0-9"),  # fullwidth 2
        ("mystery=\u0661", "digits 0-9"),  # Arabic-Indic 1
        ("mystery=1_0", "digits 0-9"),
        ("speed_rpm=\uff11\uff10\uff10\uff10", "digits 0-9"),
    ],
)
def test_whole_and_ascii_parameters(item, says, capsys):
    """Issue 22: a choice read 2.5 as wheel 2, and float() reads fullwidth digits."""
    assert main(["run", "wheel_balancer", "--duration", "0.01", "--set", item]) == 2
    err = _err(capsys)
    assert says in err and err.count("\n") == 0 and "Traceback" not in err


def test_run_record_says_where_it_wrote(tmp_path, capsys):
    out = tmp_path / "r.sbx"
    assert main(["run", "rotor", "--duration", "0.1", "--record", str(out)]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last == f"recording: 11 frames written to {out}; replay it with: sandbox replay {out}"


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="no named pipes here")
@pytest.mark.parametrize("option", ["--record", "--out"])
def test_a_named_pipe_is_refused_at_once(tmp_path, capsys, option):
    """Issue 22: --record to a FIFO waited for a reader forever (killed at 30 s)."""
    import os

    pipe = tmp_path / ("p.csv" if option == "--out" else "p.sbx")
    os.mkfifo(pipe)
    assert main(["run", "rotor", "--duration", "0.1", option, str(pipe)]) == 2
    assert "is a named pipe, not a file; give a file name" in _err(capsys)


def test_the_recorder_itself_refuses_a_named_pipe(tmp_path):
    import os

    from sandbox.physics.simulation import Simulation
    from sandbox.recording import BadRecording, Recorder

    if not hasattr(os, "mkfifo"):
        pytest.skip("no named pipes here")
    pipe = tmp_path / "p.sbx"
    os.mkfifo(pipe)
    with pytest.raises(BadRecording, match="named pipe"):
        Recorder(pipe, Simulation(get_scene("rotor")))


@pytest.mark.parametrize("frames_first", [False, True])
def test_a_full_disk_is_exit_2_naming_the_file_and_leaves_no_empty_recording(
    tmp_path, capsys, monkeypatch, frames_first
):
    """Issue 22: a full disk gave exit 1 "internal error" and a 0-byte recording. The
    disk fills at the first frame (nothing worth keeping: removed) or later (the frames
    written stay, for --salvage)."""
    import errno

    from sandbox import recording

    real = recording.Recorder.frame
    calls = {"n": 0}

    def frame(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] > (5 if frames_first else 0):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(recording.Recorder, "frame", frame)
    out = tmp_path / "r.sbx"
    assert main(["run", "rotor", "--duration", "0.5", "--record", str(out)]) == 2
    err = _err(capsys)
    assert err.startswith(f"sandbox: error: no space left to write '{out}' (")
    assert " MB free on its disk); free some space" in err and "\n" not in err
    assert out.exists() == frames_first
    if frames_first:
        assert recording.load(out, salvage=True).times.size == 5


def test_a_ctrl_c_while_the_command_loads_ends_it_quietly():
    """Issue 22: Ctrl-C in the first half second printed a KeyboardInterrupt traceback
    through numpy's imports. The installed command imports the CLI inside its guard."""
    code = (
        "import builtins, sys\n"
        "real = builtins.__import__\n"
        "def interrupted(name, *a, **k):\n"
        "    if name == 'sandbox.cli':\n"
        "        raise KeyboardInterrupt\n"
        "    return real(name, *a, **k)\n"
        "builtins.__import__ = interrupted\n"
        "from sandbox.launch import main\n"
        "sys.exit(main(['list']))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 130
    assert done.stderr == "sandbox: interrupted\n" and "Traceback" not in done.stderr


def test_the_installed_command_is_the_guarded_one():
    from pathlib import Path

    project = (Path(__file__).parents[1] / "pyproject.toml").read_text(encoding="utf-8")
    assert '\nsandbox = "sandbox.launch:main"\n' in project


@pytest.fixture
def opened_lessons(monkeypatch):
    """Lesson files opened by path in this test only (the catalogue is process-wide)."""
    from sandbox.lessons import registry as lessons

    monkeypatch.setattr(lessons, "_opened", {}, raising=False)
    lessons.catalogue.cache_clear()
    yield lessons
    monkeypatch.undo()
    lessons.catalogue.cache_clear()


def _serving(monkeypatch) -> dict[str, object]:
    calls: dict[str, object] = {}
    monkeypatch.setattr(
        "sandbox.web.serving.app.serve",
        lambda target, **options: calls.update(target=target, **options),
    )
    return calls


def test_serve_a_lesson_file_opens_that_lesson_with_its_scene(
    monkeypatch, tmp_path, opened_lessons
):
    path = tmp_path / "ma-lecon.md"
    path.write_text(LESSON_FILE, encoding="utf-8")
    calls = _serving(monkeypatch)
    monkeypatch.chdir(tmp_path)
    assert main(["serve", "ma-lecon.md", "--port", "8135"]) == 0
    assert calls["target"] == "compressor"  # the lesson's scene, not the file as MJCF
    assert calls["lesson"] == str(path.resolve())  # absolute: each worker opens it again
    assert opened_lessons.catalogue().lessons["ma-lecon"].title == "Ma leçon à moi"


@pytest.mark.parametrize(
    "text, needle",
    [
        (LESSON_FILE.replace("speed_rpm", "no_such_param"), "ma-lecon.md:7: preset names no"),
        (LESSON_FILE.replace("scene: compressor", "scene: nowhere"), "unknown scene 'nowhere'"),
        ("no front matter\n", "ma-lecon.md:1: a lesson starts with a front matter"),
        (None, "no lesson file"),
    ],
)
def test_a_bad_lesson_file_is_refused_in_one_line(
    monkeypatch, capsys, tmp_path, opened_lessons, text, needle
):
    path = tmp_path / "ma-lecon.md"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    monkeypatch.setattr("sandbox.web.serving.app.serve", lambda target, **kw: pytest.fail("served"))
    assert main(["serve", str(path)]) == 2
    err = _err(capsys)
    assert needle in err and len(err.splitlines()) == 1, err
    assert "mjcf" not in err.lower()


def test_a_lesson_named_like_a_scene_opens_with_the_lesson_prefix(monkeypatch, capsys):
    from sandbox.lessons import lessons
    from sandbox.scenes import SCENES

    assert "gyroscope" in SCENES and "gyroscope" in lessons()  # the shipped clash
    calls = _serving(monkeypatch)
    assert main(["serve", "gyroscope"]) == 0
    assert (calls["target"], calls["lesson"]) == ("gyroscope", None)  # the scene wins
    assert main(["serve", "lesson:gyroscope"]) == 0
    assert (calls["target"], calls["lesson"]) == ("gyroscope", "gyroscope")
    assert main(["serve", "lesson:equilibrage"]) == 0
    assert (calls["target"], calls["lesson"]) == ("rotor", "equilibrage")
    assert main(["serve", "lesson:rotor"]) == 2
    err = _err(capsys)
    assert "unknown lesson 'rotor'" in err and "equilibrage" in err


def test_serve_help_names_the_lesson_prefix_and_lesson_files(capsys):
    with pytest.raises(SystemExit):
        main(["serve", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "lesson:NAME" in out and "FILE.md" in out


@pytest.mark.parametrize(
    "scene, values, motion",
    [
        ("compressor", ["speed_rpm=6000"], "free"),
        ("compressor", ["speed_rpm=6000", "ramp_s=0.05"], "imposed"),
        ("engine", ["speed_rpm=6000"], "free"),
        ("robot_axis", ["profile=3", "sine_Nm=2", "sine_Hz=9"], None),
        ("robot_axis", ["profile=1", "ramp_s=0", "eta=0.8"], None),
        ("robot_axis", ["eta=0.8"], None),
    ],
)
def test_every_row_of_a_run_is_one_instant_p_ext_is_the_torque_times_the_speed(
    tmp_path, scene, values, motion
):
    """Issue 36: a student who multiplies two numbers of one row gets the third. The
    compressor's and the engine's P_ext is the actuator's torque times ω, the actuator's
    torque C_mot + J θ'' (the rotor's inertia, J = 0,02 kg·m², is in T); the robot axis's
    P_motor and P_ext are C_m ω_m, C_m the torque applied from the row's instant on."""
    import csv

    out = tmp_path / "rows.csv"
    args = ["run", scene, "--duration", "0.1", "--rate", "500", "--out", str(out)]
    for v in values:
        args += ["--set", v]
    if motion is not None:
        args += ["--motion", motion]
    assert main(args) == 0
    with out.open() as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    assert len(rows) >= 50
    peak = max(abs(r["P_ext"]) for r in rows)
    assert peak > 0
    for r in rows:
        if scene == "robot_axis":
            power = r["C_m"] * r["omega_m"]
            assert abs(r["P_motor"] - power) <= 1e-9 * peak, r["time"]
        else:
            power = r["actuator_torque"] * r["omega"]
        assert abs(r["P_ext"] - power) <= 1e-9 * peak, r["time"]
