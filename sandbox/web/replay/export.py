"""Static export of a recording: one ``index.html`` made by viser's own scene serializer.

The 3D motion, the scene's arrows and a readout overlay play in any browser, from a
static web host or straight from a USB stick (``file://``), with no Python. The export
draws with the web layer's renderer and arrows; rebuilding the recorded simulation is
:func:`sandbox.replay.open_simulation`'s job.
"""

from __future__ import annotations

import contextlib
import io
import math
import socket
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import viser

from sandbox.recording import Recording, write_csv
from sandbox.replay import open_simulation
from sandbox.web.page import locale as client_text
from sandbox.web.panels.projector import overlay_labels, overlay_lines
from sandbox.web.serving.server import light_the_scene
from sandbox.web.view3d.arrows import ArrowLayer
from sandbox.web.view3d.camera import camera_pose, scene_view
from sandbox.web.view3d.renderer import SceneRenderer
from sandbox.written import time_line

EXPORT_FPS = 30.0
"""Frames per second of a static export (recordings are thinned to this rate)."""


def overlay_text(
    rec: Recording,
    values: dict[str, float],
    names: list[str],
    labels: Mapping[str, str] | None = None,
    zeros: Mapping[str, float] | None = None,
) -> str:
    """Readout overlay of a static export, as the page's projector overlay writes it:
    the time, then "label = value unit" per readout in French (decimal comma, tr/min and
    degrees, 0 below the scene's round-off)."""
    units = dict(zip(rec.names, rec.header.get("units", [""] * len(rec.names)), strict=False))
    lines = [time_line(values.get("time", math.nan))]
    lines += overlay_lines(names, values, labels or {}, units, zeros)
    return "\n".join(lines)


LOADING_ID = "sandbox-loading"
LOADING = (
    f"<div id='{LOADING_ID}' style='position:fixed;inset:0;display:flex;align-items:center;"
    "justify-content:center;font:20px sans-serif;color:#333;background:#fff;z-index:9999'>"
    "Chargement de l'animation…</div>"
    "<script>(function () {"
    "var t = setInterval(function () {"
    "if (document.querySelector('canvas')) {"
    f"var d = document.getElementById('{LOADING_ID}'); if (d) d.remove(); clearInterval(t);"
    "}}, 200);})();</script>"
)
"""Shown while the export loads (6 to 15 s of a blank page otherwise), removed once the
3D view has its canvas."""


def with_loading_sign(html: str) -> str:
    """``html`` with :data:`LOADING` first in its body (unchanged without a body)."""
    at = html.find("<body>")
    if at < 0:
        return html
    at += len("<body>")
    return html[:at] + LOADING + html[at:]


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def export_static(
    rec: Recording,
    folder: str | Path,
    *,
    fps: float = EXPORT_FPS,
) -> Path:
    """Write ``folder/index.html`` (3D replay + readout overlay) and ``readouts.csv``.

    Returns:
        The path of ``index.html``.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    sim = open_simulation(rec)
    with contextlib.redirect_stdout(io.StringIO()):  # no server banner for an export
        server = viser.ViserServer(host="127.0.0.1", port=_free_port(), verbose=False)
    try:
        light_the_scene(server)  # as the page
        scene = server.scene
        direction, up = scene_view(sim)
        extent = float(sim.model.stat.extent)
        position, look_at = camera_pose(sim.model.stat.center, extent, direction)
        server.initial_camera.position = position
        server.initial_camera.look_at = look_at
        server.initial_camera.up = up
        renderer = SceneRenderer(scene)
        spec = sim.scene
        arrows = None
        if spec is not None and spec.page.arrows:
            arrows = ArrowLayer(
                scene, spec.page.arrows, extent=float(sim.model.stat.extent), zero=spec.zero
            )
        key = overlay_labels(sim)  # the page's overlay words
        names = [n for n in key if n in rec.names]
        labels = {n: key[n] for n in names}
        units = dict(zip(rec.names, rec.header.get("units", []), strict=False))
        zeros = {n: spec.zero_for(units.get(n, "")) if spec else 0.0 for n in names}
        known = set(sim.readout_names())  # arrows whose label writes a readout
        readings = [a.name for a in arrows.arrows if a.name in known] if arrows else []
        # Beside the mechanism, not over it: one extent to the left of its centre as the
        # camera sees it.
        sight = np.asarray(look_at, dtype=float) - np.asarray(position, dtype=float)
        right = np.cross(sight, np.asarray(up, dtype=float))
        right /= max(float(np.linalg.norm(right)), 1e-12)
        overlay = scene.add_label(
            "/overlay",
            "",
            position=np.asarray(sim.model.stat.center, dtype=float) - 1.0 * extent * right,
            font_screen_scale=1.0,
        )
        serializer = server.get_scene_serializer()
        last_t = None
        values = sim.values
        clock = rec.timeline
        for i in _thin(clock, fps):
            wanted = rec.values_at(i)
            for name, value in wanted.items():
                # a recording whose scene is gone replays its MJCF: no parameters
                if name in values and values[name] != value:
                    sim.set_value(name, value)
            sim.restore(rec.states[i])
            renderer.sync(sim.model, sim.data)
            # one instant: the overlay's values, the arrows and their labels all read
            # from the state of this frame (a recorded row may be up to 0,1 s older)
            shown = {**sim.readouts([*names, *readings]), "time": float(rec.times[i])}
            if arrows is not None:
                arrows.update(sim.snapshot((), forces=True))
                arrows.relabel(shown)
            t = float(clock[i])
            overlay.text = overlay_text(rec, shown, names, labels, zeros)
            if last_t is not None:
                serializer.insert_sleep(max(0.0, t - last_t))
            last_t = t
        html = serializer.as_html()
        html = with_loading_sign(client_text.french_page(html) or html)
    finally:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()
    index = folder / "index.html"
    index.write_text(html, encoding="utf-8")
    write_csv(rec, folder / "readouts.csv")
    return index


def _thin(times: np.ndarray, fps: float) -> list[int]:
    """Frame indices at most ``fps`` per simulated second, first and last kept."""
    keep: list[int] = []
    next_t = -math.inf
    for i, t in enumerate(times):
        if t >= next_t or t < (times[keep[-1]] if keep else -math.inf):
            keep.append(i)
            next_t = t + 1.0 / fps - 1e-9
    if keep and keep[-1] != len(times) - 1:
        keep.append(len(times) - 1)
    return keep
