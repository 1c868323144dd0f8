"""Markdown of the readout panels, in the course's notation (pure functions, no server).

Values come from :meth:`Simulation.readouts`; torsors are moved to the chosen point
and basis with :class:`sandbox.mechanics.Torsor` (the web layer computes no physics).
Each simulated value sits in ``<span data-readout="NAME">`` so that tests and
scripts can find it in the page. Names, units, docs and labels are escaped
(:func:`~sandbox.web.text.html_text`): a user's file may name a body ``<img onerror=…>``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sandbox.mechanics import Torsor
from sandbox.physics.energy import frame_power
from sandbox.web.text import html_text


def fmt(value: float, *, digits: int = 4, floor: float = 0.0) -> str:
    """A number for humans: ``digits`` significant digits, 0 under ``floor``, — if not finite."""
    if not math.isfinite(value):
        return "—"
    if abs(value) <= floor:
        return "0"
    text = f"{value:.{digits}g}"
    if "e" in text:
        mantissa, exp = text.split("e")
        text = f"{mantissa}·10<sup>{int(exp)}</sup>"
    return text


def _span(name: str, text: str) -> str:
    return f'<span data-readout="{html_text(name)}">{text}</span>'


@dataclass(frozen=True)
class TorsorSpec:
    """How to show one generic torsor.

    Attributes:
        prefix: Readout prefix (``kin``, ``dyn``, ``sup``).
        symbol: Course symbol as HTML, e.g. ``{𝒟<sub>Σ/R0</sub>}``.
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
    TorsorSpec("kin", "{𝒞<sub>Σ/R0</sub>}", "torseur cinétique", "kg·m/s", "kg·m²/s"),
    TorsorSpec("dyn", "{𝒟<sub>Σ/R0</sub>}", "torseur dynamique", "N", "N·m"),
    TorsorSpec("sup", "{𝒯<sub>0/Σ</sub>}", "action du bâti 0 sur Σ", "N", "N·m"),
)


def torsor_at_o(values: Mapping[str, float], prefix: str) -> Torsor:
    """The generic torsor ``prefix`` (readouts at O, world axes) as a :class:`Torsor`."""
    r = np.array([values[f"{prefix}_R_{c}"] for c in "xyz"], dtype=float)
    m = np.array([values[f"{prefix}_M_{c}"] for c in "xyz"], dtype=float)
    return Torsor(r, m, np.zeros(3))


def torsor_table(
    spec: TorsorSpec, torsor: Torsor, *, point: str, basis: np.ndarray, axes: Sequence[str]
) -> str:
    """Markdown table of one torsor: rows R and M_point, columns the basis' axes."""
    r, m = torsor.in_basis(basis)
    floor = 1e-9 * max(float(np.abs(r).max()), float(np.abs(m).max()), 1e-300)
    head = f"| {spec.symbol} | " + " | ".join(axes) + " |\n|:--|" + "--:|" * len(axes) + "\n"
    row_r = (
        f"| R [{spec.r_unit}] | "
        + " | ".join(
            _span(f"shown_{spec.prefix}_R{i}", fmt(v, floor=floor)) for i, v in enumerate(r)
        )
        + " |\n"
    )
    row_m = (
        f"| M<sub>{point}</sub> [{spec.m_unit}] | "
        + " | ".join(
            _span(f"shown_{spec.prefix}_M{i}", fmt(v, floor=floor)) for i, v in enumerate(m)
        )
        + " |\n"
    )
    return f"*{spec.caption}*\n\n" + head + row_r + row_m


def torsors_markdown(
    values: Mapping[str, float],
    *,
    point: np.ndarray,
    point_name: str,
    basis: np.ndarray,
    basis_name: str,
    axes: Sequence[str],
) -> str:
    """The three generic torsors reduced at ``point`` with components in ``basis``.

    Args:
        values: Readouts including ``kin_*``, ``dyn_*`` and ``sup_*``.
        point: Reduction point, world coordinates [m], shape (3,).
        point_name: Its name in the table (``O``, ``A``, ``P``).
        basis: 3x3, columns = basis vectors in world coordinates.
        basis_name: Its name (``B0``, ``B1``).
        axes: Axis names of the basis.
    """
    p = ", ".join(fmt(float(x), digits=3, floor=1e-12) for x in point)
    point_name, basis_name = html_text(point_name, 40), html_text(basis_name, 40)
    out = [f"Réduits en **{point_name}** = ({p}) m, composantes dans **{basis_name}**.\n"]
    for spec in TORSORS:
        t = torsor_at_o(values, spec.prefix).at(point)
        out.append(torsor_table(spec, t, point=point_name, basis=basis, axes=axes))
    out.append(
        "PFD : {𝒟<sub>Σ/R0</sub>} = {𝒯<sub>0/Σ</sub>} + actions extérieures "
        "(poids, moteur, charges)."
    )
    return "\n".join(out)


