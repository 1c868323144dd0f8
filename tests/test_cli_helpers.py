"""The CLI's shared helpers (``sandbox.cli.options`` and ``sandbox.cli.failures``), each
on its own: the values every command checks alike, and how a failure ends in one line."""

from __future__ import annotations

import mujoco
import pytest

from sandbox.cli.failures import (
    DEBUG_ENV,
    MAX_HELD_WARNINGS,
    held_mujoco_warnings,
    internal_error,
)
from sandbox.cli.options import (
    MAX_NAME_CHARS,
    check_folder,
    check_port_range,
    no_nul,
    pairs,
)
from sandbox.errors import BadOption, BadParameter


def test_pairs_split_name_and_value_and_strip_them():
    assert pairs(["speed_rpm=3000", " mass1_g = 5 ", "a=b=c"]) == {
        "speed_rpm": "3000",
        "mass1_g": "5",
        "a": "b=c",
    }
    assert pairs([]) == {}


@pytest.mark.parametrize(
    ("item", "words"),
    [
        ("speed_rpm", "--set expects NAME=VALUE"),
        ("=3000", "--set expects NAME=VALUE"),
        ("n" * (MAX_NAME_CHARS + 1) + "=1", "is not a parameter name and a number"),
        ("a=\x00", "is not a parameter name and a number"),
    ],
)
def test_pairs_refuse_what_is_not_name_equals_value(item, words):
    with pytest.raises(BadParameter, match=words):
        pairs([item])


def test_no_nul_refuses_a_nul_character_only(tmp_path):
    no_nul(tmp_path / "out.csv", "--out")
    with pytest.raises(BadOption, match="--out .* contains a NUL character; give another path"):
        no_nul(tmp_path / "a\x00b", "--out")


def test_check_folder_takes_a_folder_old_or_new_but_not_a_file(tmp_path):
    check_folder(tmp_path, "--out")
    check_folder(tmp_path / "not-yet", "--out")
    (tmp_path / "f").write_text("x")
    with pytest.raises(BadOption, match="--export .* is a file; give a folder"):
        check_folder(tmp_path / "f", "--export")
    with pytest.raises(BadOption, match="NUL"):
        check_folder(tmp_path / "a\x00b", "--export")


@pytest.mark.parametrize("port", [0, 8080, 65535])
def test_check_port_range_takes_0_to_65535(port):
    check_port_range(port)


@pytest.mark.parametrize("port", [-1, 65536, 99999])
def test_check_port_range_refuses_the_rest(port):
    with pytest.raises(BadOption, match=f"--port must be between 0 and 65535, got {port}"):
        check_port_range(port)


def test_held_mujoco_warnings_are_kept_on_one_line_then_the_handler_is_restored():
    before = mujoco.get_mju_user_warning()
    held: list[str] = []
    with held_mujoco_warnings(held):
        keep = mujoco.get_mju_user_warning()
        assert keep is not before
        keep("Nan, Inf or huge value in QACC at DOF 0.\nThe simulation is unstable.")
        for k in range(2 * MAX_HELD_WARNINGS):
            keep(f"warning {k}")
    assert mujoco.get_mju_user_warning() is before
    assert len(held) == MAX_HELD_WARNINGS
    assert held[0] == "Nan, Inf or huge value in QACC at DOF 0. The simulation is unstable."


def test_held_mujoco_warnings_restore_the_handler_after_an_error():
    before = mujoco.get_mju_user_warning()
    with pytest.raises(RuntimeError), held_mujoco_warnings([]):
        raise RuntimeError("boom")
    assert mujoco.get_mju_user_warning() is before


def test_internal_error_is_one_line_exit_1_naming_the_type_and_the_debug_switch(capsys):
    assert internal_error(ValueError("first line\nsecond line " + "x" * 400)) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("sandbox: error: internal error: ValueError: first line second line ")
    assert "... — please report it" in err  # the message is cut at 300 characters
    assert f"{DEBUG_ENV}=1 shows the traceback" in err
