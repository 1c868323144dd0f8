"""Hostile MJCF files: refused at load in one line (exit 2), within 20 s and 1 GB.

Every file is written inline and run through the installed ``sandbox`` console script
as a child process (peak RSS from ``wait4``). Without the checks of
:mod:`sandbox.physics.limits`, the bombs below take MuJoCo gigabytes while it parses
(``<replicate>``, ``<flexcomp>``, built-in meshes, height fields) or compiles
(textures, ``<size>``), and a wrong timestep runs 0 steps or for ever.
"""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path

import mujoco
import pytest
from hostile import Outcome, assert_refused, run_cli

from sandbox.errors import BadModel
from sandbox.physics.limits import (
    MAX_ASSET_BYTES,
    MAX_BUILTIN_PARAM,
    MAX_ELEMENTS,
    MAX_KEYS,
    MAX_MJCF_BYTES,
    MAX_MODEL_BYTES,
    MAX_USER_FIELDS,
    check_spec,
)
from sandbox.physics.model import Source, build

BODY = '<body><freejoint/><geom size="0.1"/></body>'


def mjcf(*, option: str = "", asset: str = "", world: str = BODY, head: str = "") -> str:
    options = f"<option {option}/>" if option else ""
    assets = f"<asset>{asset}</asset>" if asset else ""
    return f"<mujoco>{head}{options}{assets}<worldbody>{world}</worldbody></mujoco>"