ENERGY_ROWS = (
    ("T", "T<sub>Σ/R0</sub>", "J", "énergie cinétique"),
    ("V", "V", "J", "énergie potentielle"),
    ("P_ext", "P<sub>ext</sub>", "W", "poids, moteurs, charges"),
    ("P_int", "P<sub>int</sub>", "W", "inter-efforts (≤ 0)"),
    ("P_acc", "dT/dt", "W", "puissance des quantités d'accélération"),
)


def energy_markdown(values: Mapping[str, float]) -> str:
    """Table of T, V and the powers, and the kinetic-energy theorem's balance."""
    # Powers below 1e-9 of the largest power, or of T per second, are round-off: shown 0.
    names = [n for n, *_ in ENERGY_ROWS[2:]] + ["T"]
    scale = max(abs(values.get(n, 0.0)) for n in names) if values else 0.0
    floor = 1e-9 * max(scale, 1e-300)
    lines = ["| Grandeur | Valeur | |\n|:--|--:|:--|"]
    for name, symbol, unit, doc in ENERGY_ROWS:
        v = values.get(name, math.nan)
        lines.append(f"| {symbol} [{unit}] | {_span(name, fmt(v, floor=floor))} | {doc} |")
    frame = frame_power(values)
    lines.append(
        f"| dT/dt − P<sub>ext</sub> − P<sub>int</sub> [W] | "
        f"{_span('P_frame', fmt(frame, floor=floor))} | puissance des liaisons "
        "avec le bâti (0 si parfaites) |"
    )
    return (
        "\n".join(lines) + "\n\nThéorème de l'énergie cinétique : dT/dt = P<sub>ext</sub> "
        "+ P<sub>int</sub> (liaisons parfaites)."
    )


def gap(sim: float, ref: float) -> str:
    """Relative gap (sim − ref)/|ref| in %, or — when the reference is (nearly) zero."""
    if not (math.isfinite(sim) and math.isfinite(ref)) or abs(ref) < 1e-12:
        return "—"
    pct = round(100.0 * (sim - ref) / abs(ref), 2) + 0.0  # no "-0.00"
    return f"{pct:+.2f} %"


def scene_markdown(
    rows: Sequence[tuple[str, str, str]],
    values: Mapping[str, float],
    reference: Mapping[str, float],
) -> str:
    """Scene readouts with the course's closed-form values side by side.

    Args:
        rows: (name, unit, doc) of each scene readout, in display order.
        values: Simulated values.
        reference: Closed-form values by name (missing names show —).
    """
    lines = ["| Grandeur | Simulation | Cours | Écart |", "|:--|--:|--:|--:|"]
    for name, unit, doc in rows:
        v = values.get(name, math.nan)
        ref = reference.get(name)
        unit_text = f" [{html_text(unit)}]" if unit else ""
        label = f'<span title="{html_text(doc)}">{html_text(name)}</span>{unit_text}'
        lines.append(
            f"| {label} | {_span(name, fmt(v))} | {fmt(ref) if ref is not None else '—'} | "
            f"{gap(v, ref) if ref is not None else '—'} |"
        )
    note = "*Cours* : forme close du cours ; *Écart* : (simulation − cours) / |cours|."
    return "\n".join(lines) + "\n\n" + note


def hypotheses_markdown(lines: Sequence[str], *, integrator: str, timestep: float) -> str:
    """Bulleted modelling hypotheses followed by the numerical method."""
    items = [f"- {html_text(line)}" for line in lines]
    items.append(
        f"- Intégrateur **{html_text(integrator)}**, pas de temps dt = {fmt(timestep * 1e3)} ms"
    )
    return "\n".join(items)
