"""What ``--video`` asks for (``sandbox replay FILE --video OUT.mp4|OUT.gif``), checked
before any frame is drawn: size, frame rate, interval, speed, plots and camera.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sandbox.errors import BadOption, shown
from sandbox.recording import Recording

MIN_SIZE, MAX_SIZE = (160, 120), (3840, 2160)
FPS_RANGE = (1, 120)
CAMERAS = ("scene", "front", "side", "top")
"""``--camera`` presets: the page's view of the scene, or along −y, +x, −z (z up)."""
DIRECTIONS = {"front": (0.0, -1.0, 0.0), "side": (1.0, 0.0, 0.0), "top": (0.0, 0.0, 1.0)}


class VideoError(BadOption):
    """A video that cannot be made here (a missing backend): one line, exit 2."""


@dataclass(frozen=True)
class VideoOptions:
    """What ``--video`` asks for, checked (see :func:`check`)."""

    out: Path
    size: tuple[int, int] = (1280, 720)
    fps: int = 30
    start: float = 0.0
    stop: float | None = None
    speed: float = 1.0
    plots: tuple[str, ...] = ()
    camera: str = "scene"

    def times(self, rec: Recording) -> np.ndarray:
        """Simulated time of each frame: ``duration / speed × fps`` frames."""
        stop = rec.duration if self.stop is None else self.stop
        count = max(1, round((stop - self.start) / self.speed * self.fps))
        return self.start + np.arange(count) * self.speed / self.fps


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` within :data:`MIN_SIZE` and :data:`MAX_SIZE`.

    Raises:
        BadOption: naming the accepted form and range.
    """
    w, sep, h = str(text).lower().partition("x")
    try:
        size = (int(w), int(h)) if sep else None
    except ValueError:
        size = None
    if size is None or not (
        MIN_SIZE[0] <= size[0] <= MAX_SIZE[0] and MIN_SIZE[1] <= size[1] <= MAX_SIZE[1]
    ):
        raise BadOption(
            f"--size {shown(text)}: give WIDTHxHEIGHT from {MIN_SIZE[0]}x{MIN_SIZE[1]} to "
            f"{MAX_SIZE[0]}x{MAX_SIZE[1]}, e.g. 1280x720"
        )
    return size


def check(options: VideoOptions, rec: Recording) -> None:
    """Refuse bad options before any frame is drawn.

    Raises:
        BadOption: an extension other than .mp4 or .gif, an fps outside 1–120, an
            interval outside the recording, an unknown plot name, a speed not > 0, an
            unknown camera, an output folder that does not exist.
    """
    out = options.out
    if out.suffix.lower() not in (".mp4", ".gif"):
        raise BadOption(f"--video {shown(str(out))}: the file must end in .mp4 or .gif")
    if not out.parent.is_dir() or out.is_dir():
        raise BadOption(f"--video {shown(str(out))}: give a file in an existing folder")
    if not FPS_RANGE[0] <= options.fps <= FPS_RANGE[1]:
        raise BadOption(f"--fps {options.fps}: choose from {FPS_RANGE[0]} to {FPS_RANGE[1]}")
    if not (math.isfinite(options.speed) and 0.001 <= options.speed <= 100):
        raise BadOption(f"--speed {options.speed:g}: choose from 0.001 to 100 (0.1: slow motion)")
    stop = rec.duration if options.stop is None else options.stop
    if not (0 <= options.start < stop <= rec.duration + 1e-9):
        raise BadOption(
            f"--from {options.start:g} --to {stop:g}: the recording runs from 0 to "
            f"{rec.duration:.3g} s; choose FROM < TO within it"
        )
    unknown = [n for n in options.plots if n not in rec.names or n == "time"]
    if unknown:
        raise BadOption(
            f"--plot {shown(unknown[0])}: not a readout of this recording; "
            f"e.g. {', '.join(n for n in rec.names[1:7])}"
        )
    if options.camera not in CAMERAS:
        raise BadOption(f"--camera {shown(options.camera)}: choose one of {', '.join(CAMERAS)}")
    frames = len(options.times(rec))
    if frames > 100_000:
        raise BadOption(f"{frames} frames asked; at most 100,000: lower --fps or raise --speed")
