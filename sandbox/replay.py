"""Using a recording: rebuild its simulation, re-simulate it (``--verify``).

The static export (``--export``), which draws with the web layer's renderer, is
:func:`sandbox.web.replay.export.export_static`; the browser player is
:mod:`sandbox.web.replay.player`.

A recording is an untrusted file: :func:`sandbox.recording.load` checked its schema;
here its model is checked against the recorded states before anything is replayed.

Which model replays it (:class:`ModelChoice`, printed by ``--verify``): a scene
recording is rebuilt from the scene as this sandbox builds it today for the recorded
parameters when that gives the header's MJCF text. When it does not (the scene changed
since, or the header was edited), a one-line warning names the first differing line,
and the recording's own MJCF is used with the scene's behaviour if it can replay the
recording (it compiles, the states fit it, and the recording changes no parameter that
rebuilds the model); else the scene's model is used. A recording of an MJCF file (or of
a scene this sandbox no longer has) replays its own MJCF.

The header's MJCF alone does not reproduce a scene recording: replayed as a plain file
it deviates (0.06 after 0.1 s of the rotor, more later) because a scene adds, outside
the MJCF, the physics its effects disable (``model.opt.disableflags``, e.g. weight
neglected), its integrator and default timestep (both in the header), its drive and
per-step ``control`` (the ``ctrl`` they write is in the recorded state, but a command
that varies with time must be computed at every step), its initial state (replaced by
the first recorded state), and MuJoCo writes the MJCF with 6 significant digits (the
rotor's disk tilt is rounded). With the scene's behaviour and disabled flags, the
recorded MJCF follows the rotor's recording to 1e-39, not bit for bit.

Cost: the events are read once, in order; consecutive ``set`` events of one instant
(no step between them) rebuild the model at most once, and a ``live`` parameter never
(:func:`set_values`), so re-simulating is linear in the recording.
"""

from __future__ import annotations

import dataclasses
import re
import shutil
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from sandbox.errors import SandboxError
from sandbox.physics.model import Source
from sandbox.physics.simulation import Simulation
from sandbox.recording import STATE_SPEC, BadRecording, Recording, get_state
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


def _from_mjcf(rec: Recording, scene: Any = None) -> Simulation:
    """Compile the recorded MJCF text in a temporary folder removed at once (the model
    keeps nothing from the file). With ``scene``, the text is first compiled alone (the
    checks of an untrusted file), then with the scene's behaviour but not its edit
    (drive, control, initial state, disabled effects, timestep rules, readouts)."""
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
        sim = Simulation(xml, integrator=head["integrator"], timestep=head["timestep"])
        if scene is None:
            return sim
        return Simulation(
            Source(dataclasses.replace(scene, edit=None), xml),
            values=head["values"],
            integrator=head["integrator"],
            timestep=head["timestep"],
            motion=head["motion"],
        )
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@dataclass(frozen=True)
class ModelChoice:
    """Which model replays a recording.

    Attributes:
        own: True for the recording's own MJCF, False for the scene as built today.
        description: What was used, to end a sentence ("the scene 'rotor' as built
            today (the same MJCF as the recording's)").
        warning: One line saying why the model may not be the recorded one, or None.
    """

    own: bool
    description: str
    warning: str | None = None


def _excerpt(line: str, start: int) -> str:
    """``line`` from ``start``, at most 100 characters ("..." marks a cut)."""
    part = line[start : start + 100]
    return ("..." if start else "") + part + ("..." if len(line) > start + 100 else "")


def _difference(recorded: str, today: str) -> str:
    """The first line where two MJCF texts differ, both versions shown with ``!r`` from
    up to 75 characters before their first difference."""
    a, b = recorded.splitlines(), today.splitlines()
    for n in range(max(len(a), len(b))):
        x = a[n].strip() if n < len(a) else "(end of text)"
        y = b[n].strip() if n < len(b) else "(end of text)"
        if x != y:
            col = next((i for i, (p, q) in enumerate(zip(x, y, strict=False)) if p != q), 0)
            start = max(0, min(col, len(x), len(y)) - 75)
            return (
                f"MJCF line {n + 1}: {_excerpt(x, start)!r} in the recording, "
                f"{_excerpt(y, start)!r} today"
            )
    return "the MJCF texts differ in their line ends"


