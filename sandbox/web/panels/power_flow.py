"""« Flux de puissance » (course 6.4.2): a power chain in series drawn live as a Sankey
diagram, as an inline SVG.

The power entering (the wind's, for the wind turbine) flows from left to right through
the organs the scene declares (:class:`~sandbox.physics.page.PowerFlow`): at each one a
loss leaves the band downward (orange), the power its inertia stores as kinetic energy
leaves upward (blue), or enters from above while the inertia slows down and gives it
back, and the rest goes on to the next organ. Every band's width is proportional to its
power, on one scale for the whole drawing, so that widths compare. Every number is the
frame's readout written as every table writes it (:func:`~sandbox.written.written`).

The drawing is pure: positions are computed from estimated text widths (an upper bound of
the usual sans-serif fonts), labels that would overlap go to another row, and, as long
as there is room, no arrow or dotted line crosses a label.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import viser

from sandbox.physics.page import FlowStage, PowerFlow
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.web.client.text import html_text
from sandbox.web.panels.folder import Folder
from sandbox.web.view3d.label_layout import text_width
from sandbox.written import written

if TYPE_CHECKING:
    from sandbox.web.loop.frame import Frame

FOLDER = "Flux de puissance"
MAIN, LOSS, STORED, ORGAN = "#9aa7b0", "#e67e22", "#2e86c1", "#34495e"
INK, GREY = "#111111", "#555555"
STORED_WORDS = "énergie cinétique stockée"
GIVEN_WORDS = "énergie cinétique rendue"

# -- sizes, in the SVG's units (about a pixel in the control panel) --------------------------
WIDTH = 400.0
"""Width of the drawing: one unit per pixel in a 400 px wide panel."""
MARGIN = 4.0
"""Room kept free at each side of the drawing."""
FONT = 14.0
"""Size of the names and numbers (the words under a number: :data:`SMALL`)."""
SMALL = 13.0
LINE = 17.0
"""Height of a line of text."""
ASCENT = 13.0
"""From the top of a line to its baseline."""
THICK = 56.0
"""Width of the widest band (the largest power)."""
BEND = 10.0
"""Inner radius of a branch's bend."""
HEAD = 8.0
"""Length of an arrowhead."""
FLARE = 4.0
"""How far an arrowhead reaches beyond each side of its band."""
GAP = 8.0
"""Room kept free between two labels side by side."""
WRAP = 130.0
"""Widest line of a loss's words (longer words are wrapped)."""
STORED_WRAP = 125.0
"""Widest line of the stored energy's words (« énergie cinétique » / « stockée »)."""
STORED_LINES = 3
"""Lines of a stored energy's label: the stored zone keeps room for one."""
END_WRAP = 200.0
"""Widest line of the words of the source and the sink."""
NEGLIGIBLE = 1e-3
"""A stored power smaller than this share of the source's is not drawn."""
START = MARGIN
"""Left end of the band."""
END = WIDTH - MARGIN - HEAD
"""Right end of the band (its arrowhead after it)."""
ROOM = "−8,888"
"""The widest number a label leaves room for (its rows do not change with the digits)."""


def _fmt(x: float) -> str:
    """A coordinate of the SVG (finite by construction)."""
    return f"{x:.2f}"


def _fine(x: float) -> str:
    """A band's width, precise enough for its ratio to another to be read back."""
    return f"{x:.6f}"


def _value(values: Mapping[str, float], name: str) -> float:
    """Readout ``name``'s value, NaN when it is not declared, missing or not a number."""
    if not name:
        return math.nan
    try:
        v = float(values[name])
    except (KeyError, TypeError, ValueError):
        return math.nan
    return v if math.isfinite(v) else math.nan


def _drawn(power: float) -> bool:
    """A power is drawn as a band when it is finite and positive."""
    return math.isfinite(power) and power > 0.0


def _width(text: str, size: float, bold: bool = False) -> float:
    return text_width(text, size) * (1.08 if bold else 1.0)


def _wrap(words: str, size: float, wide: float = WRAP) -> tuple[str, ...]:
    """``words`` on lines no wider than ``wide`` (a longer single word stays whole)."""
    lines: list[str] = []
    for word in words.split():
        if lines and _width(f"{lines[-1]} {word}", size) <= wide:
            lines[-1] = f"{lines[-1]} {word}"
        else:
            lines.append(word)
    return tuple(lines)


