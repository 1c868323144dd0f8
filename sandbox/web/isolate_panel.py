"""Folder "Isoler un solide": the dynamic torsor of one solid and every action on it, as
when the course isolates the piston, the crank or the rod and writes the PFD."""

from __future__ import annotations

from collections.abc import Callable, Mapping

import mujoco
import numpy as np
import viser

from sandbox.physics import isolate
from sandbox.physics.simulation import Simulation
from sandbox.scenes.base import as_scene
from sandbox.web.panels import set_value
from sandbox.web.tables import fmt
from sandbox.web.text import MAX_SHOWN, plain


class IsolatePanel:
    """Pick a solid; see {D} at its centre of mass and the actions on it (B0 components).

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation.
    """

    def __init__(self, gui: viser.GuiApi, sim: Simulation) -> None:
        scene = as_scene(sim.scene)
        given = scene.extra.get("solid_names") if scene else None
        names = {str(k): str(v) for k, v in given.items()} if isinstance(given, Mapping) else {}
        self.names = names
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
        with gui.add_folder("Isoler un solide") as self.folder:
            self.picker = gui.add_dropdown("Solide", tuple(self.choices))
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

    def refresh(self, sim: Simulation) -> None:
        """Recompute at the current state (the caller holds the panel rate)."""
        if self.text is None:
            return
        model = sim.model
        name = self.chosen()
        with sim.lock:
            body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
            if body < 0:
                return
            sim.snapshot(("sup_R_x", "dyn_R_x"))
            pfd = isolate.balance(model, sim.data, body)
        text = isolate_markdown(pfd, label=self._label, zero=self.zero)
        if self.refused is not None:
            text = f"*Solide « {plain(self.refused, 40)} » inconnu : choix refusé.*\n\n" + text
            self.refused = None
        if self.text.content != text:
            self.text.content = text


def _one_line(text: str) -> str:
    """``text`` on one line, at most :data:`~sandbox.web.text.MAX_SHOWN` characters."""
    text = "".join(c if c.isprintable() else " " for c in text)
    return text if len(text) <= MAX_SHOWN else text[: MAX_SHOWN - 1] + "…"


GAP = "\u2002"
"""En space before each number: right-aligned columns of a narrow panel otherwise touch
("73,23-72,95")."""


def isolate_markdown(
    pfd: isolate.Balance,
    *,
    label: Callable[[str], str] = str,
    zero: Mapping[str, float] | None = None,
) -> str:
    """The actions on the isolated solid and its dynamic torsor, one column per
    component (R_x, R_y [N], M_G,z [N·m], ‖M_G‖ [N·m]), numbers the French way.

    Args:
        pfd: The balance of the solid (:func:`sandbox.physics.isolate.balance`).
        label: Turns an action's label into the words shown (e.g. body names).
        zero: The scene's round-off by unit: smaller components are shown 0.
    """
    zero = zero or {}
    n_floor, m_floor = zero.get("N", 0.0), zero.get("N·m", 0.0)
    rows = [
        "| Action sur le solide | R<sub>x</sub> [N] | R<sub>y</sub> [N] "
        "| M<sub>G,z</sub> [N·m] | ‖M<sub>G</sub>‖ [N·m] |",
        "|:--|--:|--:|--:|--:|",
    ]
    d = pfd.dynamic
    for a in [*pfd.actions, d]:
        name = "**{𝒟}** (somme des actions)" if a is d else plain(label(a.label))
        numbers = (
            fmt(a.resultant[0], floor=n_floor),
            fmt(a.resultant[1], floor=n_floor),
            fmt(a.moment[2], floor=m_floor),
            fmt(float(np.linalg.norm(a.moment)), floor=m_floor),
        )
        rows.append(f"| {name} | " + " | ".join(GAP + x for x in numbers) + " |")
    centre = " ; ".join(fmt(float(x), digits=3, floor=1e-12) for x in pfd.centre)
    return (
        f"Moments en G = ({centre}) m, composantes dans B0.\n\n"
        + "\n".join(rows)
        + f"\n\nÉcart du PFD (Σ actions − {{𝒟}}), relatif : {fmt(pfd.residual, digits=2)}."
    )
