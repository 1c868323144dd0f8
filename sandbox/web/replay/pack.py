"""Lesson packs (``sandbox replay FILE.sbx [FILE.sbx...] --export DIR``): recordings as a
static site a student opens at home from a USB stick or any static host — no Python, no
server, nothing loaded from the network.

``DIR/index.html`` lists the recordings; each has its folder with:

- ``index.html``: the recording as a video (:mod:`sandbox.web.video.render`: the mechanism, its
  arrows and labels, the key readouts in French) with play, pause, scrub and speed; under
  it the same readouts in the page's own text (readable on a phone, where the video's
  letters are small), the very lines written over each frame of the video; beside
  it, for a recording made during a lesson, the lesson's steps in French, each a chapter of
  the timeline (clicking one seeks there; the step being shown is marked); below, the
  recorded readouts against time, whose cursor follows the video and which seeks the video
  where it is clicked;

One time axis: the video, the plot, the chapters and the 3D page all run on the
recording's clock (:attr:`~sandbox.recording.Recording.timeline`, from 0 at its first
frame); the simulated time « t » (81 s for a recording started 81 s into a session) is a
readout, written the same way over the video, in the 3D page and under the video.
- ``3d/index.html``: the 3D replay whose camera turns (viser's export,
  :func:`sandbox.web.replay.export.export_static`), and ``readouts.csv``.

Everything written comes from untrusted recordings: text goes through ``html.escape``,
data through JSON with ``<`` escaped; the page's script is inline and fixed.
"""

from __future__ import annotations

import html
import json
import math
import re
import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sandbox.errors import BadOption, shown
from sandbox.lessons import catalogue
from sandbox.physics.units import shown_scale
from sandbox.recording import Recording
from sandbox.replay import open_simulation
from sandbox.scenes import SCENES
from sandbox.web.replay.export import export_static
from sandbox.web.video.render import VideoOptions, render_video
from sandbox.written import time_line

SIZE = (960, 540)
"""The videos' size: sharp on a laptop, light on a USB stick."""
PLOTTED = 3
"""Readouts plotted at most (the scene's own plots first)."""


@dataclass(frozen=True)
class Chapter:
    """A lesson step and when the recording reached it."""

    time: float
    title: str
    text: str


def check_folder(folder: Path) -> None:
    """An export folder: new, or empty.

    Raises:
        BadOption: a file, or a folder with something in it (nothing is overwritten).
    """
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise BadOption(
            f"--export {shown(str(folder))} is not an empty folder; give a new or empty one"
        )


def chapters(rec: Recording) -> tuple[str, list[Chapter]]:
    """The lesson's title and the steps a recording went through, with their times on
    the recording's clock (none without a lesson, or when this sandbox does not know the
    lesson)."""
    name = rec.header.get("lesson")
    lesson = catalogue()[0].get(name) if isinstance(name, str) else None
    if lesson is None:
        return "", []
    out: list[Chapter] = []
    clock = rec.timeline
    for event in rec.events:
        step = event.get("step")
        if event.get("k") != "lesson" or not isinstance(step, int):
            continue
        if not 0 <= step < len(lesson.steps):
            continue
        at = int(event.get("index", 0))  # the first frame recorded after the step
        t = float(clock[min(max(at, 0), len(clock) - 1)]) if len(clock) else 0.0
        s = lesson.steps[step]
        if not out or out[-1].title != s.title:
            out.append(Chapter(t, s.title, s.text))
    if not out and lesson.steps:
        s = lesson.steps[0]
        out.append(Chapter(0.0, s.title, s.text))
    return lesson.title, out


def _title(rec: Recording) -> str:
    scene = rec.header.get("scene")
    spec = SCENES.get(scene) if isinstance(scene, str) else None
    if spec is not None:
        return spec.title
    return f"Modèle {rec.header.get('target', '')}"


