"""Where a video's camera stands: the page's framing when the moving parts stay in it over
the whole clip, else the same direction, aimed and moved so that every moving part, at
every sampled instant of the clip, is inside the picture and clear of the readouts' box
(the rolling cylinder starts at the top of its plane, where the page's framing put it
under the box and cut its top; the wheel balancer's wheel was cut too).

Pure geometry on MuJoCo's poses: the parts are outlined by points (a cylinder by its two
rims, a sphere by three great circles, a box or a mesh by the corners of its
``geom_aabb``), sampled along the clip by re-simulating the recording.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import mujoco
import numpy as np

from sandbox.physics.simulation import Simulation
from sandbox.recording import Recording
from sandbox.web.video.strip import Follow

SAMPLES = 24
"""Instants of the clip whose poses are framed (first and last included)."""
MARGIN = 0.94
"""The picture's share (in normalised coordinates) that framed parts may use."""
LABELS = 0.75
"""The right edge of what is framed (normalised): the arrows' labels go right of them."""
NEAREST = 0.5
"""A camera that frames again comes at most this much nearer than the page's."""


@dataclass(frozen=True)
class Picture:
    """The picture a camera fills: its aspect (width / height), MuJoCo's vertical field
    of view [°] and the readouts' box in its top-left corner, as shares of the width
    and height."""

    aspect: float
    fovy: float
    box: tuple[float, float]


SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
"""The eight corners of a box, as signs of its half sizes."""
_TURN = np.linspace(0, 2 * np.pi, 16, endpoint=False)
RIM = np.column_stack([np.cos(_TURN), np.sin(_TURN)])
"""A circle's points, 16 of them: a disc's rim drawn by its points, not by its box (a
turning disc's box corners would sweep a circle 1.41 times as wide)."""
ROUND = np.concatenate(
    [np.insert(RIM, k, 0.0, axis=1) for k in range(3)]
)  # three great circles of a unit sphere


def outline(model: mujoco.MjModel, g: int) -> np.ndarray:
    """Points of geom ``g`` in its own frame whose hull holds what is drawn of it."""
    size, kind = model.geom_size[g], model.geom_type[g]
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        r, h = size[0], size[1]
        return np.vstack([np.column_stack([r * RIM, np.full(16, z)]) for z in (-h, h)])
    if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        r, h = size[0], size[1]
        return np.vstack([r * ROUND + (0.0, 0.0, z) for z in (-h, h)])
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return size[0] * ROUND
    if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return ROUND * size
    box = model.geom_aabb[g]  # a box, a mesh: the box around it
    return box[:3] + SIGNS * box[3:]


def _shown(model: mujoco.MjModel) -> np.ndarray:
    """Geoms drawn by default (MuJoCo shows groups 0 to 2), planes left out (infinite)."""
    shown = model.geom_type != mujoco.mjtGeom.mjGEOM_PLANE
    return shown & (model.geom_rgba[:, 3] > 0) & (model.geom_group < 3)


STATIC_SCALE = 2.0
"""A fixed part is framed when it is at most this many times as large as the moving
parts' whole travel: the compressor's cylinder and the rotor's base are, the rolling
cylinder's 4 m long plane is not."""