@dataclass(frozen=True)
class _Line:
    text: str
    size: float = FONT
    colour: str = INK
    bold: bool = False

    @property
    def width(self) -> float:
        return _width(self.text, self.size, self.bold)


@dataclass(frozen=True)
class _Label:
    """A block of lines to place in a zone of rows, centred on ``anchor`` when it fits.

    Attributes:
        anchor: The x its block is centred on (a stage, an arrow).
        lines: Its lines, top to bottom.
        room: The width it is given for placing (at least its lines' width).
        reach: The x range of the arrow or dotted line leading to it from the band
            (None: none).
    """

    anchor: float
    lines: tuple[_Line, ...]
    room: float
    reach: tuple[float, float] | None = None

    @property
    def height(self) -> float:
        return len(self.lines) * LINE + 4.0


@dataclass(frozen=True)
class _Placed:
    """A label at its row (0: nearest the band) between ``left`` and ``right``."""

    label: _Label
    row: int
    left: float
    right: float
    anchor: str = "middle"
    """The text-anchor of its lines: start (at ``left``), middle or end (at ``right``)."""


def _boxes(label: _Label) -> list[tuple[float, float, str]]:
    """Where ``label``'s block may go, kept in the drawing, in order of preference:
    centred on its anchor, else starting at its arrow, else ending at it (left, right,
    and the text-anchor of its lines)."""
    w = max([label.room, *(line.width for line in label.lines)])

    def kept(left: float) -> float:
        return max(min(left, WIDTH - MARGIN - w), MARGIN)

    out = [(kept(label.anchor - w / 2), "middle")]
    if label.reach is not None:
        out += [(kept(label.reach[0] - 2.0), "start"), (kept(label.reach[1] + 2.0 - w), "end")]
    return [(left, left + w, anchor) for left, anchor in out]


def _overlap(a0: float, a1: float, b0: float, b1: float, gap: float) -> bool:
    return a0 < b1 + gap and b0 < a1 + gap


def _crossings(
    row: int, left: float, right: float, label: _Label, placed: Sequence[_Placed]
) -> int | None:
    """How many lines from the band would cross the block at ``row`` or be crossed by its
    own line (a line runs through the rows nearer the band than its label's); None when
    a label of ``row`` overlaps it."""
    count = 0
    for p in placed:
        if p.row == row and _overlap(left, right, p.left, p.right, GAP):
            return None
        if label.reach is not None and p.row < row:
            count += _overlap(*label.reach, p.left, p.right, 2.0)
        if p.label.reach is not None and row < p.row:
            count += _overlap(*p.label.reach, left, right, 2.0)
    return count


def _pack(labels: Sequence[_Label]) -> list[_Placed]:
    """Each label, in the order given, where the fewest lines cross it (none, as long as
    there is room), then where it prefers to be (centred), then in the row nearest the
    band."""
    placed: list[_Placed] = []
    for label in labels:
        options = []
        for row in range(len(labels) + 1):
            for rank, (left, right, anchor) in enumerate(_boxes(label)):
                count = _crossings(row, left, right, label, placed)
                if count is not None:
                    options.append((count, rank, row, left, right, anchor))
        _, _, row, left, right, anchor = min(options)
        placed.append(_Placed(label, row, left, right, anchor))
    return placed


def _heights(placed: Sequence[_Placed], least: float = 0.0) -> list[float]:
    """Height of each row: its tallest block's, at least ``least`` for the first one."""
    rows = max((p.row + 1 for p in placed), default=1 if least > 0 else 0)
    out = [0.0] * rows
    for p in placed:
        out[p.row] = max(out[p.row], p.label.height)
    if out:
        out[0] = max(out[0], least)
    return out


def _text(placed: _Placed, top: float) -> str:
    """The lines of a placed block whose first line's top is at ``top``."""
    x = {"start": placed.left, "end": placed.right}.get(
        placed.anchor, (placed.left + placed.right) / 2
    )
    out = []
    for k, line in enumerate(placed.label.lines):
        weight = ' font-weight="600"' if line.bold else ""
        size = f' font-size="{line.size:g}"' if line.size != FONT else ""
        out.append(
            f'<text x="{_fmt(x)}" y="{_fmt(top + ASCENT + k * LINE)}" '
            f'text-anchor="{placed.anchor}" '
            f'fill="{line.colour}"{weight}{size}>{html_text(line.text)}</text>'
        )
    return "".join(out)