def _series(rec: Recording) -> dict[str, object]:
    """The plotted readouts in the page's units against the recording's clock, as
    JSON-able data."""
    scene = rec.header.get("scene")
    spec = SCENES.get(scene) if isinstance(scene, str) else None
    wanted = [n for n in (spec.page.plots if spec else ()) if n in rec.names]
    wanted = (wanted or [n for n in ("T", "V") if n in rec.names])[:PLOTTED]
    units = dict(zip(rec.names, rec.header.get("units", []), strict=False))
    labels: dict[str, str] = {}
    if spec is not None:
        labels = {r.name: r.label or r.name for r in spec.readouts}
    labels.update({"T": "Énergie cinétique T", "V": "Énergie potentielle V"})
    out = []
    for name in wanted:
        unit, factor = shown_scale(name, str(units.get(name, "")))
        values = rec.readouts[:, rec.names.index(name)] * factor
        clean = [None if not math.isfinite(v) else round(float(v), 6) for v in values]
        out.append({"label": labels.get(name, name), "unit": unit, "values": clean})
    clock = rec.timeline
    last = len(clock) - 1
    at = [float(clock[min(int(i), last)]) if last >= 0 else 0.0 for i in rec.readout_frames]
    return {"t": [round(t, 6) for t in at], "series": out}


def _json(data: object) -> str:
    """JSON safe inside a <script> element."""
    return json.dumps(data, ensure_ascii=False).replace("<", "\\u003c").replace(">", "\\u003e")


_INLINE = re.compile(r"&lt;(/?)(i|b|em|strong|sub|sup)&gt;")
"""The inline tags a lesson's text may use (the course's symbols: <i>ω</i>, x<sub>0</sub>),
put back after escaping: no attribute can come with them."""


def _text(paragraphs: str) -> str:
    """A lesson step's text as escaped paragraphs (Markdown marks dropped, the inline
    tags of :data:`_INLINE` kept)."""
    out = []
    for part in re.split(r"\n\s*\n", paragraphs):
        if part.strip():
            safe = html.escape(re.sub(r"[*_`#]", "", part.strip()))
            out.append("<p>" + _INLINE.sub(_TAG, safe) + "</p>")
    return "".join(out)


_TAG = r"<\1\2>"


def export_pack(recordings: Sequence[Recording], folder: Path) -> Path:
    """Write the site; returns ``folder/index.html``. Every recording is opened (its
    model checked) before anything is written; a failure removes what was written."""
    check_folder(folder)
    for rec in recordings:
        open_simulation(rec)  # a crafted model is refused before the folder exists
    made = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        return _write(recordings, folder)
    except BaseException:
        if made:
            shutil.rmtree(folder, ignore_errors=True)
        else:  # it was empty: empty it again
            for child in folder.iterdir():
                shutil.rmtree(child, ignore_errors=True) if child.is_dir() else child.unlink()
        raise


def _write(recordings: Sequence[Recording], folder: Path) -> Path:
    entries = []
    for k, rec in enumerate(recordings, start=1):
        stem = re.sub(r"[^A-Za-z0-9_-]", "_", rec.path.stem)[:40] or "enregistrement"
        sub = folder / f"{k:02d}-{stem}"
        sub.mkdir()
        captions: list[tuple[float, str]] = []  # what each frame of the video writes
        frames = render_video(rec, VideoOptions(sub / "video.mp4", size=SIZE), captions=captions)
        export_static(rec, sub / "3d")
        title = _title(rec)
        lesson, steps = chapters(rec)
        start = float(rec.times[0]) if len(rec.times) else 0.0
        (sub / "index.html").write_text(
            page(title, lesson, steps, _series(rec), frames / 30.0, captions, start),
            encoding="utf-8",
        )
        entries.append((sub.name, title, rec.duration, bool(steps)))
    items = "".join(
        f'<li><a href="{html.escape(name)}/index.html">{html.escape(title)}</a> — '
        f"{str(round(duration, 1)).replace('.', ',')} s{' · leçon' if lesson else ''}</li>"
        for name, title, duration, lesson in entries
    )
    index = folder / "index.html"
    index.write_text(
        f"<!doctype html><html lang='fr'><head><meta charset='utf-8'>"
        f"<meta name='viewport' content='width=device-width, initial-scale=1'>"
        f"<title>Dynamique des solides — enregistrements</title><style>{STYLE}</style></head>"
        f"<body><h1>Dynamique des solides</h1><p>Enregistrements de la séance :</p>"
        f"<ul>{items}</ul></body></html>",
        encoding="utf-8",
    )
    return index


