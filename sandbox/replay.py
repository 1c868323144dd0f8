"""Using a recording: rebuild its simulation, re-simulate it (``--verify``), export it.

The static export is one ``index.html`` made by viser's own scene serializer: the 3D
motion, the scene's arrows and a readout overlay play in any browser, from a static web
host or straight from a USB stick (``file://``), with no Python.
"""

from __future__ import annotations

import contextlib
import io
import math
import socket
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from sandbox.physics.simulation import Simulation
from sandbox.recording import Recording, get_state, set_state

EXPORT_FPS = 30.0
"""Frames per second of a static export (recordings are thinned to this rate)."""


def open_simulation(rec: Recording) -> Simulation:
    """A simulation like the recorded one at its first frame.

    A registered scene is rebuilt from its spec with the recorded parameters; an MJCF
    file (or a scene this sandbox no longer has) from the MJCF text in the recording.
    """
    from sandbox.scenes import SCENES

    head = rec.header
    scene = head.get("scene")
    if scene in SCENES:
        sim = Simulation(
            scene,
            values=head["values"],
            integrator=head["integrator"],
            timestep=head["timestep"],
        )
    else:
        folder = Path(tempfile.mkdtemp(prefix="sandbox-replay-"))
        xml = folder / (Path(str(head.get("target") or "model")).stem + ".xml")
        xml.write_text(head["mjcf"])
        sim = Simulation(xml, integrator=head["integrator"], timestep=head["timestep"])
    set_state(sim.model, sim.data, rec.states[0])
    return sim


def _apply(sim: Simulation, event: dict) -> None:
    kind = event["k"]
    if kind == "set":
        sim.set_value(event["name"], event["value"])
    elif kind == "integrator":
        sim.set_integrator(event["value"])
    elif kind == "timestep":
        sim.set_timestep(float(event["value"]))
    elif kind == "reset":
        sim.reset()


def _step_to(sim: Simulation, t: float) -> None:
    n = int(round((t - float(sim.data.time)) / sim.timestep))
    sim.step(n)


def resimulate(
    rec: Recording, progress: Callable[[float], None] | None = None
) -> tuple[float, int]:
    """Re-simulate from the first recorded state, replaying every recorded change.

    Returns:
        The largest absolute difference between a recorded state and the re-simulated
        one (0 when MuJoCo reproduced the run bit for bit), and the frames compared.
    """
    sim = open_simulation(rec)
    events = [e for e in rec.events if e["index"] > 0]
    k = 0
    worst = 0.0
    for i in range(1, len(rec.times)):
        while k < len(events) and events[k]["index"] <= i:
            _step_to(sim, float(events[k]["t"]))
            _apply(sim, events[k])
            k += 1
        _step_to(sim, float(rec.times[i]))
        diff = np.abs(get_state(sim.model, sim.data) - rec.states[i])
        worst = max(worst, float(np.nanmax(diff)) if diff.size else 0.0)
        if progress is not None and i % 500 == 0:
            progress(i / len(rec.times))
    return worst, len(rec.times)


def overlay_text(rec: Recording, values: dict[str, float], names: list[str]) -> str:
    """Readout overlay of a static export: time, then one line per readout."""
    units = dict(zip(rec.names, rec.header.get("units", [""] * len(rec.names)), strict=False))
    lines = [f"t = {values.get('time', math.nan):.3f} s"]
    for name in names:
        v = values.get(name, math.nan)
        lines.append(f"{name} = {v:.4g} {units.get(name, '')}".rstrip())
    return "\n".join(lines)


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def export_static(rec: Recording, folder: str | Path, *, fps: float = EXPORT_FPS) -> Path:
    """Write ``folder/index.html`` (3D replay + readout overlay) and ``readouts.csv``.

    Returns:
        The path of ``index.html``.
    """
    import viser

    from sandbox.recording import write_csv
    from sandbox.web.arrows import ArrowLayer
    from sandbox.web.renderer import SceneRenderer
    from sandbox.web.view import camera_pose, scene_view

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    sim = open_simulation(rec)
    with contextlib.redirect_stdout(io.StringIO()):  # no server banner for an export
        server = viser.ViserServer(host="127.0.0.1", port=_free_port(), verbose=False)
    try:
        scene = server.scene
        direction, up = scene_view(sim)
        extent = float(sim.model.stat.extent)
        position, look_at = camera_pose(sim.model.stat.center, extent, direction)
        server.initial_camera.position = position
        server.initial_camera.look_at = look_at
        server.initial_camera.up = up
        renderer = SceneRenderer(scene)
        arrows = None
        if sim.scene is not None and sim.scene.arrows:
            arrows = ArrowLayer(scene, sim.scene.arrows, extent=float(sim.model.stat.extent))
        names = [r.name for r in sim.scene.readouts] if sim.scene else ["T", "V", "P_acc"]
        names = [n for n in names if n in rec.names][:8]
        overlay = scene.add_label(
            "/overlay",
            "",
            position=tuple(
                np.asarray(sim.model.stat.center) + [0, 0, 0.45 * sim.model.stat.extent]
            ),
            font_screen_scale=1.0,
        )
        serializer = server.get_scene_serializer()
        last_t = None
        values = sim.values
        clock = rec.timeline
        for i in _thin(clock, fps):
            wanted = rec.values_at(i)
            for name, value in wanted.items():
                if values.get(name) != value:
                    sim.set_value(name, value)
            set_state(sim.model, sim.data, rec.states[i])
            renderer.sync(sim.model, sim.data)
            if arrows is not None:
                arrows.update(sim.snapshot(("sup_R_x", "dyn_R_x")))
                arrows.relabel()
            t = float(clock[i])
            shown = rec.readouts_of_frame(i) or {"time": float(rec.times[i])}
            overlay.text = overlay_text(rec, shown, names)
            if last_t is not None:
                serializer.insert_sleep(max(0.0, t - last_t))
            last_t = t
        html = serializer.as_html()
    finally:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()
    index = folder / "index.html"
    index.write_text(html)
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
