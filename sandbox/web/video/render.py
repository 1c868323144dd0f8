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
from collections.abc import Callable

import mujoco
import numpy as np
from PIL import Image, ImageDraw

from sandbox.physics.display import DisplayState
from sandbox.physics.snapshot import Snapshot
from sandbox.recording import Recording
from sandbox.replay import open_simulation
from sandbox.web.panels.projector import overlay_labels, overlay_lines
from sandbox.web.video.frame import ArrowLabels, Text, add_arrows
from sandbox.web.video.framing import SAMPLES, Picture, frame_clip, moving_centre, sample_clip
from sandbox.web.video.offscreen import aim, backdrop, offscreen_renderer
from sandbox.web.video.options import DIRECTIONS, VideoError, VideoOptions, check
from sandbox.web.video.strip import Follow, Strip, sampled
from sandbox.web.view3d.camera import page_pose, scene_view
from sandbox.web.view3d.geoms import mechanism_size
from sandbox.written import time_line

MP4_SPEED = ["-preset", "veryfast"]
"""x264's faster preset: the encoder shares a 2-core laptop with the drawing (its default
took 40 % of the time of a 1280×720 clip), for a file about 15 % larger."""
GIF_PALETTE = ["-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse", "-loop", "0"]
STRIP = 0.28
"""Height of the plot strip, as a fraction of the frame."""
BACKGROUND = (255, 255, 255)


# -- the video ------------------------------------------------------------------------------
def render_video(
    rec: Recording,
    options: VideoOptions,
    progress: Callable[[int, int], None] | None = None,
    *,
    captions: list[tuple[float, str]] | None = None,
) -> int:
    """Write the video ``options.out``; returns the number of frames. ``captions``, when
    given, receives each frame's time in the video [s] and the text written over it (the
    lesson pack writes it under the video, readable on a phone).

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
    width, height = options.size
    width, height = width - width % 2, height - height % 2  # yuv420p wants even sizes
    strip_h = round(height * STRIP) if options.plots else 0
    view_h = height - strip_h
    sim = open_simulation(rec)
    display = DisplayState(sim)
    spec = sim.scene
    infos = {i.name: i for i in sim.readout_infos()}
    words = {n: i.label or n for n, i in infos.items()}
    labels = overlay_labels(sim)  # the page's overlay words
    names = [n for n in labels if n in infos]
    readings = [a.name for a in (spec.page.arrows if spec else ()) if a.name in infos]
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
    arrows = tuple(spec.page.arrows) if spec is not None else ()
    size = mechanism_size(sim.model, sim.data)
    factors: dict[str, float] = {}
    direction, up = scene_view(sim)
    if options.camera != "scene":
        direction, up = (
            DIRECTIONS[options.camera],
            ((0.0, 1.0, 0.0) if options.camera == "top" else (0.0, 0.0, 1.0)),
        )
    position, look_at = page_pose(sim, direction)  # as the page frames it
    # the moving parts over the clip stay in the picture and clear of the readouts' box
    widest = ["t = −0 000,00 s"] + [  # the widest lines the box will hold
        f"{labels[n]} = −00 000,000 {units.get(n, '')}" for n in names
    ]
    box_w, box_h = text.extent(widest, text.big)
    box = (0.0, 0.0, 0.02 * width + box_w, 0.03 * view_h + box_h)  # no label goes there
    arrow_labels = ArrowLabels(text)
    picture = Picture(
        aspect=width / view_h,
        fovy=float(sim.model.vis.global_.fovy),
        box=((0.02 * width + box_w) / width, (0.03 * view_h + box_h) / view_h),
    )
    sampled_clock = np.linspace(float(times[0]), float(times[-1]), SAMPLES)
    clip = sample_clip(rec, open_simulation(rec), sampled_clock)
    following = clip.follows  # parts travelling far (a cylinder down its plane): followed
    if following:  # the camera's pose around the moving parts' centre of mass
        position, look_at = frame_clip(
            clip.shape(), position - look_at, np.zeros(3), np.asarray(up, float), picture
        )
    else:
        position, look_at = frame_clip(
            clip.points(), position, look_at, np.asarray(up, float), picture
        )
    extent = float(np.linalg.norm(look_at - position))  # the wall behind, at this scale
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
            at = follow.to(float(t))  # the simulated time at this instant of the clip
            if sim.model is not model:  # a recorded change rebuilt the model
                renderer.close()
                model = sim.model
                renderer = offscreen_renderer(model, view_h, width)
            data = display.data(at, forces=bool(arrows))
            renderer.update_scene(data)
            scene = renderer.scene
            centre = moving_centre(sim.model, data) if following else np.zeros(3)
            aim(scene, centre + position, centre + look_at, np.asarray(up, float))
            backdrop(scene, centre + look_at, extent)
            scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0  # as the page: no shadows
            snapshot = Snapshot(sim.model, data, sim.values)
            drawn = add_arrows(scene, arrows, snapshot, size, factors, units)
            frame = Image.new("RGB", (width, height), BACKGROUND)
            frame.paste(Image.fromarray(renderer.render()), (0, 0))
            draw = ImageDraw.Draw(frame, "RGBA")
            values = sim.readouts(names + readings + ["time"], data=data)
            arrow_labels.draw(draw, scene, drawn, (width, view_h), by_unit, values, avoid=(box,))
            # the simulated time of this frame, as the page and the 3D export write it (a
            # recording started at 81 s reads 81 s; the clip's own clock is the player's)
            lines = [time_line(values["time"])]
            lines += overlay_lines(names, values, labels, units, zeros)
            # top left: a player's controls cover the bottom of a video
            text.box(draw, (0.02 * width, 0.03 * view_h), lines, text.big)
            if captions is not None:
                captions.append((k / options.fps, "\n".join(lines)))  # the video's clock
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