# -- the chain's geometry ---------------------------------------------------------------------
@dataclass(frozen=True)
class _Node:
    """One stage at its column, band positions relative to the source band's top."""

    stage: FlowStage
    x: float
    top_in: float
    thick_in: float
    loss: float
    stored: float
    shown_stored: bool
    top_out: float
    thick_out: float
    out: float

    @property
    def bottom_in(self) -> float:
        return self.top_in + self.thick_in

    @property
    def bottom_out(self) -> float:
        return self.top_out + self.thick_out


def _written(name: str, value: float, zero: float) -> str:
    """A power as every view writes it; "—" alone when there is none."""
    w = written(name, value, "W", zero=zero)
    return str(w) if math.isfinite(w.value) else w.number


def _room(name: str, size: float = FONT) -> float:
    """Width kept for a number of readout ``name`` (its page unit after :data:`ROOM`)."""
    unit = written(name, 0.0, "W").unit
    return _width(f"{ROOM}\u00a0{unit}", size)


def _chain(flow: PowerFlow, values: Mapping[str, float]) -> tuple[float, float, list[_Node]]:
    """The source's power, the largest power drawn (:data:`THICK` wide) and each stage at
    its column,
    its bands' tops relative to the source band's: a stored power leaves from the top of
    the band coming in, a power given back joins it on top, a loss leaves from its bottom."""
    source = _value(values, flow.source)
    powers = [source]
    for s in flow.stages:
        powers += [_value(values, s.power_out), _value(values, s.loss)]
        powers.append(abs(_value(values, s.stored)))
    largest = max((p for p in powers if _drawn(p)), default=0.0)
    reference = source if _drawn(source) else largest
    n = len(flow.stages)
    step = (END - START) / (n + 0.6)
    nodes: list[_Node] = []
    top, flowing = 0.0, source
    for i, s in enumerate(flow.stages):
        stored = _value(values, s.stored)
        shown = math.isfinite(stored) and reference > 0 and abs(stored) > NEGLIGIBLE * reference
        out = _value(values, s.power_out)
        top_out = top
        if shown:
            top_out = top + (1 if stored > 0 else -1) * _thick(abs(stored), largest)
        node = _Node(
            stage=s,
            x=START + step * (i + 1),
            top_in=top,
            thick_in=_thick(flowing, largest),
            loss=_value(values, s.loss),
            stored=stored,
            shown_stored=shown,
            top_out=top_out,
            thick_out=_thick(out, largest),
            out=out,
        )
        nodes.append(node)
        top, flowing = top_out, out
    return source, largest, nodes


def _thick(power: float, largest: float) -> float:
    """Width of the band of ``power`` when ``largest`` is :data:`THICK` wide, 0 when it
    draws none (a ratio first: finite for any finite powers)."""
    return THICK * (power / largest) if _drawn(power) and largest > 0 else 0.0


def _arrowhead(cx: float, half: float, base: float, tip: float, colour: str) -> str:
    """A triangle pointing from ``base`` to ``tip`` (vertical), ``half`` wide each side."""
    return (
        f'<polygon points="{_fmt(cx - half)},{_fmt(base)} {_fmt(cx + half)},{_fmt(base)} '
        f'{_fmt(cx)},{_fmt(tip)}" fill="{colour}"/>'
    )


def _band(flow_name: str, power: float, d: str, colour: str, width: float) -> str:
    return (
        f'<path data-flow="{html_text(flow_name)}" data-power="{power!r}" d="{d}" '
        f'stroke="{colour}" stroke-width="{_fine(width)}" fill="none"/>'
    )


