"""``sandbox replay FILE --video``: the video decoded and read back — its frames, size and
codec, the mechanism moving and the background still, the arrow's colour, the plot
cursor advancing — and bad input refused before any frame, a failure leaving no file."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from sandbox.cli import main
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, load
from sandbox.scenes import get_scene
from sandbox.web.video import render as video
from sandbox.web.video.render import VideoOptions, render_video

imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")

SIZE = (480, 270)


@pytest.fixture(scope="module")
def rotor(tmp_path_factory) -> Path:
    """One second of the rotor at 1500 tr/min, recorded every 10 ms (its timestep)."""
    sim = Simulation(get_scene("rotor"))
    path = tmp_path_factory.mktemp("video") / "rotor.sbx"
    rec = Recorder(path, sim)
    rec.frame(sim.readouts())
    for _ in range(100):
        sim.step(1)
        rec.frame(sim.readouts())
    rec.close()
    return path


def _frames(path: Path) -> tuple[dict, list[np.ndarray]]:
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    w, h = meta["size"]
    return meta, [np.frombuffer(f, dtype=np.uint8).reshape(h, w, 3) for f in reader]


@pytest.fixture(scope="module")
def clip(rotor, tmp_path_factory) -> tuple[dict, list[np.ndarray], VideoOptions]:
    """0.4 s of the rotor at ×0.5, 10 frames a second, with bearing A in a strip."""
    out = tmp_path_factory.mktemp("out") / "rotor.mp4"
    options = VideoOptions(out, size=SIZE, fps=10, stop=0.4, speed=0.5, plots=("bearing_A",))
    assert render_video(load(rotor), options) == 8
    meta, frames = _frames(out)
    return meta, frames, options


def test_frames_size_and_codec(clip):
    """Frame count = duration / speed × fps (0.4 s / 0.5 × 10 = 8), the size asked,
    H.264 in an MP4 that any slide program plays."""
    meta, frames, _ = clip
    assert len(frames) == 8 and tuple(meta["size"]) == SIZE
    assert "h264" in meta["codec"]
    assert meta["fps"] == pytest.approx(10)


def test_the_mechanism_moves_and_the_background_stays(clip):
    """At 1500 tr/min and ×0.5, 0.05 s of motion between frames turns the rotor by
    225°: the disk's pixels change; the top right corner (white wall) does not."""
    _, frames, _ = clip
    view_h = round(SIZE[1] * (1 - video.STRIP))
    a, b = (f.astype(int) for f in frames[3:5])
    middle = np.s_[view_h // 5 : 4 * view_h // 5, SIZE[0] // 3 : 2 * SIZE[0] // 3]
    corner = np.s_[0 : view_h // 6, 5 * SIZE[0] // 6 :]
    assert np.abs(a[middle] - b[middle]).max() > 60
    assert np.abs(a[corner] - b[corner]).max() <= 4  # compression noise only
    assert a[corner].min() > 240  # white, as the page


def test_no_face_of_the_mechanism_is_black(clip):
    """Lit as the page lights it (from every side): a disc seen from its unlit side is
    shaded, not black (MuJoCo's default headlight left 7 % of a rotor's video black)."""
    _, frames, _ = clip
    view_h = round(SIZE[1] * (1 - video.STRIP))
    for frame in frames:
        black = frame[:view_h].max(axis=-1) < 40
        assert black.mean() < 0.02, black.mean()


def test_the_arrows_colour_is_drawn(clip):
    """Bearing A's arrow is blue (40, 110, 230): saturated blue pixels in the view."""
    _, frames, _ = clip
    view_h = round(SIZE[1] * (1 - video.STRIP))
    view = frames[2][:view_h].astype(int)
    blue = (view[..., 2] > 150) & (view[..., 2] - view[..., 0] > 100)
    assert blue.sum() > 40


def test_the_plot_cursor_advances(clip):
    """The strip's black cursor moves right frame after frame (inside the axes: their
    left edge is the first frame's instant), by the same step each time."""
    _, frames, _ = clip
    view_h = round(SIZE[1] * (1 - video.STRIP))
    strip_h = SIZE[1] - view_h
    left, right = int(SIZE[0] * 0.085), int(SIZE[0] * 0.975)  # inside the axes
    top, bottom = view_h + int(0.3 * strip_h), view_h + int(0.7 * strip_h)  # not the legend
    columns = []
    for f in frames[1:]:
        strip = f[top:bottom, left:right].astype(int)
        dark = (strip.sum(axis=2) < 120).sum(axis=0)
        columns.append(left + int(np.argmax(dark)))
    steps = np.diff(columns)
    assert (steps > 0).all(), columns
    assert steps.max() - steps.min() <= 2, columns


def test_a_gif_too(rotor, tmp_path):
    out = tmp_path / "rotor.gif"
    render_video(load(rotor), VideoOptions(out, size=(320, 180), fps=5, stop=0.6))
    meta, frames = _frames(out)
    assert len(frames) == 3 and tuple(meta["size"]) == (320, 180)
    assert not list(tmp_path.glob(".*part*"))


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--plot", "nope"], "not a readout of this recording"),
        (["--size", "4000x3000"], "from 160x120 to 3840x2160"),
        (["--size", "100x80"], "from 160x120 to 3840x2160"),
        (["--fps", "0"], "choose from 1 to 120"),
        (["--from", "0.5", "--to", "3"], "choose FROM < TO within it"),
        (["--speed", "0"], "0.1: slow motion"),
        (["--camera", "drone"], "choose one of scene, front, side, top"),
    ],
)
def test_bad_input_is_one_line_exit_2_before_any_frame(rotor, tmp_path, capsys, argv, words):
    out = tmp_path / "x.mp4"
    assert main(["replay", str(rotor), "--video", str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())  # nothing rendered, nothing written


def test_a_wrong_extension_is_refused(rotor, tmp_path, capsys):
    assert main(["replay", str(rotor), "--video", str(tmp_path / "x.avi")]) == 2
    assert ".mp4 or .gif" in capsys.readouterr().err


def test_a_failure_leaves_no_half_written_file(rotor, tmp_path, monkeypatch):
    calls = {"n": 0}
    box = video.Text.box

    def failing(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] > 6:
            raise RuntimeError("the disk is full")
        return box(self, *args, **kwargs)

    monkeypatch.setattr(video.Text, "box", failing)
    out = tmp_path / "x.mp4"
    with pytest.raises(video.VideoError, match="the disk is full"):
        render_video(load(rotor), VideoOptions(out, size=(320, 180), fps=10, stop=1.0))
    assert list(tmp_path.iterdir()) == []


def test_a_missing_encoder_names_what_to_install(rotor, tmp_path, monkeypatch, capsys):
    import sys

    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    assert main(["replay", str(rotor), "--video", str(tmp_path / "x.mp4")]) == 2
    err = capsys.readouterr().err
    assert 'pip install ".[video]"' in err and "imageio-ffmpeg" in err
    assert list(tmp_path.iterdir()) == []


def _export(page, export) -> dict[str, bytes]:
    """Click « Exporter une vidéo » and run the page until the video is downloaded."""
    import time

    got: dict[str, bytes] = {}
    page.client.send_file_download = lambda name, data, **_: got.__setitem__(name, data)
    page.send(page.find("button", "Exporter une vidéo"), True)
    page.tick(0.2)
    assert export.future is not None and export.progress.visible
    folder = export.folder_path
    end = time.monotonic() + 120
    said = set()
    while export.future is not None and time.monotonic() < end:
        time.sleep(0.2)
        page.tick(0.1)
        said.add(export.status.content)
    # the page counted the frames while they were made
    assert any(re.search(r"en préparation : image \d+ sur \d+", s) for s in said), said
    assert folder is not None and not folder.exists()  # its work folder removed
    return got


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_the_page_exports_the_last_seconds_of_the_simulation(tmp_path):
    """« Exporter une vidéo » without a recording: the last seconds the session kept
    (30 states a simulated second), made in a worker process and downloaded."""
    from tests.robustness.test_hostile_web import Page

    page = Page("rotor", tmp_path)
    export = page.view.video
    assert export is not None
    page.tick(3.0)
    assert 2.5 < page.ctl.rewind.seconds <= 3.0
    ((name, data),) = _export(page, export).items()
    assert name.endswith(".mp4") and data[4:8] == b"ftyp"  # an MP4
    assert "Vidéo prête" in export.status.content
    # the rotor at 1500 tr/min, 30 frames/s: the page says what the frames hide
    assert "0,83 tour entre deux images" in export.status.content
    assert "ralenti ×0,2" in export.status.content
    page.ctl.secret = object()  # type: ignore[assignment]  # a challenge: a secret state
    export._start(page.client)  # what the click starts, in the session's loop
    assert "Pas de vidéo pendant un défi" in export.status.content and export.future is None


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_the_page_exports_the_recording_in_progress(tmp_path):
    from tests.robustness.test_hostile_web import Page

    page = Page("rotor", tmp_path)
    export = page.view.video
    assert export is not None
    page.ctl.start_recording()
    page.tick(2.0)
    assert page.ctl.recorder is not None
    page.ctl.recorder.flush()
    ((name, data),) = _export(page, export).items()
    assert data[4:8] == b"ftyp"


def test_the_rewind_keeps_the_last_seconds_of_one_model():
    from sandbox.web.loop.rewind import Rewind

    sim = Simulation(get_scene("rotor"))
    ring = Rewind(seconds=1.0, rate=10.0)
    for _ in range(300):
        sim.step(1)  # 10 ms
        ring.keep(sim)
    assert len(ring.states) == 11 and ring.seconds == pytest.approx(1.0)
    sim.set_value("defect_mass_g", 40.0)  # rebuilds the model: the ring starts again
    sim.step(1)
    ring.keep(sim)
    assert len(ring.states) == 1


@pytest.mark.parametrize("system", ["Windows", "Darwin"])
def test_windows_and_macos_keep_mujocos_own_context(system, monkeypatch):
    """On a teacher's Windows or macOS laptop the renderer uses MuJoCo's own context
    (a hidden window, CGL): EGL and OSMesa are Linux's and are not tried; a context that
    cannot be made is one line naming what to do."""
    import mujoco

    from sandbox.web.video import offscreen as v

    monkeypatch.setattr(v.platform, "system", lambda: system)
    tried: list[str] = []
    real_import = __import__

    def spy(name, *args, **kwargs):
        if name in ("mujoco.egl", "mujoco.osmesa"):
            tried.append(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr("builtins.__import__", spy)

    def no_context(*args, **kwargs):
        raise RuntimeError("no display")

    monkeypatch.setattr(mujoco, "Renderer", no_context)
    with pytest.raises(v.VideoError, match="no OpenGL to draw the video offscreen"):
        v.offscreen_renderer(Simulation(get_scene("rotor")).model, 120, 160)
    assert tried == []


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_a_page_that_leaves_mid_export_leaves_no_folder(tmp_path):
    import time

    from tests.robustness.test_hostile_web import Page

    page = Page("rotor", tmp_path)
    export = page.view.video
    assert export is not None
    page.tick(2.0)
    page.send(page.find("button", "Exporter une vidéo"), True)
    page.tick(0.2)
    future, folder = export.future, export.folder_path
    assert future is not None and folder is not None and folder.exists()
    export.close()  # the browser left
    end = time.monotonic() + 120
    while (folder.exists() or not future.done()) and time.monotonic() < end:
        time.sleep(0.2)
    assert not folder.exists()


def test_a_rotation_the_frames_hide_is_named_with_the_slow_motion_that_shows_it():
    """The wagon-wheel effect: 1500 tr/min = 25 tr/s at 30 frames/s is 0.83 turn a frame
    (seen backwards), 1800 tr/min exactly one (seen still); ×0.2 gives 0.17 turn a frame."""
    from sandbox.web.video.aliasing import alias

    seen = alias(25.0, 30)
    assert seen is not None and seen.per_frame == pytest.approx(25 / 30) and not seen.still
    assert seen.speed == 0.2 and "--speed 0.2" in seen.english(30)
    assert "à l'envers" in seen.french(30) and "×0,2" in seen.french(30)
    still = alias(30.0, 30)
    assert still is not None and still.still and "arrêtée" in still.french(30)
    assert alias(25.0, 30, 0.2) is None  # the slow motion proposed shows it
    assert alias(5.0, 30) is None and alias(0.0, 30) is None and alias(math.nan, 30) is None


def test_the_command_warns_of_a_rotor_the_frames_hide(rotor, tmp_path, capsys):
    """``replay --video`` of the rotor at 1500 tr/min at 10 frames/s: a warning naming the
    slow motion that shows it; at that slow motion, none."""
    out = tmp_path / "r.mp4"
    argv = ["replay", str(rotor), "--video", str(out), "--size", "160x120", "--fps", "10"]
    assert main([*argv, "--to", "0.3"]) == 0
    err = capsys.readouterr().err
    assert "warning: the fastest part turns 25 rev/s" in err and "--speed 0.1 shows it" in err
    assert main([*argv, "--to", "0.03", "--speed", "0.1"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_a_flat_curve_in_the_strip_has_ticks_that_differ():
    """A bearing force steady to 1e-6 N gave four ticks all reading « 54,4175 »: a curve
    flatter than 2 % of its size gets that room around it; a moving one keeps its own."""
    from sandbox.written import flat_limits

    lo, hi = flat_limits(54.4175 + 1e-6 * np.sin(np.linspace(0, 9, 50)))
    assert lo == pytest.approx(54.4175 * 0.98, rel=1e-6) and hi == pytest.approx(
        54.4175 * 1.02, rel=1e-6
    )
    assert flat_limits(np.zeros(5)) == (-1.0, 1.0)
    assert flat_limits(np.linspace(-10, 10, 5)) is None
    assert flat_limits(np.zeros(0)) is None
