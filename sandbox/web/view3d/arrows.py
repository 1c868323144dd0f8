"""Force arrows of the scene (e.g. bearing forces) drawn in the 3D view every frame.

Arrows are sized to the mechanism, not to the whole model (:mod:`sandbox.web.view3d.arrow_scale`
says how long each is drawn). The user multiplies their lengths with
:attr:`ArrowLayer.user_scale` ("Échelle des flèches").

Labels name the arrow's point of application, not its tip: the forces at a bearing turn
with the rotor, 25 to 100 times a second, and a label following their tip hopped across
the view every frame. The labels of the arrows sharing a point ride on one frame node at
that point (one message a frame when the point moves, none when it stays), stacked beside
it by :mod:`sandbox.web.view3d.label_layout` in the browser's camera, with a leader line in the
arrow's colour when they stand off. Their text and their place change together, at most
the panels' refresh, with the values the tables and the overlay show at that instant.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from sandbox.physics.page import Arrow
from sandbox.physics.snapshot import Snapshot
from sandbox.web.client import wire
from sandbox.web.view3d.arrow_scale import (
    MIN_LENGTH,
    SHAFT,
    USER_SCALES,
    arrow_points,
    auto_factor,
    caption,
)
from sandbox.web.view3d.camera import overlay_box, read_camera
from sandbox.web.view3d.geoms import mechanism_size
from sandbox.web.view3d.label_layout import (
    LABEL_EM,
    PX_PER_SCALE,
    Block,
    Camera,
    Placement,
    Rect,
    label_size,
    place,
)

if TYPE_CHECKING:
    import viser


MOVE = 2e-4
"""Smallest move worth a message, as a fraction of the mechanism's size (a fifth of a
pixel when the mechanism spans a 1000-pixel view): a still arrow or label sends nothing."""
LAYOUT_RATE = 4.0
"""Placements of the labels per second at most [Hz] while their texts change with the
panels (10 Hz): a place is computed again at once when a label appears, hides or gets
wider than its room; its point's moves are followed by the label riding on it."""


FONT_PX = 16
"""Text size of the page [px] until the view says otherwise ("Taille du texte")."""

LEADER_PX = 2.0
"""Thickness of a leader line [px]."""

LEADER_MIN_PX = 8.0
"""A label whose box is nearer its point than this [px] gets no leader line."""

SNAP_PX = 0.5
"""A label's place moves only when its image would move by more than this [px]."""


class Marks(Protocol):
    """Other labels of the 3D view (the masses named on a rotor), which the arrows'
    labels keep clear of: :class:`~sandbox.web.view3d.renderer.SceneRenderer`."""

    def label_boxes(self, camera: Camera, em: float) -> list[Rect]: ...
    def set_label_scale(self, scale: float) -> None: ...


