"""Using a recording: rebuild its simulation, re-simulate it (``--verify``).

The static export (``--export``), which draws with the web layer's renderer, is
:func:`sandbox.web.export.export_static`; the browser player is
:mod:`sandbox.web.player`.

A recording is an untrusted file: :func:`sandbox.recording.load` checked its schema;
here its model is checked against the recorded states before anything is replayed.
"""

from __future__ import annotations

import re
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import SandboxError
from sandbox.physics.simulation import Simulation
from sandbox.recording import STATE_SPEC, BadRecording, Recording, get_state, set_state
from sandbox.scenes import SCENES

MAX_REPLAY_STEPS = 20_000_000
"""Most MuJoCo steps ``--verify`` may take (an hour of the finest default timestep,
0.2 ms; one to six minutes of CPU)."""

_FILE_REFERENCE = re.compile(r"\bfile\w*\s*=\s*[\"']([^\"']*)", re.IGNORECASE)
_FIX = "the file was altered or damaged after it was written: use the original file"


def _stem(target: object) -> str:
    """A harmless file name stem for the recorded target (letters, digits, ``_.-``)."""
    stem = Path(str(target)).stem if isinstance(target, str) else ""
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", stem)[:64].strip("._")
    return stem or "model"


def _refuse(rec: Recording, problem: str) -> BadRecording:
    return BadRecording(f"recording {str(rec.path)!r} {problem}; {_FIX}")


def _from_mjcf(rec: Recording) -> Simulation:
    """Compile the recorded MJCF text in a temporary folder removed at once (the model
    keeps nothing from the file)."""
    head = rec.header
    mjcf = head["mjcf"]
    ref = _FILE_REFERENCE.search(mjcf)
    if ref is not None:
        raise BadRecording(
            f"recording {str(rec.path)!r} holds a model that reads the file "
            f"{ref.group(1)[:80]!r}, which a recording does not carry; replay the MJCF file "
            "itself with 'sandbox run' or 'sandbox serve'"
        )
    folder = Path(tempfile.mkdtemp(prefix="sandbox-replay-"))
    try:
        xml = folder / f"{_stem(head.get('target'))}.xml"
        xml.write_text(mjcf, encoding="utf-8")
        return Simulation(xml, integrator=head["integrator"], timestep=head["timestep"])
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def open_simulation(rec: Recording) -> Simulation:
    """A simulation like the recorded one at its first frame.

    A registered scene is rebuilt from its spec with the recorded parameters; an MJCF
    file (or a scene this sandbox no longer has) from the MJCF text in the recording,
    compiled in a temporary folder that is removed before returning.

    Raises:
        BadRecording: the model cannot be rebuilt, reads other files, or does not match
            the recorded states; a recorded change is one the scene refuses.
    """
    head = rec.header
    scene = head.get("scene")
    try:
        if scene in SCENES:
            sim = Simulation(
                scene,
                values=head["values"],
                integrator=head["integrator"],
                timestep=head["timestep"],
            )
            _check_changes(rec, sim)
        else:
            sim = _from_mjcf(rec)
    except BadRecording:
        raise
    except SandboxError as exc:
        raise _refuse(rec, f"cannot be replayed ({exc})") from None
    size = int(mujoco.mj_stateSize(sim.model, STATE_SPEC))
    if rec.states.shape[1] != size:
        raise _refuse(
            rec, f"holds states of {rec.states.shape[1]} numbers, but its model has {size}"
        )
    set_state(sim.model, sim.data, rec.states[0])
    return sim


def _check_changes(rec: Recording, sim: Simulation) -> None:
    """Every recorded parameter value and timestep is one the scene accepts."""
    scene = sim.scene
    assert scene is not None
    for ev in rec.events:
        if ev["k"] == "set":
            scene.param(ev["name"]).check(ev["value"])
        elif ev["k"] == "timestep" and ev["value"] > scene.max_timestep:
            raise _refuse(
                rec,
                f"changes the timestep to {ev['value']!r} s, more than {scene.name!r} allows "
                f"({scene.max_timestep:g} s)",
            )


def planned_steps(rec: Recording) -> float:
    """How many MuJoCo steps :func:`resimulate` will take (timestep changes included)."""
    dt = float(rec.header["timestep"])
    t = float(rec.times[0])
    steps = 0.0
    events = [e for e in rec.events if e["index"] > 0]
    k = 0
    for i in range(1, len(rec.times)):
        while k < len(events) and events[k]["index"] <= i:
            ev = events[k]
            steps += max(0.0, ev["t"] - t) / dt
            t = ev["t"]
            if ev["k"] == "timestep":
                dt = float(ev["value"])
            k += 1
        steps += max(0.0, float(rec.times[i]) - t) / dt
        t = float(rec.times[i])
    return steps


def _apply(sim: Simulation, event: dict[str, Any]) -> None:
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

    Raises:
        BadRecording: the model cannot be rebuilt (see :func:`open_simulation`), or the
            re-simulation would take more than :data:`MAX_REPLAY_STEPS` steps.
    """
    steps = planned_steps(rec)
    if steps > MAX_REPLAY_STEPS:
        raise BadRecording(
            f"re-simulating recording {str(rec.path)!r} takes {steps:.3g} steps, more than "
            f"the {MAX_REPLAY_STEPS:.0e} that --verify allows; verify a shorter recording"
        )
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