def moving_outline(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Points outlining every visible geom of a moving body, in this pose (positions up
    to date)."""
    moving = (model.body_weldid[model.geom_bodyid] != 0) & _shown(model)
    parts = [
        data.geom_xpos[g] + outline(model, g) @ data.geom_xmat[g].reshape(3, 3).T
        for g in map(int, np.flatnonzero(moving))
    ]
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def moving_centre(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """The centre of mass of the moving bodies (what a following camera aims at: it
    does not wobble as a turning part's outline does)."""
    moving = model.body_weldid != 0
    mass = model.body_mass * moving
    total = float(mass.sum())
    if total <= 0:
        return np.zeros(3)
    return np.asarray(mass @ data.xipos / total, dtype=float)


FOLLOW_RATIO = 4.0
"""A clip whose moving parts travel this many times their own size is followed by the
camera (the rolling cylinder down its plane): framed still, it would be a dot."""


@dataclass(frozen=True)
class Clip:
    """What a clip's camera frames: the moving parts' outline at each sampled instant,
    their centre of mass then, and the fixed parts' outline."""

    moving: tuple[np.ndarray, ...]
    centres: tuple[np.ndarray, ...]
    fixed: tuple[np.ndarray, ...]

    @property
    def follows(self) -> bool:
        """The parts travel :data:`FOLLOW_RATIO` times their own size, or more."""
        shown = [m for m in self.moving if len(m)]
        if not shown:
            return False
        size = max(float(np.max(m.max(axis=0) - m.min(axis=0))) for m in shown)
        return _extent(np.concatenate(shown)) > FOLLOW_RATIO * max(size, 1e-9)

    def points(self) -> np.ndarray:
        """The still camera's cloud: every instant's moving parts, and the fixed parts of
        about the size of that motion (:data:`STATIC_SCALE`)."""
        shown = [m for m in self.moving if len(m)]
        if not shown:
            return np.zeros((0, 3))
        cloud = np.concatenate(shown)
        travel = _extent(cloud)
        return np.vstack([cloud, *(f for f in self.fixed if _extent(f) <= STATIC_SCALE * travel)])

    def shape(self) -> np.ndarray:
        """The following camera's cloud: each instant's moving parts around their centre
        of mass (the camera moves with that centre)."""
        shown = [m - c for m, c in zip(self.moving, self.centres, strict=True) if len(m)]
        return np.concatenate(shown) if shown else np.zeros((0, 3))


def _extent(points: np.ndarray) -> float:
    return float(np.max(points.max(axis=0) - points.min(axis=0))) if len(points) else 0.0


def sample_clip(rec: Recording, sim: Simulation, clock: Iterable[float]) -> Clip:
    """The moving parts' outlines and centres at each instant of ``clock`` (the
    recording's clock [s]), re-simulated on ``sim``, and the fixed parts' outline."""
    follow = Follow(rec, sim)
    moving: list[np.ndarray] = []
    centres: list[np.ndarray] = []
    fixed: list[np.ndarray] = []
    for k, t in enumerate(clock):
        follow.to(float(t))
        model, data = sim.model, sim.data
        mujoco.mj_kinematics(model, data)
        moving.append(moving_outline(model, data))
        centres.append(moving_centre(model, data))
        if k == 0:
            still = (model.body_weldid[model.geom_bodyid] == 0) & _shown(model)
            fixed = [
                data.geom_xpos[g] + outline(model, g) @ data.geom_xmat[g].reshape(3, 3).T
                for g in map(int, np.flatnonzero(still))
            ]
    return Clip(tuple(moving), tuple(centres), tuple(fixed))


def clip_points(rec: Recording, sim: Simulation, clock: Iterable[float]) -> np.ndarray:
    """The still camera's cloud of a clip (:meth:`Clip.points`)."""
    return sample_clip(rec, sim, clock).points()


def _basis(position: np.ndarray, look_at: np.ndarray, up: np.ndarray) -> np.ndarray:
    forward = look_at - position
    forward /= max(float(np.linalg.norm(forward)), 1e-12)
    right = np.cross(forward, up)
    right /= max(float(np.linalg.norm(right)), 1e-12)
    return np.stack([right, np.cross(right, forward), forward])


def _bounds(
    points: np.ndarray, position: np.ndarray, basis: np.ndarray, picture: Picture
) -> tuple[float, float, float, float] | None:
    """The points' extent on the picture in normalised coordinates (−1 to 1, y up):
    (left, right, bottom, top); None when one is behind the camera."""
    rel = (points - position) @ basis.T
    depth = rel[:, 2]
    if (depth <= 1e-9).any():
        return None
    ty = math.tan(math.radians(picture.fovy) / 2)
    tx = ty * picture.aspect
    x, y = rel[:, 0] / (depth * tx), rel[:, 1] / (depth * ty)
    return float(x.min()), float(x.max()), float(y.min()), float(y.max())


def fits(bounds: tuple[float, float, float, float] | None, picture: Picture) -> bool:
    """Inside the picture and clear of the readouts' box."""
    if bounds is None:
        return False
    left, right, bottom, top = bounds
    if left < -1 or right > 1 or bottom < -1 or top > 1:
        return False
    box_right, box_bottom = -1 + 2 * picture.box[0], 1 - 2 * picture.box[1]
    return not (left < box_right and top > box_bottom)


def frame_clip(
    points: np.ndarray,
    position: np.ndarray,
    look_at: np.ndarray,
    up: np.ndarray,
    picture: Picture,
) -> tuple[np.ndarray, np.ndarray]:
    """The page's camera (``position`` looking at ``look_at``) when ``points`` fit in
    it; else the same direction, aimed and moved so that they fill the picture below
    the readouts' box or right of it, whichever shows them larger (at least
    :data:`NEAREST` times the page's distance)."""
    position, look_at = np.asarray(position, float), np.asarray(look_at, float)
    up = np.asarray(up, float)
    basis = _basis(position, look_at, up)
    if len(points) == 0 or fits(_bounds(points, position, basis, picture), picture):
        return position, look_at
    distance = float(np.linalg.norm(look_at - position))
    box_right, box_bottom = -1 + 2 * picture.box[0], 1 - 2 * picture.box[1]
    regions = (  # the right side kept for the arrows' labels, written rightwards
        (-MARGIN, LABELS, -MARGIN, MARGIN * box_bottom),  # below the box
        (box_right + (1 - MARGIN), LABELS, -MARGIN, MARGIN),  # right of it
    )
    best = min(
        (_aim(points, look_at, distance, basis, picture, r) for r in regions if r[0] < r[1]),
        key=lambda found: found[1],
    )
    return best[0] - best[1] * basis[2], best[0]


def _aim(
    points: np.ndarray,
    look_at: np.ndarray,
    distance: float,
    basis: np.ndarray,
    picture: Picture,
    region: tuple[float, float, float, float],
) -> tuple[np.ndarray, float]:
    """(look-at point, distance) along ``basis``'s sight that fills ``region`` (left,
    right, bottom, top in normalised coordinates) with ``points``."""
    forward = basis[2]
    nearest = NEAREST * distance
    ty = math.tan(math.radians(picture.fovy) / 2)
    tx = ty * picture.aspect
    x0, x1, y0, y1 = region
    for _ in range(80):
        bounds = _bounds(points, look_at - distance * forward, basis, picture)
        if bounds is None:
            distance *= 1.5
            continue
        left, right, bottom, high = bounds
        look_at = (
            look_at
            + basis[0] * ((left + right) / 2 - (x0 + x1) / 2) * distance * tx
            + basis[1] * ((bottom + high) / 2 - (y0 + y1) / 2) * distance * ty
        )
        grow = max((right - left) / (x1 - x0), (high - bottom) / (y1 - y0))
        fitted = fits(_bounds(points, look_at - distance * forward, basis, picture), picture)
        if fitted and (grow > 0.95 or distance <= nearest):
            break
        # back when too large, nearer (gently: depth changes the picture) when small
        if grow > 1 or not fitted:
            distance *= max(grow, 1.02)
        else:
            distance = max(distance * (0.5 + 0.5 * grow), nearest)
    while not fits(_bounds(points, look_at - distance * forward, basis, picture), picture):
        distance *= 1.05  # never a part cut, whatever the loop reached
    return look_at, distance
