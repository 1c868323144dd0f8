"""Folder "Isoler un solide": the dynamic torsor of one solid and every action on it, as
when the course isolates the piston, the crank or the rod and writes the PFD."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from sandbox.physics import isolate
from sandbox.physics.simulation import Simulation
from sandbox.web.tables import fmt


class IsolatePanel:
    """Pick a solid; see {D} at its centre of mass and the actions on it (B0 components).

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation.
    """

    def __init__(self, gui: Any, sim: Simulation) -> None:
        names = dict(sim.scene.extra.get("solid_names", {})) if sim.scene else {}
        self.names = names
        self.choices: dict[str, str] = {}
        for body in isolate.solids(sim.model):
            raw = mujoco.mj_id2name(sim.model, mujoco.mjtObj.mjOBJ_BODY, body) or f"corps {body}"
            self.choices[str(names.get(raw, raw))] = raw
        self.text = None
        self.folder: Any = None
        if not self.choices:
            return
        with gui.add_folder("Isoler un solide") as self.folder:
            self.picker = gui.add_dropdown("Solide", tuple(self.choices))
            self.text = gui.add_markdown("")

    def _label(self, text: str) -> str:
        for raw, shown in self.names.items():
            text = text.replace(raw, str(shown))
        return text

    def refresh(self, sim: Simulation) -> None:
        """Recompute at the current state (the caller holds the panel rate)."""
        if self.text is None:
            return
        model = sim.model
        with sim.lock:
            body = mujoco.mj_name2id(
                model, mujoco.mjtObj.mjOBJ_BODY, self.choices[self.picker.value]
            )
            if body < 0:
                return
            sim.snapshot(("sup_R_x", "dyn_R_x"))
            pfd = isolate.balance(model, sim.data, body)
        rows = ["| | R<sub>x</sub> | R<sub>y</sub> | M<sub>G,z</sub> [N·m] | ‖M<sub>G</sub>‖ |",
                "|:--|--:|--:|--:|--:|"]  # fmt: skip
        d = pfd.dynamic
        for a in [*pfd.actions, d]:
            label = "**{𝒟} (PFD : somme des actions)**" if a is d else self._label(a.label)
            rows.append(
                f"| {label} | {fmt(a.resultant[0])} | {fmt(a.resultant[1])} | "
                f"{fmt(a.moment[2])} | {fmt(float(np.linalg.norm(a.moment)))} |"
            )
        text = (
            f"Moments en G = ({', '.join(fmt(float(x), digits=3) for x in pfd.centre)}) m, "
            f"composantes dans B0, forces en N.\n\n"
            + "\n".join(rows)
            + f"\n\nÉcart PFD (Σ actions − {{𝒟}}) : {fmt(pfd.residual, digits=2)} relatif."
        )
        if self.text.content != text:
            self.text.content = text