def open_replay(rec: Recording) -> tuple[Simulation, ModelChoice]:
    """A simulation like the recorded one at its first frame, and which model it is.

    A registered scene is rebuilt from its spec with the recorded parameters; when the
    MJCF that gives differs from the header's, the recording's own MJCF is used with the
    scene's behaviour if it can replay the recording, else the scene's, and
    :attr:`ModelChoice.warning` says so. An MJCF file (or a scene this sandbox no longer
    has) is compiled from the MJCF text in the recording, in a temporary folder that is
    removed before returning.

    Raises:
        BadRecording: the model cannot be rebuilt, reads other files, or does not match
            the recorded states; a recorded change is one the scene refuses.
    """
    head = rec.header
    scene = head.get("scene")
    today = ""
    try:
        if scene in SCENES:
            sim = Simulation(
                SCENES[scene],
                values=head["values"],
                integrator=head["integrator"],
                timestep=head["timestep"],
                motion=head["motion"],
            )
            _check_changes(rec, sim)
            today = sim.mjcf()
        else:
            sim = _from_mjcf(rec)
    except BadRecording:
        raise
    except SandboxError as exc:
        raise _refuse(rec, f"cannot be replayed ({exc})") from None
    if scene not in SCENES:
        own = f"the recording's own MJCF ({_stem(head.get('target'))!r})"
        choice = ModelChoice(True, own)
        if scene is not None:
            choice = ModelChoice(
                True,
                own,
                f"the scene {str(scene)[:64]!r} is not in this sandbox: replayed as a plain "
                "MJCF file, without the scene's drive, control and disabled effects",
            )
    elif today == head["mjcf"]:
        choice = ModelChoice(
            False, f"the scene {scene!r} as built today (the same MJCF as the recording's)"
        )
    else:
        differs = (
            f"the recording's model differs from the scene {scene!r} built today for the "
            f"same parameters ({_difference(head['mjcf'], today)})"
        )
        mine, why_not = _own_model(rec, sim)
        if mine is not None:
            sim = mine
            choice = ModelChoice(
                True,
                f"the recording's own MJCF (with the behaviour of the scene {scene!r})",
                f"{differs}; replayed with the recording's own model",
            )
        else:
            choice = ModelChoice(
                False,
                f"the scene {scene!r} as built today (not the recording's MJCF)",
                f"{differs}; replayed with the scene's model: the recording's own {why_not}",
            )
    size = int(mujoco.mj_stateSize(sim.model, STATE_SPEC))
    if rec.states.shape[1] != size:
        raise _refuse(
            rec, f"holds states of {rec.states.shape[1]} numbers, but its model has {size}"
        )
    sim.restore(rec.states[0])
    return sim, choice


def _own_model(rec: Recording, sim: Simulation) -> tuple[Simulation | None, str]:
    """The recording's own MJCF with ``sim``'s scene behaviour, or None and why not."""
    scene = sim.scene
    assert scene is not None
    rebuilt = sorted(
        {e["name"] for e in rec.events if e["k"] == "set" and not scene.param(e["name"]).live}
    )
    if rebuilt:
        return None, (
            "MJCF is the model as first built and cannot follow the recorded change of "
            f"{rebuilt[0]!r}"
        )
    try:
        mine = _from_mjcf(rec, scene)
    except Exception as exc:  # an untrusted model the scene's callbacks may not fit
        text = str(exc).split(";")[0][:160] if isinstance(exc, SandboxError) else ""
        return None, f"model cannot be built ({text or type(exc).__name__})"
    size = int(mujoco.mj_stateSize(mine.model, STATE_SPEC))
    if rec.states.shape[1] != size:
        return None, f"model has states of {size} numbers, not the {rec.states.shape[1]} recorded"
    return mine, ""


def open_simulation(rec: Recording) -> Simulation:
    """A simulation like the recorded one at its first frame (see :func:`open_replay`).

    Raises:
        BadRecording: see :func:`open_replay`.
    """
    return open_replay(rec)[0]


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
    """How many MuJoCo steps :func:`verify` will take (timestep changes included)."""
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


