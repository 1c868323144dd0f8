"""Limits on what a user's MJCF file and a timestep may cost, checked before MuJoCo
parses, allocates or compiles anything.

A file, like a recording, may be crafted or mistyped: :func:`read_mjcf` reads at most
:data:`MAX_MJCF_BYTES`; :func:`prescan` counts what ``<include>``, ``<replicate>``, height
fields and textures would expand to before MuJoCo allocates it; :func:`check_spec` prices
the parsed spec (assets, keyframes, user fields, model memory) and checks its timestep.
Every refusal is one :class:`~sandbox.errors.BadModel` or
:class:`~sandbox.errors.BadOption` line naming the limit and the fix.
"""

from __future__ import annotations

import math
import os
import stat
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import mujoco

from sandbox.errors import BadModel, BadOption, one_line, shown

MIN_TIMESTEP = 1e-6
"""Smallest timestep accepted [s]: below it a second of motion costs over a million steps
(minutes of CPU) and rounding, not the integrator, limits the accuracy."""

MAX_TIMESTEP = 0.1
"""Largest timestep accepted [s] (a scene may set a smaller ``max_timestep``)."""


MAX_MJCF_BYTES = 16 * 2**20
"""Largest MJCF file read, and largest total of the files it includes [bytes]: a model of a
mechanism is kilobytes; the cap bounds what a wrong path (``/dev/zero``, a video) costs
before it is refused."""

MAX_ASSET_BYTES = 256 * 2**20
"""Largest total size of the files a user's model loads (meshes, textures, height fields)
[bytes]."""

MAX_MODEL_BYTES = 256 * 2**20
"""Largest estimated size of what MuJoCo allocates for a model that comes from outside the
machine (a browser's upload, a recording's MJCF) before it steps
[bytes]: height fields (:data:`HFIELD_BYTES` a point), textures (:data:`TEXTURE_BYTES` a
pixel and face), mesh files (8 bytes a byte of file), the arena (``<size memory>``,
``njmax``, ``nconmax``, ``nstack``), user data and keyframes. Checked on the XML and the
MjSpec before MuJoCo parses or compiles (an hfield of 100000 x 100000 would take 160 GB):
an accepted model stays under about 350 MB of RSS. A file named on the command line is
the user's own: it gets :func:`machine_bytes` (``--max-memory``) instead."""

RAISE_HINT = "make it smaller, or give a larger --max-memory (MB) for your own file"
"""The fix a refusal names when the limit is the command line's (:func:`machine_bytes`)."""


def machine_bytes(megabytes: float | None = None) -> float:
    """What a model named on the command line may take to compile [bytes]: ``megabytes``
    when given (``--max-memory``), else half of the machine's memory (psutil, when
    installed: Linux, macOS and Windows alike), else 4 GB."""
    if megabytes is not None:
        return float(megabytes) * 2**20
    try:
        import psutil  # optional: the bench and test extras

        return float(psutil.virtual_memory().total) / 2
    except (ImportError, OSError, AttributeError):
        return 4.0 * 2**30


def estimate(path: Path) -> tuple[float, str]:
    """What the MJCF file ``path`` would take to compile [bytes], and what takes most of
    it (:func:`check_spec`'s estimate, nothing refused; (0, "") when it does not parse:
    the build says why)."""
    try:
        spec = mujoco.MjSpec.from_file(str(path))
        return check_spec(spec, path, timestep=False, limit=math.inf)
    except (ValueError, RuntimeError, mujoco.FatalError, BadModel, OSError):
        return 0.0, ""


def _fix(limit: float) -> str:
    return RAISE_HINT if limit != MAX_MODEL_BYTES else "make it smaller"


HFIELD_BYTES = 16
"""Bytes MuJoCo 4.0 takes per height field point while compiling (measured: 8000 x 8000
points peak at 1.06 GB RSS, 4000 x 4000 at 0.31 GB; the copies of the spec, the model and
the collision data)."""

TEXTURE_BYTES = 8
"""Bytes per pixel and face of a texture while compiling (measured: a 2000 x 2000 cube,
six faces, peaks at 0.20 GB RSS)."""

