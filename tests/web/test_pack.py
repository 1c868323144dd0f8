"""Lesson packs (``sandbox replay A.sbx B.sbx --export DIR``): a static site read in
headless Chromium from the disk — the lesson's steps in French as chapters, the plot's
cursor following the video and seeking it, no request leaving the page — and recordings
treated as untrusted."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.cli import main
from sandbox.lessons import catalogue
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, load
from sandbox.scenes import get_scene
from sandbox.web.replay.pack import export_pack

pytest.importorskip("imageio_ffmpeg")

CRAFTED = "<script>alert('x')</script><img src=x onerror=alert(1)>"


def _lesson_recording(
    path: Path,
    *,
    speed_up: bool = True,
    start: float = 0.0,
    frames: int = 150,
    steps: tuple[tuple[int, int], ...] = ((-1, 0), (49, 1), (99, 2)),
) -> Path:
    """By default 1.5 s of the rotor following the lesson "equilibrage": step 1 at 0,
    step 2 at 0.5 s, step 3 (and 3000 tr/min) at 1.0 s. ``start``: seconds simulated
    before the recording starts; ``steps``: (frame after which, lesson step), -1 before
    the first frame."""
    sim = Simulation(get_scene("rotor"))
    if start:
        sim.step(round(start / sim.timestep))
    rec = Recorder(path, sim, lesson="equilibrage")
    changes = dict(steps)
    if -1 in changes:
        rec.event("lesson", step=changes[-1])
    rec.frame(sim.readouts())
    for k in range(frames):
        sim.step(1)
        if k in changes:
            if speed_up and changes[k] == 2:
                sim.set_value("speed_rpm", 3000)
            rec.event("lesson", step=changes[k])
        rec.frame(sim.readouts())
    rec.close()
    return path


@pytest.fixture(scope="module")
def pack(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("pack")
    lesson = _lesson_recording(folder / "lesson.sbx")
    sim = Simulation(get_scene("compressor"))
    plain = Recorder(folder / "compressor.sbx", sim)
    for _ in range(40):
        sim.step(10)
        plain.frame(sim.readouts())
    plain.close()
    out = folder / "site"
    assert main(["replay", str(lesson), str(folder / "compressor.sbx"), "--export", str(out)]) == 0
    return out


def test_the_site_holds_each_recording(pack):
    index = (pack / "index.html").read_text(encoding="utf-8")
    assert "Rotor déséquilibré à équilibrer" in index and "· leçon" in index
    folders = sorted(p.name for p in pack.iterdir() if p.is_dir())
    assert folders == ["01-lesson", "02-compressor"]
    for name in folders:
        assert {"index.html", "video.mp4", "3d"} <= {p.name for p in (pack / name).iterdir()}
        assert (pack / name / "3d" / "readouts.csv").exists()
    page = (pack / "01-lesson" / "index.html").read_text(encoding="utf-8")
    assert "http://" not in page and "https://" not in page  # nothing from the network


@pytest.mark.browser
@pytest.mark.slow  # one Chromium page, a few seconds
def test_the_lesson_plays_offline_with_its_steps_and_plot(pack, browser):
    steps = [s.title for s in catalogue()[0]["equilibrage"].steps[:3]]
    page = browser.new_page(viewport={"width": 1280, "height": 720})
    requests: list[str] = []
    page.on("request", lambda r: requests.append(r.url))
    try:
        page.goto((pack / "index.html").as_uri())
        page.get_by_role("link", name="Rotor déséquilibré à équilibrer").click()
        for title in steps:
            page.get_by_text(title, exact=True).first.wait_for(timeout=10_000)
        on = page.locator("#steps li.on")
        assert steps[0] in on.inner_text()
        # the readouts under the video, in the page's own text, at the video's instant
        now = page.locator("#now")
        assert now.inner_text().startswith("t = 0,00\u00a0s")
        assert "Palier A = " in now.inner_text()
        size = page.evaluate(
            "() => parseFloat(getComputedStyle(document.getElementById('now')).fontSize)"
        )
        assert size >= 18  # readable on a projector and a phone
        start = page.evaluate("() => window.__cursor")
        page.evaluate("() => { const v = document.getElementById('v'); v.muted = true; v.play(); }")
        # the video plays 0,3 s and more, and the cursor follows it
        page.wait_for_function(
            "() => document.getElementById('v').currentTime > 0.3"
            f" && window.__cursor > {start + 50}",
            timeout=10_000,
        )
        page.evaluate("() => document.getElementById('v').pause()")
        # a click on the plot near its right end seeks the video there (step 3's chapter)
        plot = page.locator("#plot")
        box = plot.bounding_box()
        assert box is not None
        plot.click(position={"x": box["width"] - 20, "y": box["height"] / 2})  # scrolled to
        page.wait_for_function("() => document.getElementById('v').currentTime > 1.2")
        assert steps[2] in on.inner_text()
        assert page.wait_for_function(
            "() => document.getElementById('now').textContent.startsWith('t = 1,')"
        )
        # a chapter's click seeks back to its start
        page.get_by_text(steps[1], exact=True).first.click()
        seek = (
            "() => { const t = document.getElementById('v').currentTime;"
            " return t > 0.45 && t < 0.6; }"
        )
        page.wait_for_function(seek)
        assert steps[1] in on.inner_text()
        page.select_option("#speed", "0.5")
        assert page.evaluate("() => document.getElementById('v').playbackRate") == 0.5
    finally:
        page.close()
    assert requests and all(u.startswith("file://") for u in requests), requests


def test_a_crafted_header_shows_as_text(tmp_path):
    path = _lesson_recording(tmp_path / "r.sbx", speed_up=False)
    rec = load(path)
    rec.header["scene"] = "no such scene"  # the title then comes from the file
    rec.header["target"] = CRAFTED
    rec.header["lesson"] = CRAFTED
    index = export_pack([rec], tmp_path / "site")
    for page in (index, *tmp_path.glob("site/*/index.html")):
        text = page.read_text(encoding="utf-8")
        assert "<script>alert" not in text and "<img src=x" not in text
    assert "&lt;script&gt;alert(" in index.read_text(encoding="utf-8")


def test_a_folder_that_is_not_empty_is_refused(tmp_path, capsys):
    path = _lesson_recording(tmp_path / "r.sbx")
    out = tmp_path / "site"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert main(["replay", str(path), "--export", str(out)]) == 2
    err = capsys.readouterr().err
    assert "not an empty folder" in err and len(err.strip().splitlines()) == 1
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def test_several_recordings_go_only_to_an_export(tmp_path, capsys):
    path = _lesson_recording(tmp_path / "r.sbx")
    assert main(["replay", str(path), str(path), "--verify"]) == 2
    assert "several go together only with --export" in capsys.readouterr().err


def test_a_failure_mid_export_leaves_no_site(tmp_path, monkeypatch):
    """The second recording's video fails: the folder the export made is gone."""
    from sandbox.web.replay import pack as packing

    path = _lesson_recording(tmp_path / "r.sbx", speed_up=False)
    made = {"n": 0}
    real = packing.render_video

    def second_fails(rec, options, *args, **kwargs):
        made["n"] += 1
        if made["n"] == 2:
            raise RuntimeError("the stick was pulled out")
        return real(rec, options, *args, **kwargs)

    monkeypatch.setattr(packing, "render_video", second_fails)
    out = tmp_path / "site"
    with pytest.raises(RuntimeError, match="pulled out"):
        export_pack([load(path), load(path)], out)
    assert not out.exists()


