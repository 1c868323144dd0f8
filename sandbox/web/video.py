"""A recording as a video for slides (``sandbox replay FILE --video OUT.mp4|OUT.gif``):
the mechanism, the scene's arrows with their labels, the key readouts in large French
text, the simulated time, and optionally a strip of readouts against time with a moving
cursor — what the page shows a class, on any laptop without a GPU or a display.

Drawing: MuJoCo's own offscreen renderer (EGL, else OSMesa, on a Linux machine without a
display; CGL on macOS; a hidden window on Windows), the camera the page uses (the
scene's side, any up direction), the arrows added to its scene as MuJoCo arrows; text
with Pillow (matplotlib's DejaVu Sans, shipped with it); the strip drawn once by
matplotlib, its cursor per frame. Encoding: ffmpeg from the ``imageio-ffmpeg`` package
(the ``video`` extra; no system ffmpeg). A frame shows the recorded state carried
forward to its instant (:class:`~sandbox.physics.display.DisplayState`), so a slow
motion (``--speed 0.1``) is smooth rather than repeating recorded frames.

The output is written to a temporary file beside it and renamed at the end: a failure
leaves no half-written video.
"""

from __future__ import annotations

import contextlib
import math
import os
import platform
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import BadOption, shown
from sandbox.physics.display import DisplayState
from sandbox.physics.snapshot import Snapshot
from sandbox.recording import Recording, set_state
from sandbox.replay import open_simulation
from sandbox.scenes.base import as_scene
from sandbox.web.arrows import arrow_points, auto_factor, caption
from sandbox.web.projector import key_readouts, overlay_lines
from sandbox.web.renderer import mechanism_size
from sandbox.web.text import number
from sandbox.web.view import camera_pose, scene_view

MIN_SIZE, MAX_SIZE = (160, 120), (3840, 2160)
FPS_RANGE = (1, 120)
CAMERAS = ("scene", "front", "side", "top")
"""``--camera`` presets: the page's view of the scene, or along −y, +x, −z (z up)."""
DIRECTIONS = {"front": (0.0, -1.0, 0.0), "side": (1.0, 0.0, 0.0), "top": (0.0, 0.0, 1.0)}
MP4_SPEED = ["-preset", "veryfast"]
"""x264's faster preset: the encoder shares a 2-core laptop with the drawing (its default
took 40 % of the time of a 1280×720 clip), for a file about 15 % larger."""
GIF_PALETTE = ["-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse", "-loop", "0"]
STRIP = 0.28
"""Height of the plot strip, as a fraction of the frame."""
BACKGROUND = (255, 255, 255)


class VideoError(BadOption):
    """A video that cannot be made here (a missing backend): one line, exit 2."""