def flow_svg(flow: PowerFlow, values: Mapping[str, float], zero: float = 0.0) -> str:
    """The chain ``flow`` at ``values`` (its readouts [W]) as a Sankey diagram, one inline
    SVG: left to right the power entering, then each stage, its loss down, its stored
    kinetic energy up (or given back from above), and what leaves at the right end.

    Above the band, each stage's name and the power it passes on (the last one's is the
    power leaving, written at the right end with ``sink_words``); below it, each loss and
    its words. Bands carry ``data-flow`` (``source``, ``out:<stage>``, ``loss:<stage>``,
    ``stored:<stage>``, ``given:<stage>``) and ``data-power`` (the readout [W]); their
    ``stroke-width`` is the band's width. A power that is missing, not finite, zero or
    negative draws no band; a missing one is written « — ».

    Args:
        flow: The scene's chain.
        values: The readouts, by name (those of a frame).
        zero: The scene's round-off for powers [W] (written 0 below it).
    """
    source, largest, nodes = _chain(flow, values)

    # -- the labels: stored or given back (above their arrow), losses (below it)
    stored_nodes = [nd for nd in nodes if nd.stage.stored and nd.shown_stored]
    stored_labels: list[_Label] = []
    lines: tuple[_Line, ...]
    for nd in stored_nodes:
        t = _thick(abs(nd.stored), largest)
        arm = BEND + t / 2
        centre = nd.x + arm if nd.stored > 0 else nd.x - arm
        words = STORED_WORDS if nd.stored > 0 else GIVEN_WORDS
        lines = (
            _Line(_written(nd.stage.stored, nd.stored, zero), FONT, STORED, True),
            *(_Line(w, SMALL, STORED) for w in _wrap(words, SMALL, STORED_WRAP)),
        )
        half = t / 2 + FLARE
        room = _room(nd.stage.stored)
        stored_labels.append(_Label(centre, lines, room, (centre - half, centre + half)))
    loss_nodes = [nd for nd in nodes if nd.stage.loss]
    loss_labels: list[_Label] = []
    for nd in loss_nodes:
        t = _thick(nd.loss, largest)
        centre = nd.x + BEND + t / 2
        lines = (
            _Line(_written(nd.stage.loss, nd.loss, zero), FONT, INK, True),
            *(_Line(w, SMALL, GREY) for w in _wrap(nd.stage.loss_words, SMALL)),
        )
        reach = (centre - t / 2 - FLARE, centre + t / 2 + FLARE) if t > 0 else None
        loss_labels.append(_Label(centre, lines, _room(nd.stage.loss), reach))

    # -- the labels of the columns, each joined to the band by a dotted line (the stages
    # first: nearest the band; the source and the sink, wider, at the ends of their rows)
    heads: list[_Label] = []
    joins: list[float] = []  # where each one's dotted line meets the band (relative y)
    for i, nd in enumerate(nodes):
        lines = (_Line(nd.stage.name, FONT, INK, True),)
        room = 0.0
        if i < len(nodes) - 1:  # the last one's is the power leaving, at the right end
            lines += (_Line(_written(nd.stage.power_out, nd.out, zero)),)
            room = _room(nd.stage.power_out)
        heads.append(_Label(nd.x, lines, room, (nd.x - 1, nd.x + 1)))
        joins.append(min(nd.top_in, nd.top_out) - 3.0)
    source_x = START + 0.2 * ((nodes[0].x if nodes else END) - START)
    lines = (
        *(_Line(w, SMALL, GREY) for w in _wrap(flow.source_words, SMALL, END_WRAP)),
        _Line(_written(flow.source, source, zero), FONT, INK, True),
    )
    heads.append(_Label(source_x, lines, _room(flow.source), (source_x - 1, source_x + 1)))
    joins.append(0.0)
    if nodes:
        last = nodes[-1]
        sink_x = END + HEAD / 2
        lines = (
            *(_Line(w, SMALL, GREY) for w in _wrap(flow.sink_words, SMALL, END_WRAP)),
            _Line(_written(last.stage.power_out, last.out, zero), FONT, INK, True),
        )
        room = _room(last.stage.power_out)
        heads.append(_Label(sink_x, lines, room, (sink_x - 1, sink_x + 1)))
        joins.append(last.top_out)

    head_placed = _pack(heads)
    stored_placed = _pack(stored_labels)
    loss_placed = _pack(loss_labels)
    head_rows = _heights(head_placed)
    has_stored = any(s.stored for s in flow.stages)
    stored_rows = _heights(stored_placed, STORED_LINES * LINE + 4.0 if has_stored else 0.0)
    loss_rows = _heights(loss_placed)

    # -- vertical layout, top to bottom: heads, stored zone, band, losses
    tops = [0.0] + [nd.top_in for nd in nodes] + [nd.top_out for nd in nodes]
    bottoms = [_thick(source, largest)] + [nd.bottom_in for nd in nodes]
    bottoms += [nd.bottom_out for nd in nodes]
    head_bottom = 4.0 + sum(head_rows)
    stored_bottom = head_bottom + sum(stored_rows)
    shift = stored_bottom + (BEND + HEAD + 6.0 if has_stored else 8.0) - min(tops)
    band_bottom = shift + max(bottoms)
    loss_top = band_bottom + BEND + HEAD + 6.0
    height = loss_top + sum(loss_rows) + 4.0

    def above(bottom: float, rows: Sequence[float], row: int) -> float:
        return bottom - sum(rows[: row + 1])

    out: list[str] = []
    # the main band: the source, then what each stage passes on, an arrowhead at the end
    edges = [START] + [nd.x for nd in nodes] + [END]
    segments = [("source", source, 0.0)]
    segments += [(f"out:{nd.stage.name}", nd.out, nd.top_out) for nd in nodes]
    for (flow_name, power, rel_top), x0, x1 in zip(segments, edges, edges[1:], strict=False):
        t = _thick(power, largest)
        if t > 0:
            y = shift + rel_top + t / 2
            d = f"M{_fmt(x0)} {_fmt(y)}H{_fmt(x1)}"
            out.append(_band(flow_name, power, d, MAIN, t))
    power, rel_top = segments[-1][1:]
    if _thick(power, largest) > 0:
        t, y0 = _thick(power, largest), shift + rel_top
        out.append(
            f'<polygon points="{_fmt(END)},{_fmt(y0 - FLARE)} {_fmt(END + HEAD)},'
            f'{_fmt(y0 + t / 2)} {_fmt(END)},{_fmt(y0 + t + FLARE)}" fill="{MAIN}"/>'
        )

    # losses: down from the bottom of the band coming in, to their label's row
    for nd, placed in zip(loss_nodes, loss_placed, strict=True):
        t = _thick(nd.loss, largest)
        if t <= 0:
            continue
        arm = BEND + t / 2
        y, cx = shift + nd.bottom_in - t / 2, nd.x + arm
        tip = loss_top + sum(loss_rows[: placed.row]) - 2.0
        d = (
            f"M{_fmt(nd.x)} {_fmt(y)}A{_fmt(arm)} {_fmt(arm)} 0 0 1 {_fmt(cx)} "
            f"{_fmt(y + arm)}V{_fmt(tip - HEAD)}"
        )
        out.append(_band(f"loss:{nd.stage.name}", nd.loss, d, LOSS, t))
        out.append(_arrowhead(cx, t / 2 + FLARE, tip - HEAD, tip, LOSS))

    # stored kinetic energy: up from the top of the band; given back: down into it
    for nd, placed in zip(stored_nodes, stored_placed, strict=True):
        t = _thick(abs(nd.stored), largest)
        if t <= 0:
            continue
        arm = BEND + t / 2
        tip = above(stored_bottom, stored_rows, placed.row) + placed.label.height
        if nd.stored > 0:
            y, cx = shift + nd.top_in + t / 2, nd.x + arm
            d = (
                f"M{_fmt(nd.x)} {_fmt(y)}A{_fmt(arm)} {_fmt(arm)} 0 0 0 {_fmt(cx)} "
                f"{_fmt(y - arm)}V{_fmt(tip + HEAD)}"
            )
            out.append(_band(f"stored:{nd.stage.name}", nd.stored, d, STORED, t))
            out.append(_arrowhead(cx, t / 2 + FLARE, tip + HEAD, tip, STORED))
        else:
            y, cx = shift + nd.top_out + t / 2, nd.x - arm
            d = (
                f"M{_fmt(cx)} {_fmt(tip)}V{_fmt(y - arm)}A{_fmt(arm)} {_fmt(arm)} "
                f"0 0 0 {_fmt(nd.x)} {_fmt(y)}"
            )
            out.append(_band(f"given:{nd.stage.name}", nd.stored, d, STORED, t))

    # the organs: a dark bar across the band at each stage
    for nd in nodes:
        y0 = shift + min(nd.top_in, nd.top_out) - 3.0
        y1 = shift + max(nd.bottom_in, nd.bottom_out) + 3.0
        out.append(
            f'<rect x="{_fmt(nd.x - 1.5)}" y="{_fmt(y0)}" width="3" '
            f'height="{_fmt(max(y1 - y0, 6.0))}" fill="{ORGAN}"/>'
        )

    # the dotted lines from the columns' labels down to the band, broken around the
    # stored zone's labels
    for placed, join in zip(head_placed, joins, strict=True):
        x, to = placed.label.anchor, shift + join
        y = above(head_bottom, head_rows, placed.row) + placed.label.height
        gaps = sorted(
            (above(stored_bottom, stored_rows, p.row), p.label.height)
            for p in stored_placed
            if p.left - 2.0 <= x <= p.right + 2.0
        )
        gaps = [(g0, g0 + h) for g0, h in gaps]
        for g0, g1 in [*gaps, (to, to)]:
            if g0 > y:
                out.append(
                    f'<path d="M{_fmt(x)} {_fmt(y)}V{_fmt(min(g0, to))}" stroke="{GREY}" '
                    'stroke-width="1" stroke-dasharray="2 3" fill="none"/>'
                )
            y = max(y, g1)

    # the words and numbers
    for placed in head_placed:
        out.append(_text(placed, above(head_bottom, head_rows, placed.row) + 2.0))
    for placed in stored_placed:
        out.append(_text(placed, above(stored_bottom, stored_rows, placed.row) + 2.0))
    for placed in loss_placed:
        out.append(_text(placed, loss_top + sum(loss_rows[: placed.row]) + 2.0))

    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {WIDTH:g} {math.ceil(height)}" '
        'width="100%" role="img" aria-label="Diagramme de Sankey du flux de puissance" '
        f'font-family="sans-serif" font-size="{FONT:g}" style="display:block;max-width:40em">'
        f"{''.join(out)}</svg>"
    )