def test_a_recording_started_at_step_3_exports_step_3(tmp_path):
    """The page followed the lesson to its third step, then « Enregistrer »: the
    recording starts with that step, and the pack's first chapter is step 3's, not step 1's
    (the recording used to hold only the lesson's name)."""
    from sandbox.web.loop import Controller
    from sandbox.web.replay.pack import chapters

    ctl = Controller(Simulation(get_scene("rotor")), record_dir=tmp_path)
    ctl.lesson, ctl.lesson_step = "equilibrage", 2  # what the lesson panel sets
    path = ctl.start_recording()
    for _ in range(20):
        ctl.sim.step(1)
        ctl.record()
    ctl.stop_recording()
    lesson = catalogue()[0]["equilibrage"]
    title, found = chapters(load(path))
    assert title == lesson.title
    assert [c.title for c in found] == [lesson.steps[2].title]


def test_one_clock_for_the_video_the_plot_the_chapters_and_the_3d_page(tmp_path, monkeypatch):
    """A recording started 2 s into a session (the page's « Enregistrer » at t = 2 s):
    the plot, the chapters and the readouts under the video count from the recording's
    start; the simulated time t reads 2 s at its first frame over the video and under it
    (the same lines, frame by frame), and the page says which is which."""
    import json
    import re

    from sandbox.web.video import render

    path = _lesson_recording(
        tmp_path / "late.sbx", speed_up=False, start=2.0, frames=60, steps=((-1, 1), (29, 2))
    )
    sim = Simulation(get_scene("rotor"))  # its timestep
    written: list[str] = []
    real = render.time_line
    monkeypatch.setattr(render, "time_line", lambda t: written.append(real(t)) or real(t))
    export_pack([load(path)], tmp_path / "site")
    assert written[0] == "t = 2,00\u00a0s"  # over the video: the simulated time
    assert len(set(written)) == len(written) > 10  # it moves (it stayed on the first frame)
    page = (tmp_path / "site" / "01-late" / "index.html").read_text(encoding="utf-8")
    data = json.loads(re.search(r"const DATA = (.*);", page).group(1))
    assert data["t"][0] == 0.0 and abs(data["t"][-1] - 60 * sim.timestep) < 1e-9
    times = [float(t) for t in re.findall(r'data-t="([0-9.]+)"', page)]
    assert times[0] == 0.0 and abs(times[1] - 30 * sim.timestep) < 1e-9
    captions = json.loads(re.search(r"const CAPTIONS = (.*);", page).group(1))
    assert captions[0][0] == 0.0 and captions[0][1].startswith("t = 2,00\u00a0s")
    # under the video: the very lines written over each of its frames, at its clock
    assert [c[1].split("\n")[0] for c in captions] == written
    assert captions[1][0] == pytest.approx(1 / 30, abs=1e-6)
    assert "t = 2,00\u00a0s au début" in page  # the page names its two times
    three_d = (tmp_path / "site" / "01-late" / "3d" / "index.html").read_text(encoding="utf-8")
    assert three_d  # the 3D page's overlay is the captions' code (export_static)