MAX_ELEMENTS = 100_000
"""Largest number of elements of a user's model once ``<replicate>``, ``<composite>`` and
``<flexcomp>`` are expanded (checked on the XML text, before MuJoCo parses it: three
nested replicates of 1000 would make 10⁹ bodies)."""

MAX_BUILTIN_PARAM = 200
"""Largest value of a built-in mesh's ``params`` (resolutions, edges: ``builtin="plate"
params="10000 10000"`` alone takes 5 GB while MuJoCo parses it)."""

MAX_KEYS = 10_000
"""Most keyframes (``<size nkey>``) a user's model may ask for."""

MAX_USER_FIELDS = 10_000
"""Most user numbers per element (``<size nuser_body ...>``) or in all (``nuserdata``)."""


def check_timestep(value: float) -> float:
    """Validate a timestep [s]: finite, between :data:`MIN_TIMESTEP` and :data:`MAX_TIMESTEP`."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise BadOption(
            f"timestep must be a positive number of seconds, got {value!r}; try --timestep 0.001"
        )
    if value < MIN_TIMESTEP:
        raise BadOption(
            f"timestep {value!r} s is too small (min {MIN_TIMESTEP:g} s); try --timestep 0.001"
        )
    if value > MAX_TIMESTEP:
        raise BadOption(
            f"timestep {value!r} s is too large (max {MAX_TIMESTEP:g} s); try --timestep 0.001"
        )
    return float(value)


def read_mjcf(path: Path, limit: int = MAX_MJCF_BYTES) -> str:
    """Text of an MJCF file, reading at most ``limit`` bytes (a device never ends).

    Raises:
        BadModel: not a regular file, unreadable, larger than ``limit``, or not UTF-8.
    """
    name = shown(str(path))
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise BadModel(f"{name} is not a regular file; give an MJCF file (.xml)")
        with open(path, "rb") as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise BadModel(
            f"cannot read {name}: {reason}; check the path and its permissions"
        ) from None
    if len(data) > limit:
        raise BadModel(
            f"{name} is larger than {limit // 2**20} MB; an MJCF file is text of a few "
            "kilobytes: check the path"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise BadModel(f"{name} is not a text MJCF file; give an .xml file") from None


@dataclass
class _Scan:
    """What :func:`prescan` counted so far, and the limit in bytes."""

    root: Path
    limit: float = MAX_MODEL_BYTES
    elements: int = 0
    read: int = 0
    files: int = 0
    seen: set[str] = field(default_factory=set)


def _numbers(text: str | None) -> list[float]:
    values = []
    for word in (text or "").split():
        try:
            value = float(word)
        except ValueError:
            continue
        if math.isfinite(value):
            values.append(value)
    return values


def _product(text: str | None) -> float:
    out = 1.0
    for value in _numbers(text):
        out *= max(1.0, value)
    return out


def prescan(path: Path, limit: float = MAX_MODEL_BYTES) -> None:
    """Refuse before MuJoCo parses it an MJCF whose parsing alone would take more than
    ``limit`` bytes (height fields, textures) or expand past :data:`MAX_ELEMENTS`.

    MuJoCo expands ``<replicate>``, ``<composite>``, ``<flexcomp>`` and built-in meshes
    while parsing; this counts them (following ``<include>``) on the bounded text.
    """
    scan = _Scan(root=path.parent, limit=limit)
    _scan_file(path, scan, 1.0, path)


def _scan_file(path: Path, scan: _Scan, mult: float, top: Path) -> None:
    scan.files += 1
    if scan.files > 100:
        raise BadModel(f"{shown(str(top))} includes more than 100 files; fix the <include>s")
    text = read_mjcf(path, MAX_MJCF_BYTES - scan.read)
    scan.read += len(text.encode("utf-8"))
    if "<!ENTITY" in text:
        raise BadModel(f"{shown(str(path))} declares XML entities; MJCF does not use them")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise BadModel(
            f"cannot load MJCF {shown(str(path))}: malformed XML ({one_line(str(exc))}); "
            "fix the file (see MuJoCo's XML reference)"
        ) from None
    _scan_element(root, scan, mult, top)


def _scan_element(elem: ET.Element, scan: _Scan, mult: float, top: Path) -> None:
    tag = elem.tag
    for key, value in elem.attrib.items():  # MuJoCo would print a warning and go on
        if any(word.lower().lstrip("+-") == "nan" for word in value.split()):
            raise BadModel(
                f"{shown(str(top))}: {shown(f'<{tag} {key}={value!r}>')} is not a number; "
                "give a finite value"
            )
    if tag == "replicate":
        mult *= _product(elem.get("count"))
    elif tag in ("composite", "flexcomp"):
        mult *= _product(elem.get("count"))
    elif tag == "mesh" and elem.get("builtin"):
        big = [v for v in _numbers(elem.get("params")) if abs(v) > MAX_BUILTIN_PARAM]
        if big:
            raise BadModel(
                f"{shown(str(top))}: built-in mesh {shown(elem.get('name') or '')} has "
                f"params {big[0]:g} (max {MAX_BUILTIN_PARAM}); use a smaller resolution"
            )
    elif tag in ("hfield", "texture"):  # MuJoCo allocates an hfield's points on parsing
        dims = (elem.get("nrow"), elem.get("ncol"))
        if tag == "texture":
            dims = (elem.get("width"), elem.get("height") or elem.get("width"))
        area = _product(dims[0]) * _product(dims[1])
        if tag == "hfield":
            cost = HFIELD_BYTES * area
        else:  # MuJoCo's default texture type is a cube: six faces
            cost = TEXTURE_BYTES * area * (1 if elem.get("type") == "2d" else 6)
        if cost > scan.limit:
            raise BadModel(
                f"{shown(str(top))}: {tag} {shown(elem.get('name') or '')} of "
                f"{' x '.join(d or '?' for d in dims)} would take more than "
                f"{scan.limit / 2**20:,.0f} MB; {_fix(scan.limit)}"
            )
    elif tag == "include" and elem.get("file"):
        target = scan.root / str(elem.get("file"))
        key = str(target.resolve()) if target.exists() else str(target)
        if key in scan.seen:
            raise BadModel(
                f"{shown(str(top))} includes {shown(str(target))} twice; fix the <include>s"
            )
        scan.seen.add(key)
        if target.exists():
            _scan_file(target, scan, mult, top)
    scan.elements += int(min(mult, 1e18))
    if scan.elements > MAX_ELEMENTS:
        raise BadModel(
            f"{shown(str(top))} expands to more than {MAX_ELEMENTS} elements (<replicate>, "
            "<composite> or <flexcomp> counts); use smaller counts"
        )
    for child in elem:
        _scan_element(child, scan, mult, top)


def _png_pixels(data: bytes) -> int:
    """width x height of a PNG header (0 if the bytes are not a PNG)."""
    if len(data) >= 24 and data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR":
        return int.from_bytes(data[16:20], "big") * int.from_bytes(data[20:24], "big")
    return 0


def _asset(spec: mujoco.MjSpec, name: str, folder: str, top: Path) -> tuple[int, int]:
    """(bytes, PNG pixels) of an asset file a model names (0, 0 when MuJoCo will not find
    it and says so itself)."""
    base = Path(spec.modelfiledir or top.parent)
    for candidate in (base / folder / name, base / name, Path(name)):
        try:
            info = os.stat(candidate)
        except (OSError, ValueError):
            continue
        if not stat.S_ISREG(info.st_mode):
            raise BadModel(f"{shown(str(top))}: asset {shown(name)} is not a regular file")
        with open(candidate, "rb") as fh:
            head = fh.read(24)
        return info.st_size, _png_pixels(head)
    return 0, 0


def check_spec(
    spec: mujoco.MjSpec, path: Path, *, timestep: bool = True, limit: float = MAX_MODEL_BYTES
) -> tuple[float, str]:
    """Refuse a user's parsed model that MuJoCo could not run sensibly, before compiling.

    Checks the file's own timestep (unless ``timestep`` is False: the caller overrides it)
    and bounds what compiling would allocate (``limit``: :data:`MAX_MODEL_BYTES` for a
    model from outside, :func:`machine_bytes` for the user's own; :data:`MAX_ASSET_BYTES`,
    :data:`MAX_KEYS`, :data:`MAX_USER_FIELDS`).

    Returns:
        The estimate [bytes] and what takes most of it (the user's own file is told).

    Raises:
        BadModel: naming the element, its value and the limit.
    """
    name = shown(str(path))
    if timestep:
        dt = float(spec.option.timestep)
        if not (math.isfinite(dt) and MIN_TIMESTEP <= dt <= MAX_TIMESTEP):
            raise BadModel(
                f'{name} sets <option timestep="{dt:g}">, outside [{MIN_TIMESTEP:g}, '
                f'{MAX_TIMESTEP:g}] s; write e.g. timestep="0.001" in the file '
                "(or give --timestep to 'sandbox run')"
            )
    if spec.nkey > MAX_KEYS:
        raise BadModel(f"{name} asks for <size nkey={spec.nkey}> (max {MAX_KEYS}); lower it")
    users = {
        "nuserdata": (spec.nuserdata, 1),
        "nuser_body": (spec.nuser_body, len(spec.bodies)),
        "nuser_jnt": (spec.nuser_jnt, len(spec.joints)),
        "nuser_geom": (spec.nuser_geom, len(spec.geoms)),
        "nuser_site": (spec.nuser_site, len(spec.sites)),
        "nuser_cam": (spec.nuser_cam, len(spec.cameras)),
        "nuser_tendon": (spec.nuser_tendon, len(spec.tendons)),
        "nuser_actuator": (spec.nuser_actuator, len(spec.actuators)),
        "nuser_sensor": (spec.nuser_sensor, len(spec.sensors)),
    }
    total = 0.0
    for key, (count, elements) in users.items():
        if count > MAX_USER_FIELDS:
            raise BadModel(
                f"{name} asks for <size {key}={count}> (max {MAX_USER_FIELDS}); lower it"
            )
        total += 8.0 * max(count, 0) * elements
    parts: list[tuple[str, float]] = [("user numbers", total)]
    parts.append(("<size memory>", max(float(spec.memory), 0.0)))
    parts.append(("<size njmax>", 1024.0 * max(spec.njmax, 0)))
    parts.append(("<size nconmax>", 1024.0 * max(spec.nconmax, 0)))
    parts.append(("<size nstack>", 8.0 * max(spec.nstack, 0)))
    per_key = 8.0 * 16 * (len(spec.joints) + len(spec.bodies) + len(spec.actuators) + 1)
    parts.append(("keyframes", per_key * max(spec.nkey, 0)))
    files = 0
    for h in spec.hfields:
        size, pixels = _asset(spec, h.file, spec.texturedir, path) if h.file else (0, 0)
        files += size
        points = max(float(h.nrow) * float(h.ncol), float(pixels), size / 4.0)
        what = f"file {shown(h.file)}" if h.file else f"{h.nrow} x {h.ncol}"
        parts.append((f"hfield {shown(h.name)} ({what})", HFIELD_BYTES * points))
    for t in spec.textures:
        size, pixels = 0, 0
        for file in [t.file, *list(t.cubefiles)]:
            if file:
                more, px = _asset(spec, file, spec.texturedir, path)
                size, pixels = size + more, pixels + px
        files += size
        faces = 6.0 if t.type != mujoco.mjtTexture.mjTEXTURE_2D else 1.0
        side = float(t.width) ** 2 if faces > 1 else 0.0  # a cube's face is width x width
        area = faces * max(float(t.width) * float(t.height), side)
        what = f"file {shown(t.file)}" if t.file else f"{t.width} x {t.height}"
        parts.append((f"texture {shown(t.name)} ({what})", TEXTURE_BYTES * max(area, pixels)))
    for m in spec.meshes:
        size = _asset(spec, m.file, spec.meshdir, path)[0] if m.file else 0
        files += size
        parts.append((f"mesh {shown(m.name)}", 8.0 * size + 4.0 * len(m.uservert)))
    if files > MAX_ASSET_BYTES:
        raise BadModel(
            f"{name} loads {files / 2**20:.0f} MB of asset files (max "
            f"{MAX_ASSET_BYTES // 2**20} MB); use smaller meshes and textures"
        )
    what, biggest = max(parts, key=lambda p: p[1])
    estimate = sum(p[1] for p in parts)
    if estimate > limit:
        raise BadModel(
            f"{name} would take about {estimate / 2**20:,.0f} MB to compile, mostly "
            f"{what} (max {limit / 2**20:,.0f} MB); {_fix(limit)}"
        )
    return estimate, what