def set_values(sim: Simulation, changes: Sequence[tuple[str, float]]) -> int:
    """Apply parameter changes made at one instant, in order, with at most one rebuild.

    A ``live`` parameter is set at once (no rebuild, as
    :meth:`~sandbox.physics.simulation.Simulation.set_value` does); of the others, all
    but the last only change ``sim.values``, and the last one rebuilds the model with
    every value. That leaves the state the changes made one by one leave (each rebuild
    copies the motion into a fresh ``MjData`` and applies the drive), unless an
    intermediate model had another number of coordinates.

    Returns:
        The number of model rebuilds (0 or 1).

    Raises:
        UnknownParameter, BadParameter: a refused value (the earlier ones stay set).
    """
    scene = sim.scene
    if scene is None:
        for name, value in changes:
            sim.set_value(name, value)  # raises: a file has no parameter
        return 0
    rebuilt = [i for i, (name, _) in enumerate(changes) if not scene.param(name).live]
    last = rebuilt[-1] if rebuilt else -1
    for i, (name, value) in enumerate(changes):
        if i != last and not scene.param(name).live:
            sim.values[name] = scene.param(name).check(value)
        else:
            sim.set_value(name, value)
    return 1 if rebuilt else 0


def _apply(sim: Simulation, event: dict[str, Any]) -> None:
    kind = event["k"]
    if kind == "integrator":
        sim.set_integrator(event["value"])
    elif kind == "timestep":
        sim.set_timestep(float(event["value"]))
    elif kind == "reset":
        sim.reset()
    elif kind == "motion":
        sim.set_motion(event["value"])


def _steps_to(sim: Simulation, t: float) -> int:
    return int(round((t - float(sim.data.time)) / sim.timestep))


def _step_to(sim: Simulation, t: float) -> None:
    sim.step(_steps_to(sim, t))


@dataclass(frozen=True)
class Verification:
    """What :func:`verify` found.

    Attributes:
        deviation: Largest absolute difference between a recorded state and the
            re-simulated one (0 when MuJoCo reproduced the run bit for bit).
        frames: Frames compared.
        model: Which model re-simulated it.
        rebuilds: Model rebuilds the recorded parameter changes took.
    """

    deviation: float
    frames: int
    model: ModelChoice
    rebuilds: int


def verify(rec: Recording, progress: Callable[[float], None] | None = None) -> Verification:
    """Re-simulate from the first recorded state, replaying every recorded change.

    The events are read once; consecutive ``set`` events with no step between them are
    applied together (:func:`set_values`), so the time is linear in the recording.

    Raises:
        BadRecording: the model cannot be rebuilt (see :func:`open_replay`), or the
            re-simulation would take more than :data:`MAX_REPLAY_STEPS` steps.
    """
    steps = planned_steps(rec)
    if steps > MAX_REPLAY_STEPS:
        raise BadRecording(
            f"re-simulating recording {str(rec.path)!r} takes {steps:.3g} steps, more than "
            f"the {MAX_REPLAY_STEPS:.0e} that --verify allows; verify a shorter recording"
        )
    sim, choice = open_replay(rec)
    events = [e for e in rec.events if e["index"] > 0]
    k = rebuilds = 0
    worst = 0.0
    for i in range(1, len(rec.times)):
        while k < len(events) and events[k]["index"] <= i:
            _step_to(sim, float(events[k]["t"]))
            if events[k]["k"] != "set":
                _apply(sim, events[k])
                k += 1
                continue
            changes: list[tuple[str, float]] = []  # this instant's: no step between them
            while (
                k < len(events)
                and events[k]["index"] <= i
                and events[k]["k"] == "set"
                and _steps_to(sim, float(events[k]["t"])) == 0
            ):
                changes.append((events[k]["name"], events[k]["value"]))
                k += 1
            rebuilds += set_values(sim, changes)
        _step_to(sim, float(rec.times[i]))
        diff = np.abs(get_state(sim.model, sim.data) - rec.states[i])
        worst = max(worst, float(np.nanmax(diff)) if diff.size else 0.0)
        if progress is not None and i % 500 == 0:
            progress(i / len(rec.times))
    return Verification(worst, len(rec.times), choice, rebuilds)


def resimulate(
    rec: Recording, progress: Callable[[float], None] | None = None
) -> tuple[float, int]:
    """The deviation and frame count of :func:`verify`: the largest absolute difference
    between a recorded state and the re-simulated one (0 when bit for bit), and the
    frames compared.

    Raises:
        BadRecording: see :func:`verify`.
    """
    result = verify(rec, progress)
    return result.deviation, result.frames