UNTRUSTED = ("--max-memory", str(MAX_MODEL_BYTES // 2**20))
"""A file named on the command line is the user's own and may take half the machine's
memory; these files are hostile: they run under the limit of files from outside."""


def run_file(tmp_path: Path, text: str | bytes, *args: str, name: str = "m.xml") -> Outcome:
    """``sandbox run NAME ARGS`` on ``text`` written in ``tmp_path``, under the limit of
    files from outside (:data:`UNTRUSTED`) unless ``ARGS`` give ``--max-memory``."""
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    limit = () if "--max-memory" in args else UNTRUSTED
    return run_cli("run", name, *args, *limit, cwd=tmp_path)


def png_header(width: int, height: int) -> bytes:
    """The first chunk of a PNG claiming ``width`` x ``height`` RGB pixels (no data)."""
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    crc = struct.pack(">I", zlib.crc32(b"IHDR" + ihdr))
    return b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" + ihdr + crc


RANGE = "outside [1e-06, 0.1] s"


# -- the file's own timestep ------------------------------------------------------------
@pytest.mark.parametrize("value", ["0", "1e-300", "-0.01", "100", "5e-324", "1e-9", "0.5"])
def test_file_timestep_out_of_range(value, tmp_path):
    line = assert_refused(run_file(tmp_path, mjcf(option=f'timestep="{value}"')), RANGE)
    assert f'<option timestep="{float(value):g}">' in line and 'timestep="0.001"' in line


@pytest.mark.parametrize("value", ["nan", "-nan", "NaN"])
def test_file_timestep_nan(value, tmp_path):
    result = run_file(tmp_path, mjcf(option=f'timestep="{value}"'))
    assert_refused(result, "<option timestep=", "is not a number; give a finite value")


def test_nan_anywhere_is_refused_before_mujoco_warns(tmp_path):
    world = '<body pos="0 nan 1"><freejoint/><geom size="0.1"/></body>'
    assert_refused(run_file(tmp_path, mjcf(world=world)), "<body pos='0 nan 1'>")


def test_a_given_timestep_overrides_the_files(tmp_path):
    res = run_file(
        tmp_path, mjcf(option='timestep="0"'), "--timestep", "0.001", "--duration", "0.01"
    )
    assert res.code == 0 and "Traceback" not in res.err, res.err


def test_describe_refuses_a_zero_timestep_too(tmp_path):
    (tmp_path / "z.xml").write_text(mjcf(option='timestep="0"'))
    assert_refused(run_cli("describe", "z.xml", cwd=tmp_path), RANGE)


# -- bombs MuJoCo expands while parsing ---------------------------------------------------
NESTED = (
    '<replicate count="1000" offset="0 0 1"><replicate count="1000" offset="1 0 0">'
    '<replicate count="1000" offset="0 1 0"><body><geom size="0.1"/></body>'
    "</replicate></replicate></replicate>"
)


@pytest.mark.parametrize(
    "world, words",
    [
        (NESTED, [f"more than {MAX_ELEMENTS} elements"]),
        (
            '<flexcomp name="f" type="grid" count="3000 3000 1" spacing=".01 .01 .01" dim="2"/>',
            [f"more than {MAX_ELEMENTS} elements"],
        ),
        (
            '<composite type="cable" count="1000000 1 1" curve="s" size="1">'
            '<joint kind="main"/><geom type="capsule" size=".01"/></composite>',
            [f"more than {MAX_ELEMENTS} elements"],
        ),
    ],
    ids=["replicate-1e9", "flexcomp-9e6", "cable-1e6"],
)
def test_expansion_bombs(world, words, tmp_path):
    assert_refused(run_file(tmp_path, mjcf(world=world)), *words)


@pytest.mark.parametrize(
    "builtin, params",
    [
        ("plate", "10000 10000"),
        ("supersphere", "1000 1 1"),
        ("supertorus", "1000 0.3 1 1"),
        ("cone", "100000 1"),
    ],
)
def test_builtin_mesh_bombs(builtin, params, tmp_path):
    asset = f'<mesh name="m" builtin="{builtin}" params="{params}"/>'
    world = '<geom type="mesh" mesh="m"/>'
    line = assert_refused(run_file(tmp_path, mjcf(asset=asset, world=world)), "built-in mesh")
    assert f"(max {MAX_BUILTIN_PARAM})" in line


@pytest.mark.parametrize(
    "asset",
    ['nrow="100000" ncol="100000"', 'nrow="20000" ncol="20000"', 'nrow="8000" ncol="8000"'],
    ids=["1e10", "4e8", "6.4e7"],  # the last one compiles at 1.06 GB of RSS
)
def test_hfield_bombs(asset, tmp_path):
    xml = mjcf(
        asset=f'<hfield name="h" {asset} size="1 1 1 0.1"/>',
        world='<geom type="hfield" hfield="h"/>',
    )
    line = assert_refused(run_file(tmp_path, xml), "hfield 'h'")
    assert f"more than {MAX_MODEL_BYTES // 2**20} MB" in line


@pytest.mark.parametrize(
    "texture",
    [
        'type="2d" builtin="checker" width="100000" height="100000"',
        'type="cube" builtin="flat" width="30000"',
        'type="skybox" builtin="gradient" width="20000" height="20000"',
    ],
    ids=["2d", "cube", "skybox"],
)
def test_texture_bombs(texture, tmp_path):
    xml = mjcf(asset=f'<texture name="t" {texture}/>')
    assert_refused(run_file(tmp_path, xml), "texture 't'", "make it smaller")


# -- what compiling would allocate ------------------------------------------------------
@pytest.mark.parametrize(
    "size, words",
    [
        ('memory="100G"', ["<size memory>", f"max {MAX_MODEL_BYTES // 2**20} MB"]),
        ('njmax="100000000"', ["<size njmax>"]),
        ('nconmax="100000000"', ["<size nconmax>"]),
        ('nstack="1000000000"', ["<size nstack>"]),
        ('nkey="100000000"', [f"<size nkey=100000000> (max {MAX_KEYS})"]),
        ('nuserdata="100000000"', [f"<size nuserdata=100000000> (max {MAX_USER_FIELDS})"]),
        ('nuser_geom="100000000"', ["<size nuser_geom=100000000>"]),
    ],
)
def test_size_bombs(size, words, tmp_path):
    assert_refused(run_file(tmp_path, mjcf(head=f"<size {size}/>")), *words)


def test_png_height_field_claiming_1e10_pixels(tmp_path):
    (tmp_path / "big.png").write_bytes(png_header(100000, 100000))
    asset = '<hfield name="h" file="big.png" size="1 1 1 0.1"/>'
    xml = mjcf(asset=asset, world='<geom type="hfield" hfield="h"/>')
    assert_refused(run_file(tmp_path, xml), "hfield 'h' (file 'big.png')")


def test_png_texture_claiming_1e10_pixels(tmp_path):
    (tmp_path / "big.png").write_bytes(png_header(100000, 100000))
    xml = mjcf(asset='<texture name="t" type="2d" file="big.png"/>')
    assert_refused(run_file(tmp_path, xml), "texture 't' (file 'big.png')")


def test_asset_files_over_the_cap(tmp_path):
    with (tmp_path / "huge.stl").open("wb") as fh:
        fh.truncate(MAX_ASSET_BYTES + 2**20)  # sparse: costs no disk
    asset = '<mesh name="m" file="huge.stl"/>'
    line = assert_refused(
        run_file(tmp_path, mjcf(asset=asset, world='<geom type="mesh" mesh="m"/>'))
    )
    assert f"(max {MAX_ASSET_BYTES // 2**20} MB)" in line


def test_asset_that_is_a_device(tmp_path):
    asset = '<mesh name="m" file="/dev/zero"/>'
    xml = mjcf(asset=asset, world='<geom type="mesh" mesh="m"/>')
    assert_refused(run_file(tmp_path, xml), "asset '/dev/zero' is not a regular file")


# -- the file itself --------------------------------------------------------------------
@pytest.mark.parametrize(
    "text, words",
    [
        ("<mujoco><worldbody><body><geom type='sphere'/></body></worldbody>", ["malformed XML"]),
        ("", ["malformed XML (no element found"]),
        ("<mujoco><bogus/></mujoco>", ["cannot load MJCF 'm.xml'", "bogus"]),
        (bytes(range(256)) * 10, ["is not a text MJCF file"]),
        (
            '<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "aaaaaaaaaa">'
            '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]><mujoco model="&b;"/>',
            ["declares XML entities"],
        ),
        ('<mujoco><include file="/dev/zero"/></mujoco>', ["'/dev/zero' is not a regular file"]),
        ('<mujoco><include file="m.xml"/></mujoco>', ["includes", "twice"]),
    ],
    ids=["unclosed", "empty", "unknown-element", "binary", "entities", "include-zero", "loop"],
)
def test_bad_files(text, words, tmp_path):
    assert_refused(run_file(tmp_path, text), *words)


def test_a_file_over_the_size_cap(tmp_path):
    with (tmp_path / "big.xml").open("wb") as fh:
        fh.truncate(MAX_MJCF_BYTES + 1)
    assert_refused(run_cli("run", "big.xml", cwd=tmp_path), "is larger than 16 MB")


@pytest.mark.parametrize(
    "target, words",
    [
        ("missing.xml", ["unknown scene or file 'missing.xml'"]),
        (".", ["'.' is a directory"]),
        ("/dev/zero", ["'/dev/zero' is not a regular file"]),
        ("fifo.xml", ["'fifo.xml' is not a regular file"]),
    ],
)
def test_paths_that_are_not_mjcf_files(target, words, tmp_path):
    os.mkfifo(tmp_path / "fifo.xml")  # opening it would wait for a writer for ever
    assert_refused(run_cli("run", target, cwd=tmp_path), *words)


# -- within the limits, files still run -------------------------------------------------
def test_a_small_height_field_runs(tmp_path):
    asset = '<hfield name="h" nrow="100" ncol="100" size="1 1 1 0.1"/>'
    world = (
        '<geom type="hfield" hfield="h"/><body pos="0 0 1.5"><freejoint/><geom size=".1"/></body>'
    )
    res = run_file(tmp_path, mjcf(asset=asset, world=world), "--duration", "0.1")
    assert res.code == 0 and "Traceback" not in res.err, res.err


def test_the_largest_height_field_accepted_stays_far_under_1_gb(tmp_path):
    asset = '<hfield name="h" nrow="4000" ncol="4000" size="1 1 1 0.1"/>'  # 256 MB estimated
    world = (
        '<geom type="hfield" hfield="h"/><body pos="0 0 1.5"><freejoint/><geom size=".1"/></body>'
    )
    res = run_file(tmp_path, mjcf(asset=asset, world=world), "--duration", "0.01")
    assert res.code == 0 and "Traceback" not in res.err, res.err
    assert res.rss_bytes < 512 * 2**20, f"{res.rss_bytes / 2**20:.0f} MB"  # measured 0.31 GB


def test_check_spec_estimates_the_hfield_and_accepts_the_scenes(tmp_path):
    spec = mujoco.MjSpec.from_string(
        mjcf(asset='<hfield name="h" nrow="1000" ncol="1000" size="1 1 1 .1"/>')
    )
    check_spec(spec, tmp_path / "m.xml")  # 4 MB
    spec.hfields[0].nrow = spec.hfields[0].ncol = 9000  # 324 MB > 256 MB
    with pytest.raises(BadModel, match="hfield 'h' \\(9000 x 9000\\)"):
        check_spec(spec, tmp_path / "m.xml")
    import sandbox.scenes

    for scene in sandbox.scenes.SCENES.values():  # bundled files stay far under the caps
        source = Source.of_scene(scene)
        check_spec(mujoco.MjSpec.from_file(str(source.path)), source.path, timestep=False)
        build(source, scene.defaults())


# -- the user's own file on the command line ----------------------------------------------
ARENA = mjcf(head='<size memory="1G"/>')
"""A model whose arena is 1 GB (MuJoCo's gallery has three such: replicate/bunnies.xml,
leaves.xml, particle.xml)."""


def test_a_1_gb_arena_named_on_the_command_line_runs_and_is_said(tmp_path):
    """The teacher's own file is not a browser's upload: it gets the machine's memory, and
    a note says what it takes."""
    out = run_file(tmp_path, ARENA, "--duration", "0.01", "--max-memory", "4096")
    assert out.code == 0, out.err
    assert "takes about 1,024 MB to compile, mostly <size memory>" in out.err
    assert "allowed: 4,096 MB" in out.err


def test_a_lower_max_memory_refuses_it_naming_the_option(tmp_path):
    out = run_file(tmp_path, ARENA, "--duration", "0.01", "--max-memory", "200")
    line = assert_refused(out, "about 1,024 MB", "(max 200 MB)")
    assert "--max-memory" in line


def test_the_same_file_from_outside_keeps_its_limit(tmp_path):
    """What a browser sends or a recording carries opens through a source of the default
    limit: refused, the fix without the command line's option."""
    from sandbox.errors import BadModel
    from sandbox.physics.simulation import Simulation

    path = tmp_path / "arena.xml"
    path.write_text(ARENA)
    with pytest.raises(BadModel, match=r"\(max 256 MB\); make it smaller$"):
        Simulation(path)


def test_the_default_limit_of_the_command_line_is_half_the_machine():
    import psutil

    from sandbox.physics.limits import machine_bytes

    assert machine_bytes() == pytest.approx(psutil.virtual_memory().total / 2)
    assert machine_bytes(300) == 300 * 2**20
