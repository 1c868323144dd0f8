"""Markdown of the readout panels, in the course's notation (pure functions, no server).

Values come from :meth:`Simulation.readouts`; torsors are moved to the chosen point
and basis with :class:`sandbox.mechanics.Torsor` (the web layer computes no physics).
Numbers are written the French way (:func:`sandbox.web.client.text.number`: decimal comma,
×10ⁿ, 0 below the scene's round-off). Each simulated value sits in
``<span data-readout="NAME" data-value="1.25">1,25</span>``: tests and scripts find it
in the page and read the exact value (with a dot) from ``data-value``. Names, units,
docs and labels are escaped (:func:`cell`): a user's file may name a body
``<img onerror=…>``, and a ``|`` in a tooltip would cut the table's row.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sandbox.bench.plot import duration
from sandbox.mechanics import Torsor
from sandbox.physics.energy import frame_power
from sandbox.physics.model import integrator_words
from sandbox.physics.units import shown_scale
from sandbox.web.client.text import html_text, number, table_row
from sandbox.written import written

RELATIVE_ZERO = 1e-9
"""A component below this fraction of the largest one of its table is round-off (shown 0)."""


def fmt(value: float, *, digits: int = 4, floor: float = 0.0) -> str:
    """A number for French readers: ``digits`` significant digits, decimal comma, ×10ⁿ,
    0 when ``|value| <= floor``, — if not finite (:func:`sandbox.web.client.text.number`)."""
    return number(float(value), digits, zero=floor)


def written_floor(values: Iterable[float], digits: int = 4) -> float:
    """Half the last digit written of the largest ``|value|`` at ``digits`` significant
    digits: the components of one vector, or the powers of one balance, are written to
    the precision of the largest, so a component below this reads 0 beside it (the heavy
    top's vertical momentum, 2×10⁻⁹ kg·m/s beside 0,03; the compressor's loop closure
    working 0,009 W beside a motor's 390 W), a component above it keeps its digits."""
    big = max((abs(float(v)) for v in values), default=0.0)
    if not (math.isfinite(big) and big > 0.0):
        return 0.0
    return 0.5 * 10.0 ** (math.floor(math.log10(big)) - (digits - 1))


def cell(value: object, limit: int = 200) -> str:
    """``value`` as the text of a markdown table cell or HTML attribute: HTML escaped, and
    ``|`` written as an entity (a bare ``|`` ends the cell, even inside an attribute,
    and the rest of the cell then shows as raw HTML)."""
    return html_text(value, limit).replace("|", "&#124;")


@functools.lru_cache(maxsize=4096)
def _cell_of(name: str) -> str:
    """:func:`cell` of a readout's name or unit, escaped once (tables are rewritten ten
    times a second; their words do not change)."""
    return cell(name)


def _span(name: str, text: str, value: float | None = None) -> str:
    exact = f' data-value="{value!r}"' if value is not None else ""
    return f'<span data-readout="{_cell_of(name)}"{exact}>{text}</span>'


@dataclass(frozen=True)
class Row:
    """One line of the scene table.

    Attributes:
        name: Contract name of the readout (never shown: it names the ``data-readout``).
        unit: Contract unit (shown as :func:`~sandbox.physics.units.shown_scale`: ω in
            tr/min, an angle in degrees).
        doc: English sentence, the tooltip while ``hint`` is empty.
        label: French words with the course's symbol ("" shows ``name``).
        hint: French tooltip.
        zero: Round-off [unit]: values at most this are shown 0.
    """

    name: str
    unit: str
    doc: str = ""
    label: str = ""
    hint: str = ""
    zero: float = 0.0


@dataclass(frozen=True)
class TorsorSpec:
    """How to show one generic torsor.

    Attributes:
        prefix: Readout prefix (``kin``, ``dyn``, ``sup``).
        symbol: Course symbol as HTML, e.g. ``{𝒟<sub>Σ/R₀</sub>}``.
        caption: Short French caption.
        r_unit: Unit of the resultant.
        m_unit: Unit of the moment.
    """

    prefix: str
    symbol: str
    caption: str
    r_unit: str
    m_unit: str


TORSORS = (
    TorsorSpec("kin", "{𝒞<sub>Σ/R₀</sub>}", "Torseur cinétique", "kg·m/s", "kg·m²/s"),
    TorsorSpec("dyn", "{𝒟<sub>Σ/R₀</sub>}", "Torseur dynamique", "N", "N·m"),
    TorsorSpec("sup", "{𝒯<sub>0/Σ</sub>}", "Action du bâti 0 sur Σ", "N", "N·m"),
)


def torsor_at_o(values: Mapping[str, float], prefix: str) -> Torsor:
    """The generic torsor ``prefix`` (readouts at O, world axes) as a :class:`Torsor`."""
    r = np.array([values[f"{prefix}_R_{c}"] for c in "xyz"], dtype=float)
    m = np.array([values[f"{prefix}_M_{c}"] for c in "xyz"], dtype=float)
    return Torsor(r, m, np.zeros(3))


def torsor_table(
    spec: TorsorSpec,
    torsor: Torsor,
    *,
    point: str,
    basis: np.ndarray,
    axes: Sequence[str],
    zero: Mapping[str, float] | None = None,
    least: tuple[float, float] = (0.0, 0.0),
) -> str:
    """Markdown table of one torsor: rows R and M_point, columns the basis' axes.

    A component is 0 below :data:`RELATIVE_ZERO` of the largest component, below the
    scene's round-off ``zero`` of its unit (contract unit -> value), or below the last
    digit written of its vector's largest component (:func:`written_floor`), or below
    ``least`` (resultant, moment: the precision of the equation the torsor is a term of)."""
    r, m = torsor.in_basis(basis)
    floor = RELATIVE_ZERO * max(float(np.abs(r).max()), float(np.abs(m).max()), 1e-300)
    zero = zero or {}
    r_floor = max(floor, zero.get(spec.r_unit, 0.0), written_floor(r), least[0])
    m_floor = max(floor, zero.get(spec.m_unit, 0.0), written_floor(m), least[1])
    head = table_row(spec.symbol, *axes) + "\n|:--|" + "--:|" * len(axes) + "\n"
    row_r = (
        table_row(
            f"R [{spec.r_unit}]",
            *(
                _span(f"shown_{spec.prefix}_R{i}", fmt(v, floor=r_floor), float(v))
                for i, v in enumerate(r)
            ),
        )
        + "\n"
    )
    row_m = (
        table_row(
            f"M<sub>{point}</sub> [{spec.m_unit}]",
            *(
                _span(f"shown_{spec.prefix}_M{i}", fmt(v, floor=m_floor), float(v))
                for i, v in enumerate(m)
            ),
        )
        + "\n"
    )
    return f"*{spec.caption}*\n\n" + head + row_r + row_m


PFD_TERMS = ("dyn", "sup")
"""The torsors of the fundamental principle's two sides ({𝒟} and the frame's action)."""


def torsors_markdown(
    values: Mapping[str, float],
    *,
    point: np.ndarray,
    point_name: str,
    basis: np.ndarray,
    basis_name: str,
    axes: Sequence[str],
    zero: Mapping[str, float] | None = None,
) -> str:
    """The three generic torsors reduced at ``point`` with components in ``basis``.

    Args:
        values: Readouts including ``kin_*``, ``dyn_*`` and ``sup_*``.
        point: Reduction point, world coordinates [m], shape (3,).
        point_name: Its name in the table (``O``, ``A``, ``P``).
        basis: 3x3, columns = basis vectors in world coordinates.
        basis_name: Its name (``B0``, ``B1``).
        axes: Axis names of the basis.
        zero: The scene's round-off by contract unit (:attr:`Scene.zero`).
    """
    p = " ; ".join(fmt(float(x), digits=3, floor=1e-12) for x in point)
    point_name, basis_name = html_text(point_name, 40), html_text(basis_name, 40)
    out = [f"Réduits en **{point_name}** = ({p}) m, composantes dans **{basis_name}**.\n"]
    torsors = {spec.prefix: torsor_at_o(values, spec.prefix).at(point) for spec in TORSORS}
    # {𝒟} and {𝒯} are terms of one equation (PFD), written to one precision: {𝒟} of a
    # machine at constant speed reads 0 beside the frame's hundreds of newtons, not the
    # integration's 10⁻⁵ N (robot axis)
    parts = [torsors[k].in_basis(basis) for k in PFD_TERMS]
    shared = (
        written_floor(np.concatenate([r for r, _ in parts])),
        written_floor(np.concatenate([m for _, m in parts])),
    )
    for spec in TORSORS:
        least = shared if spec.prefix in PFD_TERMS else (0.0, 0.0)
        out.append(
            torsor_table(
                spec,
                torsors[spec.prefix],
                point=point_name,
                basis=basis,
                axes=axes,
                zero=zero,
                least=least,
            )
        )
    out.append(
        "PFD : {𝒟<sub>Σ/R₀</sub>} = {𝒯<sub>0/Σ</sub>} + actions extérieures "
        "(poids, moteur, charges)."
    )
    return "\n".join(out)


ENERGY_ROWS = (
    ("T", "T<sub>Σ/R₀</sub>", "J", "énergie cinétique"),
    ("V", "V", "J", "énergie potentielle"),
    ("P_ext", "P<sub>ext</sub>", "W", "poids, moteurs, charges"),
    (
        "P_int",
        "P<sub>int</sub>",
        "W",
        "inter-efforts : nulle si liaisons parfaites, négative avec frottement",
    ),
    ("P_acc", "dT/dt", "W", "puissance des quantités d'accélération"),
)


def energy_markdown(
    values: Mapping[str, float],
    *,
    zero: Mapping[str, float] | None = None,
    friction: bool = False,
) -> str:
    """Table of T, V and the powers, and the kinetic-energy theorem's balance
    (``friction``: the bearings' friction with the frame is applied and counted in P_int).

    Powers below :data:`RELATIVE_ZERO` of the largest power (or of T per second), or
    below the scene's round-off ``zero`` of their unit, are round-off: shown 0. The
    powers of the balance are written to the precision of the largest one
    (:func:`written_floor`): one below its last digit reads 0."""
    names = [n for n, *_ in ENERGY_ROWS[2:]] + ["T"]
    scale = max(abs(values.get(n, 0.0)) for n in names) if values else 0.0
    floor = RELATIVE_ZERO * max(scale, 1e-300)
    zero = zero or {}
    frame = frame_power(values)
    powers = [values.get(n, math.nan) for n, *_ in ENERGY_ROWS[2:]] + [frame]
    balance = max(floor, written_floor(p for p in powers if math.isfinite(p)))
    lines = ["| Grandeur | Valeur | |\n|:--|--:|:--|"]
    for name, symbol, unit, doc in ENERGY_ROWS:
        v = values.get(name, math.nan)
        least = balance if unit == "W" else floor
        shown = fmt(v, floor=max(least, zero.get(unit, 0.0)))
        lines.append(table_row(f"{symbol} [{unit}]", _span(name, shown, v), doc))
    lines.append(
        table_row(
            "dT/dt − P<sub>ext</sub> − P<sub>int</sub> [W]",
            _span("P_frame", fmt(frame, floor=max(balance, zero.get("W", 0.0))), frame),
            "puissance des liaisons avec le bâti hors frottement des paliers (0 si parfaites)"
            if friction
            else "puissance des liaisons avec le bâti (0 si parfaites)",
        )
    )
    theorem = "Théorème de l'énergie cinétique : dT/dt = P<sub>ext</sub> + P<sub>int</sub>"
    if friction:
        return (
            "\n".join(lines) + f"\n\n{theorem}, le frottement des paliers sur le bâti compté "
            "dans P<sub>int</sub> (les autres liaisons parfaites)."
        )
    return "\n".join(lines) + f"\n\n{theorem} (liaisons parfaites)."


def gap(sim: float, ref: float) -> str:
    """Relative gap (sim − ref)/|ref| in % with a decimal comma ("+1,25 %"), or — when the
    reference is (nearly) zero."""
    if not (math.isfinite(sim) and math.isfinite(ref)) or abs(ref) < 1e-12:
        return "—"
    pct = round(100.0 * (sim - ref) / abs(ref), 2) + 0.0  # no "-0.00"
    return f"{pct:+.2f}\u202f%".replace(".", ",").replace("-", "−")


def _row(row: Row | Sequence[str]) -> Row:
    if isinstance(row, Row):
        return row
    name, unit, doc = row
    return Row(name, unit, doc)


def scene_markdown(
    rows: Sequence[Row | tuple[str, str, str]],
    values: Mapping[str, float],
    reference: Mapping[str, float],
) -> str:
    """Scene readouts with the course's closed-form values side by side.

    Args:
        rows: Each scene readout, in display order: a :class:`Row`, or (name, unit, doc).
        values: Simulated values.
        reference: Closed-form values by name (missing names show —).
    """
    lines = [table_row("Grandeur", "Simulation", "Cours", "Écart"), "|:--|--:|--:|--:|"]
    for item in rows:
        row = _row(item)
        v = values.get(row.name, math.nan)
        ref = reference.get(row.name)
        label = _label_cell(row)
        # written as every view writes it (a flag « oui », θ modulo 360°, the round-off 0)
        course = written(row.name, ref, row.unit, zero=row.zero).number if ref is not None else "—"
        shown = written(row.name, v, row.unit, zero=row.zero).number
        lines.append(
            table_row(
                label,
                _span(row.name, shown, v),
                course,
                gap(v, ref) if ref is not None else "—",
            )
        )
    note = "*Cours* : forme close du cours ; *Écart* : (simulation − cours) / |cours|."
    return "\n".join(lines) + "\n\n" + note.replace("|", "&#124;")


@functools.lru_cache(maxsize=4096)
def _label_cell(row: Row) -> str:
    """The words of a scene row with their tooltip and unit, escaped once per row."""
    words = row.label or row.name
    label = f'<span title="{cell(row.hint or row.doc)}">{cell(words)}</span>'
    shown = shown_scale(row.name, row.unit)[0]
    return label + (f" [{cell(shown)}]" if shown else "")


def hypotheses_markdown(
    lines: Sequence[str], *, integrator: str, timestep: float, imposed: bool = False
) -> str:
    """Bulleted modelling hypotheses followed by the numerical method (an imposed motion
    has none: it is exact at any instant)."""
    items = [f"- {html_text(line)}" for line in lines]
    if imposed:
        items.append("- Calcul exact à chaque instant : ni intégrateur ni pas de temps")
    else:
        method = html_text(integrator_words(integrator))
        # written as « Précision et coût » writes it (« 200 µs », not « 0,2 ms »)
        items.append(f"- Intégrateur **{method}**, pas de temps dt = {duration(timestep)}")
    return "\n".join(items)