LEGEND = (
    "La largeur de chaque bande est proportionnelle à la puissance qu'elle transporte ; "
    "sous le nom de chaque organe, la puissance qu'il transmet au suivant ; en orange : "
    "les pertes ; en bleu : l'énergie cinétique stockée par les inerties (rendue quand "
    "elles ralentissent)."
)


def panel_html(flow: PowerFlow, values: Mapping[str, float], zero: float = 0.0) -> str:
    """The whole folder: the diagram, the chain's overall efficiency when the scene
    declares it (its readout, written as the tables write it), and the legend."""
    parts = [flow_svg(flow, values, zero)]
    if flow.efficiency:
        eta = written(flow.efficiency, _value(values, flow.efficiency), "")
        parts.append(
            '<p style="margin:0.4em 0 0;font-weight:600">'
            f"Rendement global η = {html_text(str(eta))}</p>"
        )
    parts.append(
        f'<p style="margin:0.3em 0 0;color:#555">{html_text(LEGEND, limit=len(LEGEND))}</p>'
    )
    return f'<div class="sandbox-power-flow">{"".join(parts)}</div>'


# -- the panel --------------------------------------------------------------------------------
def flow_names(flow: PowerFlow) -> tuple[str, ...]:
    """Every readout ``flow`` shows: the source, each stage's power passed on, loss and
    stored power when declared, the overall efficiency when declared."""
    names = [flow.source]
    for s in flow.stages:
        names += [n for n in (s.power_out, s.loss, s.stored) if n]
    if flow.efficiency:
        names.append(flow.efficiency)
    return tuple(dict.fromkeys(names))


