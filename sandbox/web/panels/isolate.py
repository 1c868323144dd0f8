"""Folder "Isoler un solide": the dynamic torsor of one solid and every action on it, as
when the course isolates the piston, the crank or the rod and writes the PFD."""

from __future__ import annotations

from collections.abc import Callable, Mapping

import mujoco
import numpy as np
import viser

from sandbox.physics import isolate
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.snapshot import Snapshot
from sandbox.web.client.text import MAX_SHOWN, plain, table_row
from sandbox.web.panels.controls import set_value
from sandbox.web.panels.folder import Folder
from sandbox.web.panels.tables import fmt

FOLDER = "Isoler un solide"
"""The folder's title (in « Panneau affiché »)."""


class IsolatePanel:
    """Pick a solid; see {D} at its centre of mass and the actions on it (B0 components).

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation.
    """

    def __init__(self, gui: viser.GuiApi, sim: ReadOnlySimulation) -> None:
        self.sim = sim
        scene = sim.scene
        self.names = names = dict(scene.page.names.solids) if scene else {}
        self.zero: Mapping[str, float] = dict(scene.zero) if scene is not None else {}
        self.choices: dict[str, str] = {}
        for body in isolate.solids(sim.model):
            raw = mujoco.mj_id2name(sim.model, mujoco.mjtObj.mjOBJ_BODY, body) or f"corps {body}"
            # Options are shown as text by the browser (never as HTML); a body name from
            # a file is only made one line and cut to a readable length.
            shown = _one_line(str(names.get(raw, raw)))
            while shown in self.choices:  # two bodies whose names agree once cut
                shown += "′"
            self.choices[shown] = raw
        self.text: viser.GuiMarkdownHandle | None = None
        self.folder: viser.GuiFolderHandle | None = None
        self.refused: str | None = None  # the last value refused (shown in the panel)
        if not self.choices:
            return
        with gui.add_folder(FOLDER) as self.folder:
            self.picker = gui.add_dropdown("Solide", tuple(self.choices))
            self.point = gui.add_dropdown(
                "Point de réduction",
                (POINT_G, POINT_O),
                hint="Point où les moments sont réduits : le centre de gravité G du solide "
                "isolé, ou l'origine O du repère R₀",
            )
            self.basis = gui.add_dropdown(
                "Base des composantes",
                (BASIS_0, BASIS_1),
                hint="Base des composantes : B₀, fixe, ou B₁, liée au solide isolé "
                "(elle tourne avec lui)",
            )
            self.text = gui.add_markdown("")
        self._good = self.picker.value

    def _label(self, text: str) -> str:
        for raw, shown in self.names.items():
            text = text.replace(raw, str(shown))
        return text

    def chosen(self) -> str:
        """The MJCF name of the solid picked; a value that is not an option (only a crafted
        message sends one) is refused once: the picker goes back to the last good choice."""
        value = self.picker.value
        if isinstance(value, str) and value in self.choices:
            self._good = value
            return self.choices[value]
        self.refused = value if isinstance(value, str) else repr(value)
        set_value(self.picker, self._good)
        return self.choices[self._good]

    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché »: it reads the state itself (the instant the
        tables show), so a challenge closes it."""
        if self.folder is None:
            return []
        return [Folder(FOLDER, self.folder, lambda frame: self.refresh(self.sim, frame.state))]

    def refresh(self, sim: ReadOnlySimulation, state: Snapshot | None = None) -> None:
        """Recompute at ``state``, the instant the tables show (its forces prepared; None:
        the physics state); the caller holds the panel rate."""
        if self.text is None:
            return
        model = sim.model
        name = self.chosen()
        with sim.lock:
            body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
            if body < 0:
                return
            if state is None or state.model is not model:
                state = sim.snapshot((), forces=True)
            at_o = self.point.value == POINT_O
            pfd = isolate.balance(model, state.data, body, np.zeros(3) if at_o else None)
        text = isolate_markdown(
            pfd,
            label=self._label,
            zero=self.zero,
            point="O" if at_o else "G",
            basis="B1" if self.basis.value == BASIS_1 else "B0",
        )
        if self.refused is not None:
            text = f"*Solide « {plain(self.refused, 40)} » inconnu : choix refusé.*\n\n" + text
            self.refused = None
        if self.text.content != text:
            self.text.content = text


def _one_line(text: str) -> str:
    """``text`` on one line, at most :data:`~sandbox.web.client.text.MAX_SHOWN` characters."""
    text = "".join(c if c.isprintable() else " " for c in text)
    return text if len(text) <= MAX_SHOWN else text[: MAX_SHOWN - 1] + "…"


POINT_G = "G, centre de gravité du solide"
POINT_O = "O, origine du repère R₀"
BASIS_0 = "B₀, fixe"
BASIS_1 = "B₁, liée au solide"

_SUB = {"B0": "₀", "B1": "₁"}


RESOLVED = 1e-5
"""A component under this fraction of the largest one in its table reads 0: the table
shows four digits, and what lies five decades under its largest action is the
integration's error, not a force a student could measure: the heavy top at its default
0.5 ms leaves a nutation of 10⁻⁸ rad that gives its {𝒟} R_z up to 1,8x10⁻⁵ N beside its
9,81 N weight, where the course has 0."""


def isolate_markdown(
    pfd: isolate.Balance,
    *,
    label: Callable[[str], str] = str,
    zero: Mapping[str, float] | None = None,
    point: str = "G",
    basis: str = "B0",
) -> str:
    """The actions on the isolated solid and its dynamic torsor in three dimensions: a
    table of resultants and one of moments at ``point``, each with its three components
    in ``basis`` ("B0", fixed, or "B1", the solid's own), numbers the French way; then
    the PFD's gap, absolute, and relative to the largest torsor (0 when it is round-off).

    Args:
        pfd: The balance of the solid (:func:`sandbox.physics.isolate.balance`).
        label: Turns an action's label into the words shown (e.g. body names).
        zero: The scene's round-off by unit: smaller components are shown 0, as are those
            under :data:`RESOLVED` of their table's largest.
        point: The name of the point the moments are reduced at (``pfd.point``).
        basis: "B0" or "B1".
    """
    zero = zero or {}
    n_floor, m_floor = zero.get("N", 0.0), zero.get("N·m", 0.0)
    sub = _SUB.get(basis, "₀")
    axes = pfd.axes if basis == "B1" else np.eye(3)
    d = pfd.dynamic

    def name(a: isolate.Action) -> str:
        return "**{𝒟}** (somme des actions)" if a is d else plain(label(a.label))

    def table(
        title: str, unit: str, pick: Callable[[isolate.Action], np.ndarray], floor: float
    ) -> str:
        head = [f"{title}<sub>{c}{sub}</sub>" for c in "xyz"]
        rows = [table_row(f"Action sur le solide [{unit}]", *head), "|:--|--:|--:|--:|"]
        every = [(a, axes.T @ pick(a)) for a in [*pfd.actions, d]]
        largest = max(float(np.abs(v).max()) for _, v in every)
        floor = max(floor, RESOLVED * largest)
        for a, local in every:
            rows.append(table_row(name(a), *(fmt(float(x), floor=floor) for x in local)))
        return "\n".join(rows)

    # a coordinate a millionth of the largest is the closure's round-off (the compressor's
    # crank read G = (−0,003 ; −1,96×10⁻¹⁰ ; 0) m): it reads 0
    spot = max(1e-12, RESOLVED * float(np.abs(pfd.centre).max()))
    centre = " ; ".join(fmt(float(x), digits=3, floor=spot) for x in pfd.centre)
    gap_r, gap_m = pfd.gap
    closed = gap_r <= n_floor and gap_m <= m_floor
    relative = "0" if closed else fmt(pfd.residual, digits=2)
    where = "G" if point == "G" else "O"
    words = "B₁, liée au solide" if basis == "B1" else "B₀, fixe"
    return (
        f"G = ({centre}) m ; composantes dans {words}.\n\n"
        + table("R", "N", lambda a: a.resultant, n_floor)
        + "\n\n"
        + table(f"M<sub>{where},</sub>", "N·m", lambda a: a.moment, m_floor).replace(
            "</sub><sub>", ""
        )
        + f"\n\nÉcart du PFD (Σ actions − {{𝒟}}) : ‖ΔR‖ = {fmt(gap_r, digits=2, floor=n_floor)}"
        f" N, ‖ΔM<sub>{where}</sub>‖ = {fmt(gap_m, digits=2, floor=m_floor)} N·m, soit "
        f"{relative} de la plus grande action."
    )