STYLE = (
    "body{font:18px/1.45 sans-serif;margin:16px;color:#111;background:#fff}"
    "main{display:flex;flex-wrap:wrap;gap:16px}#left{flex:1 1 560px;min-width:280px}"
    "video{width:100%;background:#fff}canvas{width:100%;height:280px;cursor:pointer}"
    "#now{font-size:20px;white-space:pre-line;margin:6px 0;padding:6px 10px;"
    "background:#f3f5f8;border-radius:6px;font-variant-numeric:tabular-nums}"
    "#clock{color:#444}"
    "#steps{flex:0 1 340px}#steps li{cursor:pointer;padding:4px 6px;border-radius:4px}"
    "#steps li.on{background:#e3edfb}#steps li>span{font-weight:bold}"
    "select{font-size:inherit}nav{margin:8px 0}a{color:#1a56c4}"
)


def page(
    title: str,
    lesson: object,
    steps: Sequence[Chapter],
    series: dict[str, object],
    duration: float,
    captions: Sequence[tuple[float, str]] = (),
    start: float = 0.0,
) -> str:
    """One recording's page (every text escaped, data as JSON): ``captions`` are the
    readouts' text at times of the recording's clock, ``start`` the simulated time of its
    first frame [s]."""
    chapters_html = "".join(
        f'<li data-t="{c.time:.6f}"><span>{html.escape(c.title)}</span>{_text(c.text)}</li>'
        for c in steps
    )
    lesson_html = (
        f"<aside id='steps'><h2>Leçon : {html.escape(str(lesson))}</h2><ol>{chapters_html}</ol>"
        "</aside>"
        if steps
        else ""
    )
    return (
        "<!doctype html><html lang='fr'><head><meta charset='utf-8'>"
        "<meta name='viewport' content='width=device-width, initial-scale=1'>"
        f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>"
        f"<h1>{html.escape(title)}</h1>"
        "<nav><a href='../index.html'>← Tous les enregistrements</a> · "
        "<a href='3d/index.html'>Vue 3D libre (faire tourner la caméra)</a> · "
        "<a href='3d/readouts.csv'>Mesures (CSV)</a></nav>"
        "<main><div id='left'><video id='v' src='video.mp4' controls preload='auto'></video>"
        "<div><label>Vitesse de lecture <select id='speed'>"
        "<option value='0.25'>×0,25</option><option value='0.5'>×0,5</option>"
        "<option value='1' selected>×1</option><option value='2'>×2</option></select>"
        f"</label> · durée {str(round(duration, 1)).replace('.', ',')} s</div>"
        "<div id='now' aria-live='off'></div>"
        f"<p id='clock'>{html.escape(clock_words(start))}</p>"
        "<canvas id='plot'></canvas></div>"
        f"{lesson_html}</main>"
        f"<script>const DATA = {_json({**series, 'end': round(duration, 6)})};\n"
        f"const CAPTIONS = {_json([[round(t, 6), text] for t, text in captions])};\n"
        f"{SCRIPT}</script></body></html>"
    )


def clock_words(start: float) -> str:
    """The sentence that names the page's two times."""
    return (
        "La vidéo, les courbes et les étapes comptent le temps depuis le début de "
        "l'enregistrement. Le temps t affiché est celui de la simulation "
        f"({time_line(start)} au début)."
    )