class PowerFlowPanel:
    """Folder « Flux de puissance » of a scene that declares a power chain.

    Create it with :meth:`create` (None for scenes without one); the view refreshes it
    from each frame that brings readouts, at the panels' rate.
    """

    def __init__(self, gui: viser.GuiApi, sim: ReadOnlySimulation, flow: PowerFlow) -> None:
        self.sim = sim
        self.flow = flow
        scene = sim.scene
        self.zero = scene.zero_for("W") if scene is not None else 0.0
        self.names = flow_names(flow)
        self.folder = gui.add_folder(FOLDER, expand_by_default=True)
        with self.folder:
            self.html = gui.add_html("")
        self._shown = ""

    @classmethod
    def create(cls, gui: viser.GuiApi, sim: ReadOnlySimulation) -> PowerFlowPanel | None:
        """The panel when ``sim`` is of a scene that declares a power chain, else None."""
        scene = sim.scene
        flow = scene.page.power_flow if scene is not None else None
        return cls(gui, sim, flow) if flow is not None else None

    def pickable(self) -> list[Folder]:
        """Its folder: it shows the frame's readouts."""
        return [Folder(FOLDER, self.folder, self._refresh, names=lambda: self.names)]

    def _refresh(self, frame: Frame) -> None:
        self.refresh(frame.readouts)

    def refresh(self, readouts: Mapping[str, float] | None) -> bool:
        """Redraw with ``readouts`` (the frame's); True when the text changed."""
        text = panel_html(self.flow, readouts or {}, self.zero)
        if text == self._shown:
            return False
        self._shown = text
        self.html.content = text
        return True