@dataclass(frozen=True)
class VideoOptions:
    """What ``--video`` asks for, checked (see :func:`check`)."""

    out: Path
    size: tuple[int, int] = (1280, 720)
    fps: int = 30
    start: float = 0.0
    stop: float | None = None
    speed: float = 1.0
    plots: tuple[str, ...] = ()
    camera: str = "scene"

    def times(self, rec: Recording) -> np.ndarray:
        """Simulated time of each frame: ``duration / speed × fps`` frames."""
        stop = rec.duration if self.stop is None else self.stop
        count = max(1, round((stop - self.start) / self.speed * self.fps))
        return self.start + np.arange(count) * self.speed / self.fps


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` within :data:`MIN_SIZE` and :data:`MAX_SIZE`.

    Raises:
        BadOption: naming the accepted form and range.
    """
    w, sep, h = str(text).lower().partition("x")
    try:
        size = (int(w), int(h)) if sep else None
    except ValueError:
        size = None
    if size is None or not (
        MIN_SIZE[0] <= size[0] <= MAX_SIZE[0] and MIN_SIZE[1] <= size[1] <= MAX_SIZE[1]
    ):
        raise BadOption(
            f"--size {shown(text)}: give WIDTHxHEIGHT from {MIN_SIZE[0]}x{MIN_SIZE[1]} to "
            f"{MAX_SIZE[0]}x{MAX_SIZE[1]}, e.g. 1280x720"
        )
    return size


def check(options: VideoOptions, rec: Recording) -> None:
    """Refuse bad options before any frame is drawn.

    Raises:
        BadOption: an extension other than .mp4 or .gif, an fps outside 1–120, an
            interval outside the recording, an unknown plot name, a speed not > 0, an
            unknown camera, an output folder that does not exist.
    """
    out = options.out
    if out.suffix.lower() not in (".mp4", ".gif"):
        raise BadOption(f"--video {shown(str(out))}: the file must end in .mp4 or .gif")
    if not out.parent.is_dir() or out.is_dir():
        raise BadOption(f"--video {shown(str(out))}: give a file in an existing folder")
    if not FPS_RANGE[0] <= options.fps <= FPS_RANGE[1]:
        raise BadOption(f"--fps {options.fps}: choose from {FPS_RANGE[0]} to {FPS_RANGE[1]}")
    if not (math.isfinite(options.speed) and 0.001 <= options.speed <= 100):
        raise BadOption(f"--speed {options.speed:g}: choose from 0.001 to 100 (0.1: slow motion)")
    stop = rec.duration if options.stop is None else options.stop
    if not (0 <= options.start < stop <= rec.duration + 1e-9):
        raise BadOption(
            f"--from {options.start:g} --to {stop:g}: the recording runs from 0 to "
            f"{rec.duration:.3g} s; choose FROM < TO within it"
        )
    unknown = [n for n in options.plots if n not in rec.names or n == "time"]
    if unknown:
        raise BadOption(
            f"--plot {shown(unknown[0])}: not a readout of this recording; "
            f"e.g. {', '.join(n for n in rec.names[1:7])}"
        )
    if options.camera not in CAMERAS:
        raise BadOption(f"--camera {shown(options.camera)}: choose one of {', '.join(CAMERAS)}")
    frames = len(options.times(rec))
    if frames > 100_000:
        raise BadOption(f"{frames} frames asked; at most 100,000: lower --fps or raise --speed")


# -- offscreen OpenGL -----------------------------------------------------------------------
def offscreen_renderer(model: mujoco.MjModel, height: int, width: int) -> mujoco.Renderer:
    """MuJoCo's renderer on a headless context: ``MUJOCO_GL`` when the user set it; on a
    Linux machine without a display, EGL, else OSMesa.

    Raises:
        VideoError: no OpenGL this machine can draw with (naming what to install).
    """
    from mujoco.rendering.classic import gl_context  # where Renderer finds its context

    headless = platform.system() == "Linux" and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    )
    if headless and not os.environ.get("MUJOCO_GL"):
        for backend in ("egl", "osmesa"):
            try:
                module = __import__(f"mujoco.{backend}", fromlist=["GLContext"])
                module.GLContext(1, 1).free()
            except Exception:  # missing library or driver: try the next one
                continue
            gl_context.GLContext = module.GLContext
            break
    model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
    model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
    try:
        return mujoco.Renderer(model, height, width)
    except Exception as exc:
        raise VideoError(
            "vidéo : pas d'OpenGL pour dessiner hors écran / no OpenGL to draw the video "
            f"offscreen ({type(exc).__name__}: {exc}); Linux: apt install libegl1 (or "
            "libosmesa6 and MUJOCO_GL=osmesa); macOS and Windows: update the graphics driver"
        ) from None


def aim(scene: mujoco.MjvScene, position: np.ndarray, look_at: np.ndarray, up: np.ndarray) -> None:
    """Point the scene's cameras from ``position`` at ``look_at``, ``up`` up (any up:
    MuJoCo's free camera only knows z)."""
    forward = look_at - position
    forward /= max(float(np.linalg.norm(forward)), 1e-12)
    up = up - np.dot(up, forward) * forward
    up /= max(float(np.linalg.norm(up)), 1e-12)
    for cam in scene.camera:
        cam.pos[:] = position
        cam.forward[:] = forward
        cam.up[:] = up


def backdrop(scene: mujoco.MjvScene, look_at: np.ndarray, extent: float) -> None:
    """A white wall behind the mechanism, facing the camera and lit by nothing (MuJoCo
    clears to black where a scene has no skybox; the page is white)."""
    if scene.ngeom >= scene.maxgeom:
        return
    cam = scene.camera[0]
    forward, up = np.asarray(cam.forward, float), np.asarray(cam.up, float)
    right = np.cross(forward, up)
    rot = np.column_stack([right, up, forward])  # the wall's z along the sight
    geom = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(
        geom,
        mujoco.mjtGeom.mjGEOM_BOX,
        np.array([40.0, 40.0, 0.001]) * extent,
        look_at + 6.0 * extent * forward,
        rot.ravel(),
        np.array([1.0, 1.0, 1.0, 1.0], dtype=np.float32),
    )
    geom.emission = 1.0
    scene.ngeom += 1


def project(scene: mujoco.MjvScene, points: np.ndarray, width: int, height: int) -> np.ndarray:
    """Pixel coordinates (x right, y down) of world ``points`` (n×3) in the view of
    ``scene``'s camera (NaN behind it)."""
    cam = scene.camera[0]
    forward, up = np.asarray(cam.forward), np.asarray(cam.up)
    right = np.cross(forward, up)
    rel = np.asarray(points, dtype=float) - np.asarray(cam.pos)
    z = rel @ forward
    near, top = float(cam.frustum_near), float(cam.frustum_top)
    half_h = top / near
    half_w = half_h * width / height
    with np.errstate(divide="ignore", invalid="ignore"):
        x = (rel @ right) / z / half_w
        y = (rel @ up) / z / half_h
    out = np.stack([(x + 1) * width / 2, (1 - y) * height / 2], axis=1)
    out[z <= 0] = np.nan
    return out


# -- the frame's text -----------------------------------------------------------------------
def _font(px: int) -> Any:
    from matplotlib import get_data_path
    from PIL import ImageFont

    return ImageFont.truetype(str(Path(get_data_path()) / "fonts/ttf/DejaVuSans.ttf"), px)


class Text:
    """Boxes of French text drawn on a frame (Pillow), sized to the frame's height."""

    def __init__(self, height: int) -> None:
        self.big = _font(max(12, round(height * 0.042)))
        self.small = _font(max(10, round(height * 0.026)))

    def box(
        self,
        draw: Any,
        xy: tuple[float, float],
        lines: Sequence[str],
        font: Any,
        color: tuple[int, int, int] = (0, 0, 0),
    ) -> None:
        """Lines in a white box with its top-left corner at ``xy``."""
        text = "\n".join(lines)
        x0, y0, x1, y1 = draw.multiline_textbbox(xy, text, font=font, spacing=4)
        pad = max(4, font.size // 4)
        draw.rectangle((x0 - pad, y0 - pad, x1 + pad, y1 + pad), fill=(255, 255, 255, 215))
        draw.multiline_text(xy, text, font=font, fill=color, spacing=4)


# -- the recorded motion, between its frames --------------------------------------------------
class Follow:
    """Moves a simulation to any instant of a recording: from the recorded frame at or
    before it, stepped on (a recording keeps frames at the page's rate, 10 to 60 a
    second; the compressor's crank turns 50 times a second). Re-simulating from a
    recorded state is exact (``sandbox replay --verify``)."""

    def __init__(self, rec: Recording, sim: Any) -> None:
        self.rec, self.sim = rec, sim
        self.index = -1

    def to(self, time: float) -> None:
        """The physics state at the last whole timestep at or before ``time``."""
        rec, sim = self.rec, self.sim
        i = max(0, int(np.searchsorted(rec.times, time + 1e-12, side="right")) - 1)
        if i != self.index or float(sim.data.time) > time + 1e-12:
            for name, value in rec.values_at(i).items():
                # a recording whose scene is gone replays its MJCF: no parameters
                if name in sim.values and sim.values[name] != value:
                    sim.set_value(name, value)
            set_state(sim.model, sim.data, rec.states[i])
            self.index = i
        steps = math.floor((time - float(sim.data.time)) / sim.timestep + 1e-9)
        if steps > 0:
            sim.step(steps)


MAX_STRIP_SAMPLES = 20_000
"""Readout evaluations for the strip at most (every timestep of a short clip)."""


def sampled(
    rec: Recording, sim: Any, names: Sequence[str], start: float, stop: float
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The strip's readouts over [start, stop] on the re-simulated motion, at every
    timestep (thinned to :data:`MAX_STRIP_SAMPLES`): the recorded readouts, taken at the
    page's rate, would alias a crank turning 50 times a second."""
    follow = Follow(rec, sim)
    follow.to(start)
    dt = sim.timestep
    count = int((stop - start) / dt) + 1
    stride = max(1, math.ceil(count / MAX_STRIP_SAMPLES))
    times = start + np.arange(0, count, stride) * dt
    columns: dict[str, list[float]] = {n: [] for n in names}
    for t in times:
        follow.to(float(t))
        values = sim.readouts(list(names))
        for n in names:
            columns[n].append(values[n])
    return times, {n: np.asarray(v, dtype=float) for n, v in columns.items()}


# -- the plot strip -------------------------------------------------------------------------
class Strip:
    """Readouts against time over the clip, drawn once (:meth:`draw`); a cursor per
    frame (:meth:`x_of`)."""

    def __init__(
        self,
        rec: Recording,
        names: Sequence[str],
        labels: dict[str, str],
        span: tuple[float, float],
        width: int,
        height: int,
    ) -> None:
        self.units = dict(zip(rec.names, rec.header.get("units", []), strict=False))
        self.names, self.labels, self.span = tuple(names), labels, span
        self.width, self.height = width, height
        self.image: Any = None
        self.left = self.right = self.top = self.bottom = 0.0

    def draw(self, times: np.ndarray, columns: dict[str, np.ndarray]) -> None:
        """The curves, French axis and legend (decimal comma), once for the clip."""
        from PIL import Image

        from sandbox.bench.plot import LOCK, comma_formatter, new_figure
        from sandbox.physics.units import shown_scale

        with LOCK:
            fig = new_figure(self.width / 100, self.height / 100)
            ax = fig.add_axes((0.08, 0.22, 0.75, 0.7))
            for k, name in enumerate(self.names):
                unit, factor = shown_scale(name, self.units.get(name, ""))
                words = f"{self.labels.get(name) or name}" + (f" [{unit}]" if unit else "")
                ax.plot(times, columns[name] * factor, lw=2, label=words, color=f"C{k}")
            ax.set_xlim(*self.span)
            ax.set_xlabel("Temps t [s]")
            ax.xaxis.set_major_formatter(comma_formatter())
            ax.yaxis.set_major_formatter(comma_formatter())
            ax.grid(True, alpha=0.3)
            ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
            fig.canvas.draw()
            rgba = np.asarray(fig.canvas.buffer_rgba())  # type: ignore[attr-defined]
            box = ax.get_window_extent()
        self.image = Image.fromarray(rgba[..., :3].copy())
        self.left, self.right = float(box.x0), float(box.x1)
        self.top, self.bottom = self.height - float(box.y1), self.height - float(box.y0)

    def x_of(self, time: float) -> float:
        """Pixel column of ``time`` in the strip."""
        a, b = self.span
        return self.left + (time - a) / (b - a) * (self.right - self.left)


# -- the video ------------------------------------------------------------------------------
def render_video(
    rec: Recording, options: VideoOptions, progress: Callable[[int, int], None] | None = None
) -> int:
    """Write the video ``options.out``; returns the number of frames.

    Raises:
        BadOption: bad options (before any frame).
        VideoError: no encoder or no offscreen OpenGL here.
    """
    check(options, rec)
    try:
        import imageio_ffmpeg  # type: ignore[import-untyped]  # (the video extra; no stubs)
    except ImportError:
        raise VideoError(
            "vidéo : le paquet imageio-ffmpeg manque / the video needs imageio-ffmpeg: "
            'pip install ".[video]"'
        ) from None
    from PIL import Image, ImageDraw

    width, height = options.size
    width, height = width - width % 2, height - height % 2  # yuv420p wants even sizes
    strip_h = round(height * STRIP) if options.plots else 0
    view_h = height - strip_h
    sim = open_simulation(rec)
    display = DisplayState(sim)
    spec = as_scene(sim.scene)
    infos = {i.name: i for i in sim.readout_infos()}
    words = {n: i.label or n for n, i in infos.items()}
    key = key_readouts(sim)
    names = [n for n in key if n in infos]
    labels = {n: key[n] or words.get(n, n) for n in names}
    units = {n: i.unit for n, i in infos.items()}
    zeros = {n: spec.zero_for(units.get(n, "")) if spec else 0.0 for n in infos}
    by_unit = dict(spec.zero) if spec is not None else {}
    times = options.times(rec)
    stop = float(times[-1]) + options.speed / options.fps  # the clip's end
    strip = (
        Strip(
            rec,
            options.plots,
            words,
            (options.start, max(stop, options.start + 1e-6)),
            width,
            strip_h,
        )
        if options.plots
        else None
    )
    renderer = offscreen_renderer(sim.model, view_h, width)
    if strip is not None:
        strip.draw(*sampled(rec, open_simulation(rec), options.plots, options.start, stop))
    text = Text(height)
    arrows = tuple(spec.arrows) if spec is not None else ()
    size = mechanism_size(sim.model, sim.data)
    factors: dict[str, float] = {}
    direction, up = scene_view(sim)
    if options.camera != "scene":
        direction, up = (
            DIRECTIONS[options.camera],
            ((0.0, 1.0, 0.0) if options.camera == "top" else (0.0, 0.0, 1.0)),
        )
    center, extent = np.asarray(sim.model.stat.center, float), float(sim.model.stat.extent)
    if spec is not None and spec.look_at is not None:
        center, extent = np.asarray(spec.look_at[0], float), spec.look_at[1]
    position, look_at = camera_pose(center, extent, direction)  # as the page frames it
    tmp = options.out.with_name(f".{options.out.name}.part{options.out.suffix}")
    gif = options.out.suffix.lower() == ".gif"
    writer = imageio_ffmpeg.write_frames(
        str(tmp),
        (width, height),
        fps=options.fps,
        codec="gif" if gif else "libx264",
        pix_fmt_out="pal8" if gif else "yuv420p",
        macro_block_size=2,
        ffmpeg_log_level="error",
        quality=None if gif else 7,
        # a GIF's 256 colours chosen for the whole clip, and played in a loop
        output_params=GIF_PALETTE if gif else MP4_SPEED,
    )
    writer.send(None)
    follow = Follow(rec, sim)
    model = sim.model
    try:
        for k, t in enumerate(times):
            follow.to(float(t))
            if sim.model is not model:  # a recorded change rebuilt the model
                renderer.close()
                model = sim.model
                renderer = offscreen_renderer(model, view_h, width)
            data = display.data(float(t), ("sup_R_x", "dyn_R_x") if arrows else ())
            renderer.update_scene(data)
            scene = renderer.scene
            aim(scene, position, look_at, np.asarray(up, float))
            backdrop(scene, look_at, extent)
            scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0  # as the page: no shadows
            snapshot = Snapshot(sim.model, data, sim.values)
            drawn = _add_arrows(scene, arrows, snapshot, size, factors, units)
            frame = Image.new("RGB", (width, height), BACKGROUND)
            frame.paste(Image.fromarray(renderer.render()), (0, 0))
            draw = ImageDraw.Draw(frame, "RGBA")
            _label_arrows(draw, text, scene, drawn, width, view_h, by_unit)
            values = sim.readouts(names + ["time"], data=data)
            lines = [f"t = {number(float(t), 4)} s"]
            lines += overlay_lines(names, values, labels, units, zeros)
            # top left: a player's controls cover the bottom of a video
            text.box(draw, (0.02 * width, 0.03 * view_h), lines, text.big)
            if strip is not None:
                frame.paste(strip.image, (0, view_h))
                x = strip.x_of(float(t))
                draw.line(
                    (x, view_h + strip.top, x, view_h + strip.bottom),
                    fill=(0, 0, 0),
                    width=max(2, height // 360),
                )
            writer.send(frame.tobytes())
            if progress is not None:
                progress(k + 1, len(times))
        writer.close()
    except BaseException as exc:
        with contextlib.suppress(Exception):
            writer.close()
        tmp.unlink(missing_ok=True)
        if isinstance(exc, (OSError, RuntimeError)):  # ffmpeg failed or was killed
            raise VideoError(f"the video encoder failed ({type(exc).__name__}: {exc})") from None
        raise
    finally:
        renderer.close()
    tmp.replace(options.out)
    return len(times)


def _add_arrows(
    scene: mujoco.MjvScene,
    arrows: Sequence[Any],
    snapshot: Snapshot,
    size: float,
    factors: dict[str, float],
    units: dict[str, str],
) -> list[tuple[Any, np.ndarray, float, str]]:
    """The scene's arrows as MuJoCo arrows in ``scene`` (sized as the page sizes them:
    a unit's factor changes only when its longest arrow would leave the view or shrink
    to a dot); returns (arrow, its point, magnitude, unit) of those drawn."""
    ends = []
    for arrow in arrows:
        origin, end, magnitude = arrow_points(arrow, snapshot)
        unit = getattr(arrow, "unit", "") or units.get(arrow.name, "")
        ends.append((arrow, origin, end, magnitude, unit))
    for unit in {e[4] for e in ends}:
        longest = max(float(np.linalg.norm(e[2] - e[1])) for e in ends if e[4] == unit)
        factors[unit] = auto_factor(factors.get(unit, 1.0), longest, size)
    drawn = []
    shaft = 0.012 * size
    for arrow, origin, end, magnitude, unit in ends:
        tip = origin + factors[unit] * (end - origin)
        if np.linalg.norm(tip - origin) < 1e-4 or scene.ngeom >= scene.maxgeom:
            continue
        geom = scene.geoms[scene.ngeom]
        rgba = np.array([*(c / 255 for c in arrow.color), 1.0], dtype=np.float32)
        mujoco.mjv_initGeom(
            geom, mujoco.mjtGeom.mjGEOM_ARROW, np.zeros(3), np.zeros(3), np.eye(3).ravel(), rgba
        )
        mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_ARROW, shaft, origin, tip)
        scene.ngeom += 1
        drawn.append((arrow, origin, magnitude, unit))
    return drawn


def _label_arrows(
    draw: Any,
    text: Text,
    scene: mujoco.MjvScene,
    drawn: Sequence[tuple[Any, np.ndarray, float, str]],
    width: int,
    height: int,
    zeros: dict[str, float],
) -> None:
    """Each arrow's label ("Palier A : 54,4 N") beside its point of application, the
    labels of one point stacked, in the arrow's colour."""
    stacks: dict[tuple[int, int], int] = {}
    for arrow, origin, magnitude, unit in drawn:
        ((x, y),) = project(scene, origin[None, :], width, height)
        if not (math.isfinite(x) and math.isfinite(y)):
            continue
        key = (round(x / 40), round(y / 40))
        row = stacks.get(key, 0)
        stacks[key] = row + 1
        words = caption(arrow, magnitude, unit, zeros)
        at = (min(x + 12, width - 8 * text.small.size), y + 4 + row * 1.4 * text.small.size)
        r, g, b = (int(c * 0.6) for c in arrow.color)  # darker: readable on white
        color = (r, g, b)
        text.box(draw, at, [words], text.small, color)