class ArrowLayer:
    """The scene's arrows as one viser arrows node, and one label per arrow, in a client's
    (or the broadcast) scene.

    Each drawn frame sends one message for every arrow that moved (the node's points) and
    one per point of application that moved more than :data:`MOVE` (its labels ride on
    it); which arrows show (round-off, a lesson's choice) changes the points and colours
    together. :meth:`relabel` writes the values (the readouts of the panel's instant, the
    same numbers as the overlay's) and places the labels.

    Args:
        scene: A viser ``SceneApi``.
        arrows: The scene's arrows.
        extent: Size of the model [m] (used when ``size`` is not given).
        size: Size of the mechanism [m] (:func:`mechanism_size`): thickness and reach;
            None measures it on the first :meth:`update`.
        units: Unit of each arrow's vector (contract form), when the arrows do not say.
        zero: Round-off of the scene by unit (``Scene.zero``): smaller magnitudes read 0.
        prefix: Scene-tree folder above ``/arrows`` and ``/arrow_labels``.
    """

    def __init__(
        self,
        scene: viser.SceneApi,
        arrows: Sequence[Arrow],
        *,
        extent: float,
        size: float | None = None,
        units: Sequence[str] = (),
        zero: Mapping[str, float] | None = None,
        prefix: str = "",
    ) -> None:
        self.zero = dict(zero or {})
        self.arrows = tuple(arrows)
        given = tuple(units) + ("",) * (len(self.arrows) - len(units))
        self.units = tuple(a.unit or u for a, u in zip(self.arrows, given, strict=True))
        self.size = float(size) if size is not None and size > 0 else float(extent) or 1.0
        self._measured = size is not None and size > 0
        self.user_scale = 1.0
        self.factors: dict[str, float] = {}  # unit -> automatic length factor
        self.colors = np.array([a.color for a in self.arrows], dtype=np.uint8).reshape(-1, 3)
        shaft = SHAFT * self.size
        self.node = scene.add_arrows(
            f"{prefix}/arrows",
            points=np.zeros((1, 2, 3), dtype=np.float32),
            colors=self.colors[:1] if len(self.colors) else (0, 0, 0),
            shaft_radius=shaft,
            head_radius=2.5 * shaft,
            head_length=6 * shaft,
            visible=False,
        )
        # arrows starting from the same named point share a frame node there
        points: dict[str, list[int]] = {}
        for k, a in enumerate(self.arrows):
            points.setdefault(a.point or f"_{a.name}", []).append(k)
        self.groups: list[list[int]] = list(points.values())
        self.group_of = [0] * len(self.arrows)
        for g, members in enumerate(self.groups):
            for k in members:
                self.group_of[k] = g
        self.font_px = float(FONT_PX)
        scale = self.font_scale
        folder = f"{prefix}/arrow_labels"
        self.frames: list[viser.FrameHandle] = [
            scene.add_frame(f"{folder}/{_node_name(name)}", show_axes=False) for name in points
        ]
        self.labels: list[viser.LabelHandle] = [
            scene.add_label(
                f"{folder}/{_node_name(self._point(k))}/{_node_name(a.name)}",
                a.label,
                visible=False,
                anchor="top-left",
                font_screen_scale=scale,
            )
            for k, a in enumerate(self.arrows)
        ]
        self.leaders: list[Any] = [
            scene.add_line_segments(
                f"{folder}/{_node_name(name)}/leaders",
                points=np.zeros((1, 2, 3), dtype=np.float32),
                colors=(0, 0, 0),
                thickness=LEADER_PX,
                thickness_units="screen",
                visible=False,
            )
            for name in points
        ]
        self.enabled: set[str] | None = None  # None: every arrow
        n = len(self.arrows)
        self.magnitudes = [0.0] * n
        self.shown = [False] * n
        self.origins = np.zeros((n, 3))
        self.ends = np.zeros((n, 3))
        self._zero = np.array([self.zero.get(u, 0.0) for u in self.units])
        self._by_unit: dict[str, list[int]] = {}
        for k, unit in enumerate(self.units):
            self._by_unit.setdefault(unit, []).append(k)
        self._sent_points = np.zeros((0, 2, 3), dtype=np.float32)
        self._sent_mask: tuple[bool, ...] = (False,) * n
        self._frame_at = np.full((len(self.groups), 3), np.nan)
        self._seen = np.zeros(n, dtype=bool)  # arrows shown since the last relabel
        self._offsets = np.zeros((n, 3))  # each label's place on its frame [m]
        self._leader_sent: list[np.ndarray | None] = [None] * len(self.groups)
        self._placed: list[Placement | None] = [None] * len(self.groups)
        self._reserved = [0.0] * n  # widest text of each label so far [px]
        self._laid_at = -math.inf  # when the labels were last placed (time.monotonic)
        self.camera: Camera | Any = None  # a viser CameraHandle, or a fixed Camera
        self.laid_out: Camera | None = None  # the camera of the last layout
        self.font: Callable[[], float] | None = None  # the page's text size [px]
        self.marks: Marks | None = None
        self.messages = 0  # messages queued so far (the counted guard of the tests)
        self.text_messages = 0  # label texts written so far
        self.dirty = False  # a setting changed since the last draw: draw again

    def _point(self, k: int) -> str:
        return self.arrows[k].point or f"_{self.arrows[k].name}"

    def watch(
        self,
        camera: Any,
        *,
        font: Callable[[], float] | None = None,
        marks: Marks | None = None,
    ) -> None:
        """Place the labels in a browser's view from now on.

        Args:
            camera: Its viser ``CameraHandle`` (read at each placing), or a fixed
                :class:`~sandbox.web.view3d.label_layout.Camera`.
            font: The page's text size [px] ("Taille du texte"), which the labels follow.
            marks: Other labels of the view, kept clear of and sized alike.
        """
        self.camera, self.font, self.marks = camera, font, marks

    @property
    def font_scale(self) -> float:
        """viser's ``font_screen_scale`` of the labels at the page's text size."""
        return LABEL_EM * self.font_px / PX_PER_SCALE

    def set_scale(self, factor: float) -> None:
        """The user's factor on every arrow's length (clipped to :data:`USER_SCALES`)."""
        low, high = USER_SCALES
        if math.isfinite(factor):
            self.user_scale = min(max(float(factor), low), high)
            self.dirty = True

    def resize(self, size: float) -> None:
        """Size the shafts and heads, and the reach, to a mechanism of ``size`` metres."""
        if not (math.isfinite(size) and size > 0):
            return
        self.size, self._measured = float(size), True
        self.factors.clear()
        shaft = SHAFT * self.size
        wire.set_props(
            self.node, shaft_radius=shaft, head_radius=2.5 * shaft, head_length=6 * shaft
        )
        self.messages += 1

    @property
    def shaft_radius(self) -> float:
        """Radius of the shafts [m] (heads are 2.5 and 6 shafts)."""
        return SHAFT * self.size

    def update(self, snapshot: Snapshot) -> None:
        """Evaluate the arrows on ``snapshot`` and draw them (a replay's export, tests):
        a live view draws the frame's own picture with :meth:`draw`."""
        if not self._measured:
            self.resize(mechanism_size(snapshot.model, snapshot.data))
        ends = np.full((len(self.arrows), 2, 3), np.nan)
        sizes = np.full(len(self.arrows), np.nan)
        for k, arrow in enumerate(self.arrows):
            start, end, magnitude = arrow_points(arrow, snapshot)
            ends[k, 0], ends[k, 1], sizes[k] = start, end, magnitude
        self.draw(ends, sizes)

    def draw(self, ends: np.ndarray, magnitudes: np.ndarray) -> None:
        """Move every arrow to its start and end ``ends`` (A, 2, 3) [m, at the scene's
        scale] with the norms ``magnitudes`` (A,) of their vectors; an arrow whose values
        are not finite is hidden. Vectorised over the arrows (a frame's cost)."""
        self.dirty = False
        starts = np.asarray(ends[:, 0], dtype=float)
        sizes = np.asarray(magnitudes, dtype=float)
        vectors = np.asarray(ends[:, 1], dtype=float) - starts
        with np.errstate(invalid="ignore"):
            vectors[np.abs(sizes) <= self._zero] = 0.0  # round-off: no arrow, not one
            # blown up to a visible length by the automatic scale
            lengths = np.sqrt((vectors * vectors).sum(axis=1))
        wanted = self._wanted()
        wanted_list, length_list = wanted.tolist(), lengths.tolist()  # Python floats: cheap
        scale = np.empty(len(self.arrows))
        for unit, members in self._by_unit.items():
            picked = [
                length_list[k] for k in members if wanted_list[k] and math.isfinite(length_list[k])
            ]
            if picked:
                self.factors[unit] = auto_factor(
                    self.factors.get(unit, 1.0), max(picked), self.size
                )
            scale[members] = self.factors.get(unit, 1.0) * self.user_scale
        tips = starts + scale[:, None] * vectors
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(tips).all(axis=1) & np.isfinite(starts).all(axis=1)
            show = ok & wanted & (scale * lengths > MIN_LENGTH)
        self.magnitudes = np.where(ok, sizes, math.nan).tolist()
        self.origins = np.where(ok[:, None], starts, self.origins)
        self.ends = np.where(ok[:, None], tips, self.ends)
        self.shown = show.tolist()
        self._send(np.stack([starts[show], tips[show]], axis=1), show)
        self._carry_labels(show)

    def _wanted(self) -> np.ndarray:
        """The arrows a lesson's step asks for (all when it asks for none)."""
        if self.enabled is None:
            return np.ones(len(self.arrows), dtype=bool)
        return np.array([a.name in self.enabled for a in self.arrows], dtype=bool)

    def _send(self, points: np.ndarray, show: np.ndarray) -> None:
        """One message for the node: its points when they moved, with the colours when
        the set of arrows shown changed; its visibility when none or some show."""
        mask = tuple(show.tolist())
        if not len(points):
            if self.node.visible:
                self.node.visible = False
                self.messages += 1
            self._sent_mask = mask
            return
        points = points.astype(np.float32)
        if mask != self._sent_mask or points.shape != self._sent_points.shape:
            wire.set_props(self.node, points=points, colors=self.colors[show])
            self.messages += 1
        elif np.abs(points - self._sent_points).max() > MOVE * self.size:
            wire.set_props(self.node, points=points)
            self.messages += 1
        else:
            points = self._sent_points  # below what a pixel shows: keep the sent one
        self._sent_points, self._sent_mask = points, mask
        if not self.node.visible:
            self.node.visible = True
            self.messages += 1

    def _anchor(self, g: int) -> np.ndarray | None:
        """Point of application of group ``g``: its first arrow shown (None: none)."""
        for k in self.groups[g]:
            if self.shown[k]:
                return np.asarray(self.origins[k], dtype=float)
        return None

    def _carry_labels(self, show: np.ndarray) -> None:
        """Each point of application's frame where its arrows start (sent when it moved
        by more than :data:`MOVE`): its labels and leaders ride on it. Labels show and
        hide with their text (:meth:`relabel`): a force passing through 0 at 50 Hz would
        make its label blink."""
        for g, frame in enumerate(self.frames):
            at = self._anchor(g)
            if at is None:
                continue
            if not (np.abs(at - self._frame_at[g]) <= MOVE * self.size).all():
                wire.set_position(frame, at)
                self._frame_at[g] = at
                self.messages += 1
        self._seen |= show

    def caption(
        self,
        k: int,
        readouts: Mapping[str, float] | None = None,
        magnitudes: Sequence[float] | np.ndarray | None = None,
    ) -> str:
        """The label of arrow ``k``: its words, value and unit ("Palier A : 0,91 N"): the
        readout of its name in ``readouts`` when there is one (the pilon's sign, as the
        tables write it), else its magnitude (of ``magnitudes`` when given: the held
        instant's, else the last drawn)."""
        arrow = self.arrows[k]
        reading = readouts.get(arrow.name) if readouts is not None else None
        size = self.magnitudes[k] if magnitudes is None else magnitudes[k]
        return caption(arrow, float(size), self.units[k], self.zero, reading=reading)

    def relabel(
        self,
        readouts: Mapping[str, float] | None = None,
        magnitudes: Sequence[float] | np.ndarray | None = None,
    ) -> None:
        """Write the labels and place them, at the panels' refresh: the values of the
        frame the tables and the overlay show (``readouts``, read from the state the
        arrows were drawn at, or from a fast rotation's held instant whose arrows'
        ``magnitudes`` are given), so that one screen shows one instant."""
        if magnitudes is not None and len(magnitudes) != len(self.arrows):
            magnitudes = None
        self._follow_font()
        seen = self._seen | np.asarray(self.shown, dtype=bool)
        self._seen = np.zeros_like(seen)
        em = PX_PER_SCALE * self.font_scale
        moved = self.laid_out is None  # the room of a label changes: placed again now
        for k, label in enumerate(self.labels):
            text = self.caption(k, readouts, magnitudes)
            if label.text != text:
                label.text = text
                self.messages += 1
                self.text_messages += 1
                moved = moved or label_size(text, em)[0] > self._reserved[k]
            if label.visible != bool(seen[k]):
                label.visible = bool(seen[k])
                self.messages += 1
                moved = True
        now = time.monotonic()
        if moved or now - self._laid_at >= 1.0 / LAYOUT_RATE:
            self._laid_at = now
            self.layout()

    def _follow_font(self) -> None:
        """The labels at the page's text size, when it changed."""
        if self.font is None:
            return
        try:
            px = float(self.font())
        except (TypeError, ValueError):
            return
        if not (math.isfinite(px) and 8 <= px <= 64) or px == self.font_px:
            return
        self.font_px = px
        self._reserved = [0.0] * len(self.arrows)
        scale = self.font_scale
        for label in self.labels:
            label.font_screen_scale = scale
            self.messages += 1
        if self.marks is not None:
            self.marks.set_label_scale(scale)

    def layout(self) -> None:
        """Place each point's labels beside it in the watched camera's view (nothing
        without one): sent only where a place changed."""
        camera = read_camera(self.camera)
        if camera is None:
            return
        self.laid_out = camera
        em = PX_PER_SCALE * self.font_scale
        blocks: list[Block] = []
        rows: list[list[int]] = []
        depths: list[float] = []
        for g, members in enumerate(self.groups):
            ks = [k for k in members if self.labels[k].visible]
            at = self._frame_at[g]
            x, y, depth = camera.project(at) if ks and np.isfinite(at).all() else (math.nan,) * 3
            sizes = []
            for k in ks:
                width, height = label_size(self.labels[k].text, em)
                self._reserved[k] = max(self._reserved[k], width)
                sizes.append((self._reserved[k], height))
            blocks.append(Block((x, y), tuple(sizes)))
            rows.append(ks)
            depths.append(depth)
        cx, cy, _ = camera.project(np.asarray(camera.look_at, dtype=float))
        avoid = [overlay_box(camera, self.font_px)]
        if self.marks is not None:
            avoid += self.marks.label_boxes(camera, em)
        view = (4.0, 4.0, camera.width - 4.0, camera.height - 4.0)
        placed = place(blocks, view=view, centre=(cx, cy), avoid=avoid, before=self._placed)
        self._placed = placed
        for g, (block, spot) in enumerate(zip(blocks, placed, strict=True)):
            if spot is None:
                self._lead(g, [], 0.0)
                continue
            depth, (px, py) = depths[g], block.point
            tolerance = SNAP_PX * depth / camera.focal
            ends = []
            for k, (x, y, anchor), (w, h) in zip(
                rows[g], spot.rows(block), block.sizes, strict=True
            ):
                offset = camera.offset(x - px, y - py, depth)
                label = self.labels[k]
                if label.anchor != anchor:
                    label.anchor = anchor  # type: ignore[assignment]
                    self.messages += 1
                if not (np.abs(offset - self._offsets[k]) <= tolerance).all():
                    wire.set_position(label, offset)
                    self._offsets[k] = offset
                    self.messages += 1
                left = x if anchor == "top-left" else x - w if anchor == "top-right" else x - w / 2
                nx, ny = min(max(px, left), left + w), min(max(py, y), y + h)
                if math.hypot(nx - px, ny - py) >= LEADER_MIN_PX:
                    ends.append((k, camera.offset(nx - px, ny - py, depth)))
            self._lead(g, ends, tolerance)

    def _lead(self, g: int, ends: list[tuple[int, np.ndarray]], tolerance: float) -> None:
        """Leader lines of group ``g`` from its point to each label's nearest edge."""
        node = self.leaders[g]
        if not ends:
            if node.visible:
                node.visible = False
                self.messages += 1
            self._leader_sent[g] = None
            return
        points = np.zeros((len(ends), 2, 3), dtype=np.float32)
        points[:, 1] = [end for _, end in ends]
        sent = self._leader_sent[g]
        if sent is None or sent.shape != points.shape or np.abs(sent - points).max() > tolerance:
            colors = np.repeat(self.colors[[k for k, _ in ends]][:, None, :], 2, axis=1)
            wire.set_props(node, points=points, colors=colors)
            self._leader_sent[g] = points
            self.messages += 1
        if not node.visible:
            node.visible = True
            self.messages += 1

    def only(self, names: Sequence[str] | None) -> None:
        """Show only the arrows called ``names`` (None: all), from the next update on."""
        self.enabled = None if names is None else set(names)
        self.dirty = True

    def hide(self) -> None:
        """Hide every arrow (e.g. after a divergence)."""
        if self.node.visible:
            self.node.visible = False
        for k, label in enumerate(self.labels):
            if label.visible:
                label.visible = False
            self.shown[k] = False
        for node in self.leaders:
            if node.visible:
                node.visible = False
        self._leader_sent = [None] * len(self.groups)
        self._sent_mask = tuple(self.shown)


def _node_name(name: str) -> str:
    """A scene-tree name part from a scene's word (no "/", which nests nodes)."""
    return "".join(c if c.isalnum() or c in "_-" else "_" for c in name) or "_"
