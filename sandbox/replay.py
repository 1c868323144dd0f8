"""Using a recording: rebuild its simulation, re-simulate it (``--verify``).

The static export (``--export``), which draws with the web layer's renderer, is
:func:`sandbox.web.export.export_static`; the browser player is
:mod:`sandbox.web.player`.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from sandbox.physics.simulation import Simulation
from sandbox.recording import Recording, get_state, set_state
from sandbox.scenes import SCENES


def open_simulation(rec: Recording) -> Simulation:
    """A simulation like the recorded one at its first frame.

    A registered scene is rebuilt from its spec with the recorded parameters; an MJCF
    file (or a scene this sandbox no longer has) from the MJCF text in the recording.
    """
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
