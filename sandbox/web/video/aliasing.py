"""When a video's frames hide a rotation (the wagon-wheel effect), and the slow motion that
shows it.

A part turning ``rate`` revolutions a second, filmed at ``fps`` frames a second of a clip
played at ``speed`` (0.1: slow motion), turns ``rate × speed / fps`` revolutions between
two frames. Past half a turn the eye pairs each frame with the nearest position: a rotor
at 1500 tr/min (25 tr/s) filmed at 30 frames/s turns 0.83 turn a frame and is seen turning
backwards at 5 tr/s; at 1800 tr/min it is seen still. A quarter turn a frame at most shows
the rotation as it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from sandbox.french import number
from sandbox.recording import STATE_SPEC, Recording
from sandbox.replay import open_simulation
from sandbox.web.video.options import VideoOptions

SEEN = 0.5
"""Most of a turn between two frames the eye still reads the right way round."""

SHOWN = 0.25
"""Turn between two frames the proposed slow motion gives at most."""

SAMPLES = 200
"""Frames of a recording read for its fastest rotation."""

NICE = (1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001)
"""The slow motions proposed (``--speed``), fastest first."""


@dataclass(frozen=True)
class Alias:
    """A rotation the frames hide.

    Attributes:
        rate: The fastest part's revolutions a second [tr/s] (simulated time).
        per_frame: Its turns between two frames of the clip.
        speed: The slow motion that shows it (``--speed``), None when even the slowest
            allowed does not.
    """

    rate: float
    per_frame: float
    speed: float | None

    @property
    def still(self) -> bool:
        """The frames catch it at nearly the same place: it looks stopped."""
        return abs(self.per_frame - round(self.per_frame)) < 0.05

    def english(self, fps: int) -> str:
        """One line for the command."""
        seen = "still" if self.still else "turning backwards or jumping"
        fix = (
            f"--speed {self.speed:g} shows it turning" if self.speed else "no slow motion shows it"
        )
        return (
            f"the fastest part turns {self.rate:.3g} rev/s, {self.per_frame:.2f} turn between "
            f"two frames at {fps} fps: the video shows it {seen}; {fix}"
        )

    def french(self, fps: int) -> str:
        """One sentence for the page."""
        seen = "arrêtée" if self.still else "tournant à l'envers ou par sauts"
        fix = (
            f"un ralenti ×{number(self.speed, 3)} la montre tourner (option --speed "
            f"{self.speed:g} de « sandbox replay … --video »)"
            if self.speed
            else "aucun ralenti ne la montre tourner"
        )
        return (
            f"La pièce la plus rapide fait {number(self.rate, 3)} tours par seconde, soit "
            f"{number(self.per_frame, 2)} {'tour' if self.per_frame < 2 else 'tours'} entre "
            f"deux images à {fps} images/s : la vidéo "
            f"la montre {seen} ; {fix}."
        )


def alias(rate: float, fps: float, speed: float = 1.0) -> Alias | None:
    """The :class:`Alias` of a part turning ``rate`` tr/s in a clip of ``fps`` frames a
    second played at ``speed``; None when the frames show its rotation."""
    rate = abs(float(rate))
    if not math.isfinite(rate) or rate <= 0.0:
        return None
    per_frame = rate * speed / fps
    if per_frame <= SEEN:
        return None
    fitting = [s for s in NICE if rate * s / fps <= SHOWN]
    return Alias(rate, per_frame, fitting[0] if fitting else None)


def turn_rate(model: mujoco.MjModel, qvel: np.ndarray) -> float:
    """The fastest hinge's revolutions a second at velocities ``qvel`` (0 without one)."""
    hinges = [
        int(model.jnt_dofadr[j])
        for j in range(model.njnt)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
    ]
    if not hinges:
        return 0.0
    return float(np.max(np.abs(qvel[hinges]))) / (2.0 * math.pi)


def fastest_turn(rec: Recording, model: mujoco.MjModel, start: float, stop: float) -> float:
    """The fastest hinge's revolutions a second over the recording's frames from ``start``
    to ``stop`` (at most :data:`SAMPLES` read; frames of another model's size skipped)."""
    data = mujoco.MjData(model)
    size = int(mujoco.mj_stateSize(model, STATE_SPEC))
    inside = np.flatnonzero((rec.times >= start) & (rec.times <= stop))
    step = max(1, len(inside) // SAMPLES)
    fastest = 0.0
    for i in inside[::step]:
        state = rec.states[i]
        if len(state) != size or not np.all(np.isfinite(state)):
            continue
        mujoco.mj_setState(model, data, np.asarray(state, dtype=float), STATE_SPEC)
        fastest = max(fastest, turn_rate(model, data.qvel))
    return fastest


def of_clip(rec: Recording, options: VideoOptions) -> Alias | None:
    """The :class:`Alias` of the clip ``options`` asks of ``rec`` (None: it shows every
    rotation)."""
    stop = rec.duration if options.stop is None else options.stop
    model = open_simulation(rec).model
    return alias(fastest_turn(rec, model, options.start, stop), options.fps, options.speed)