SCRIPT = r"""
const video = document.getElementById('v'), canvas = document.getElementById('plot');
const ctx = canvas.getContext('2d'), colors = ['#1f77b4', '#ff7f0e', '#2ca02c'];
// the axis runs over the whole video (the last readout row may come a frame before its end)
const t = DATA.t, t0 = 0, t1 = Math.max(t.length ? t[t.length - 1] : 0, DATA.end || 0) || 1;
const pad = {l: 64, r: 16, t: 14 + 22 * DATA.series.length, b: 52};  // legend above, axis below
let W = 600, H = 240;  // CSS pixels: the canvas follows its box (a phone, a laptop)
let lo = Infinity, hi = -Infinity;
for (const s of DATA.series) {
  for (const v of s.values) {
    if (v !== null) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  }
}
if (!(hi > lo)) { lo = (isFinite(lo) ? lo : 0) - 1; hi = lo + 2; }
{ const m = 0.08 * (hi - lo); lo -= m; hi += m; }  // no curve on the frame's edge
const fr = (v) => v.toLocaleString('fr-FR', {maximumSignificantDigits: 4});
const X = (time) => pad.l + (time - t0) / ((t1 - t0) || 1) * (W - pad.l - pad.r);
const Y = (v) => H - pad.b - (v - lo) / (hi - lo) * (H - pad.t - pad.b);
function fit() {
  const dpr = window.devicePixelRatio || 1;
  W = canvas.clientWidth || 600; H = canvas.clientHeight || 240;
  if (canvas.width !== Math.round(W * dpr)) {
    canvas.width = Math.round(W * dpr); canvas.height = Math.round(H * dpr);
  }
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
}
function draw() {
  fit();
  ctx.clearRect(0, 0, W, H);
  ctx.font = '16px sans-serif'; ctx.fillStyle = '#333'; ctx.strokeStyle = '#ccc';
  const raw = (hi - lo) / 4, mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw);
  for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) {
    const y = Y(v);
    ctx.beginPath(); ctx.moveTo(pad.l, y); ctx.lineTo(W - pad.r, y); ctx.stroke();
    ctx.fillText(fr(v), 4, y + 4);
  }
  ctx.textAlign = 'left'; ctx.fillText(fr(t0), pad.l, H - 30);
  ctx.textAlign = 'right'; ctx.fillText(fr(t1) + ' s', W - pad.r, H - 30);
  ctx.textAlign = 'center';  // its own line: a phone's width holds it whole
  ctx.fillText("temps de l'enregistrement", (pad.l + W - pad.r) / 2, H - 8);
  ctx.textAlign = 'left';
  DATA.series.forEach((s, k) => {
    ctx.strokeStyle = colors[k % 3]; ctx.lineWidth = 2; ctx.beginPath();
    let up = false;
    s.values.forEach((v, i) => { if (v === null) { up = false; return; }
      if (up) ctx.lineTo(X(t[i]), Y(v)); else ctx.moveTo(X(t[i]), Y(v)); up = true; });
    ctx.stroke();
  });
  DATA.series.forEach((s, k) => {  // the legend above the curves, one line each
    const text = s.label + (s.unit ? ' [' + s.unit + ']' : '');
    ctx.fillStyle = colors[k % 3]; ctx.fillText(text, pad.l, 18 + 22 * k);
  });
  const x = X(clock());
  ctx.strokeStyle = '#000'; ctx.lineWidth = 2;
  ctx.beginPath(); ctx.moveTo(x, pad.t); ctx.lineTo(x, H - pad.b); ctx.stroke();
  window.__cursor = x;
  const steps = document.querySelectorAll('#steps li');
  let on = null;
  steps.forEach((li) => { if (parseFloat(li.dataset.t) <= clock() + 1e-9) on = li; });
  steps.forEach((li) => li.classList.toggle('on', li === on));
  let k = -1;  // the last caption at or before the clock
  for (let lo2 = 0, hi2 = CAPTIONS.length - 1; lo2 <= hi2;) {
    const mid = (lo2 + hi2) >> 1;
    if (CAPTIONS[mid][0] <= clock() + 1e-6) { k = mid; lo2 = mid + 1; } else hi2 = mid - 1;
  }
  const text = k >= 0 ? CAPTIONS[k][1] : (CAPTIONS.length ? CAPTIONS[0][1] : '');
  const now = document.getElementById('now');
  if (now.textContent !== text) now.textContent = text;
}
// one clock: the video's time is the recording's (the video is drawn at its own speed)
function clock() { return video.currentTime; }
function seekSim(time) {
  video.currentTime = Math.max(0, Math.min(time, video.duration || time));
  draw();
}
canvas.addEventListener('click', (e) => {
  const box = canvas.getBoundingClientRect();
  const x = (e.clientX - box.left) * W / box.width;
  seekSim(t0 + (x - pad.l) / (W - pad.l - pad.r) * (t1 - t0));
});
document.querySelectorAll('#steps li').forEach((li) => {
  li.addEventListener('click', () => seekSim(parseFloat(li.dataset.t)));
});
document.getElementById('speed').addEventListener('change', (e) => {
  video.playbackRate = parseFloat(e.target.value);
});
video.addEventListener('timeupdate', draw); video.addEventListener('loadedmetadata', draw);
window.addEventListener('resize', draw);
(function loop() { if (!video.paused) draw(); requestAnimationFrame(loop); })();
draw();
"""
