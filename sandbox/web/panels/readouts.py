"""Readout folders: scene readouts vs the course, live plots, torsors, energy and powers."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import mujoco
import numpy as np
import viser

from sandbox.physics.bearings import friction_on
from sandbox.physics.picture import Picture
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.readouts import GENERIC_NAMES
from sandbox.physics.snapshot import Snapshot
from sandbox.web.panels import tables
from sandbox.web.panels.controls import set_value
from sandbox.web.panels.folder import Folder
from sandbox.web.panels.plots import ComponentPlot, Plot, component_plot, group_by_unit
from sandbox.web.view3d.arrows import ArrowLayer

if TYPE_CHECKING:
    from sandbox.web.loop.frame import Frame

POINT_O = "O (origine)"
POINT_P = "P (saisi)"
BASIS_0 = "B₀, fixe"
"""The world basis, written as « Isoler un solide » writes it (one name for B₀)."""

SCENE_FOLDER = "Grandeurs de la scène"
PLOTS_FOLDER = "Courbes"
TORSORS_FOLDER = "Torseurs"
ENERGY_FOLDER = "Énergie et puissances"

ENERGY_NAMES = ("T", "V", "P_ext", "P_int", "P_acc")
"""Readouts of the energy table."""

TORSOR_NAMES = tuple(n for n in GENERIC_NAMES if n[:4] in ("kin_", "dyn_", "sup_"))
"""Readouts of the torsor table."""


def short_name(label: str) -> str:
    """Point name for a subscript: the last word of an arrow label ("Palier A" -> "A")."""
    words = label.split()
    return words[-1] if words else "P"


class ReadoutPanel:
    """Folders "Grandeurs de la scène", "Courbes", "Torseurs" and "Énergie et puissances".

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation (only read).
        arrows: The arrow layer, whose origins are offered as reduction points.
    """

    def __init__(
        self, gui: viser.GuiApi, sim: ReadOnlySimulation, *, arrows: ArrowLayer | None = None
    ) -> None:
        self.arrows = arrows
        scene = sim.scene
        infos = {i.name: i for i in sim.readout_infos()}
        self.zero: dict[str, float] = dict(scene.zero) if scene is not None else {}
        self._rows = {
            imposed: [
                tables.Row(
                    r.name,
                    r.unit,
                    r.doc,
                    (r.imposed_label if imposed else "") or r.label,
                    (r.imposed_hint if imposed else "") or r.hint,
                    self.zero.get(r.unit, 0.0),
                )
                for r in (scene.readouts if scene else ())
            ]
            for imposed in (False, True)
        }
        self.withheld: frozenset[str] = frozenset()  # a challenge's secret readouts
        self._ref_key: tuple[tuple[str, float], ...] | None = None
        self._ref: dict[str, float] = {}
        self.scene_text: viser.GuiMarkdownHandle | None = None
        self.folders: dict[str, viser.GuiFolderHandle] = {}
        if self._rows[False]:
            with gui.add_folder(SCENE_FOLDER) as self.folders[SCENE_FOLDER]:
                self.scene_text = gui.add_markdown("")
        names = list(scene.page.plots) if scene and scene.page.plots else ["T", "V"]
        names = [n for n in names if n in infos]
        arrow_of = {a.name: a for a in (arrows.arrows if arrows else ())}
        colors = {n: a.color for n, a in arrow_of.items()}
        words = {n: infos[n].label or (arrow_of[n].label if n in arrow_of else n) for n in names}
        self.plots: list[Plot] = group_by_unit(
            names, {n: infos[n].unit for n in names}, colors, labels=words, zero=self.zero
        )
        self.sim = sim
        self.body = -1
        if scene is not None and scene.page.body_frame:
            self.body = mujoco.mj_name2id(
                sim.model, mujoco.mjtObj.mjOBJ_BODY, scene.page.body_frame
            )
        self.scene_arrows = tuple(scene.page.arrows) if scene is not None else ()
        self.components: ComponentPlot | None = component_plot(scene)
        if self.components is not None and self.components.spec.basis == "B1" and self.body <= 0:
            self.components = None
        if self.plots or self.components is not None:
            with gui.add_folder(PLOTS_FOLDER) as self.folders[PLOTS_FOLDER]:
                if self.components is not None:
                    self.components.attach(gui, title=self.components.title())
                for plot in self.plots:
                    unit = f" [{plot.shown_unit}]" if plot.shown_unit else ""
                    title = f"{' et '.join(plot.labels)}{unit} en fonction du temps"
                    plot.attach(gui, title=title)
        with gui.add_folder(TORSORS_FOLDER) as self.folders[TORSORS_FOLDER]:
            labels = [a.label for a in (arrows.arrows if arrows else ())]
            self.point = gui.add_dropdown(
                "Point",
                (POINT_O, *labels, POINT_P),
                initial_value=POINT_O,
                hint="Point de réduction des torseurs",
            )
            self.point_xyz = gui.add_vector3(
                "P [m]",
                (0.0, 0.0, 0.0),
                step=0.001,
                hint="Coordonnées du point P dans R₀ (choisir « P (saisi) » dans « Point »)",
            )
            bases = [BASIS_0]
            if self.body > 0 and scene is not None:
                solid = scene.page.names.solids.get(scene.page.body_frame or "")
                bases.append(f"B₁, liée au solide {solid}" if solid else "B₁, liée au solide")
            self.basis = gui.add_dropdown(
                "Base",
                tuple(bases),
                initial_value=BASIS_0,
                hint="Base de projection des composantes",
            )
            self.torsor_text = gui.add_markdown("")
        with gui.add_folder(ENERGY_FOLDER) as self.folders[ENERGY_FOLDER]:
            self.energy_text = gui.add_markdown("")

    @property
    def scene_rows(self) -> list[tables.Row]:
        """The scene's rows, in the words of the way its motion is computed now (an
        imposed motion's torque row reads « Couple nécessaire »)."""
        return self._rows[self.sim.motion == "imposed"]

    # -- choices of the user -------------------------------------------------------------
    def chosen_point(self) -> tuple[np.ndarray, str]:
        """Reduction point in world coordinates [m] and its short name."""
        choice = self.point.value
        if choice == POINT_P:
            try:
                xyz = np.asarray(self.point_xyz.value, dtype=float)
            except (TypeError, ValueError):
                xyz = np.zeros(0)
            if xyz.shape == (3,) and np.isfinite(xyz).all() and np.abs(xyz).max() < 1e6:
                return xyz, "P"
            set_value(self.point_xyz, (0.0, 0.0, 0.0))  # a crafted point: back to O
            return np.zeros(3), "P"
        if self.arrows is not None:
            for arrow, origin in zip(self.arrows.arrows, self.arrows.origins, strict=True):
                if arrow.label == choice:
                    return np.asarray(origin, dtype=float), short_name(arrow.label)
        return np.zeros(3), "O"

    def chosen_basis(
        self, sim: ReadOnlySimulation, data: mujoco.MjData | None = None
    ) -> tuple[np.ndarray, str, tuple[str, ...]]:
        """Basis matrix (columns = unit vectors in world), its name and axis names, from
        ``data`` (the state the values were read from; default: the physics state)."""
        if self.basis.value != BASIS_0 and 0 < self.body < sim.model.nbody:
            state = sim.data if data is None else data
            return (
                state.xmat[self.body].reshape(3, 3).copy(),
                "B₁",
                ("x<sub>1</sub>", "y<sub>1</sub>", "z<sub>1</sub>"),
            )
        return np.eye(3), "B₀", ("x<sub>0</sub>", "y<sub>0</sub>", "z<sub>0</sub>")

    # -- refresh -------------------------------------------------------------------------
    def reference(self, sim: ReadOnlySimulation) -> dict[str, float]:
        """The course's closed-form values, recomputed only when parameters change."""
        key = tuple(sorted(sim.values.items()))
        if key != self._ref_key:
            self._ref, self._ref_key = sim.reference(), key
        return self._ref

    def plot_names(self) -> list[str]:
        """Readouts drawn by the plots."""
        return [n for plot in self.plots for n in plot.names]

    def names(self, folder: str | None) -> list[str]:
        """Readouts a folder shows (none for other folders)."""
        if folder == SCENE_FOLDER:
            return [row.name for row in self.scene_rows]
        if folder == TORSORS_FOLDER:
            return list(TORSOR_NAMES)
        if folder == ENERGY_FOLDER:
            return list(ENERGY_NAMES)
        return []

    def pickable(self) -> list[Folder]:
        """Its folders of « Panneau affiché »: they show only a frame's readouts (the
        withheld ones removed), so a challenge keeps them. The plots are filled by
        :meth:`sample` at every panel tick, shown or not (their history goes on)."""
        return [self._folder(title, handle) for title, handle in self.folders.items()]

    def _folder(self, title: str, handle: viser.GuiFolderHandle) -> Folder:
        def refresh(frame: Frame) -> None:
            if frame.readouts is not None:
                self.refresh(self.sim, frame.readouts, title, state=frame.state)

        def names() -> list[str]:
            return self.names(title)

        plots = title == PLOTS_FOLDER
        return Folder(title, handle, None if plots else refresh, names, secret_safe=True)

    def sample(
        self,
        values: Mapping[str, float],
        *,
        push: bool = True,
        picture: Picture | None = None,
    ) -> None:
        """Add the current readouts (and the arrow components of the frame's ``picture``)
        to the plots; send them when ``push``."""
        for plot in self.plots:
            plot.append(values)
            if push:
                plot.push()
        if self.components is not None and picture is not None:
            self.sample_components(picture)
            if push:
                self.components.push()

    def sample_components(self, picture: Picture) -> None:
        """Add the arrows' components of a frame's picture (in B0, or in B1 of the scene's
        body frame): evaluated once with the frame, not again here."""
        if self.components is None or len(picture.vectors) != len(self.scene_arrows):
            return
        vectors = {a.name: picture.vectors[k] for k, a in enumerate(self.scene_arrows)}
        basis = np.eye(3)
        if self.components.spec.basis == "B1" and 0 < self.body < len(picture.body_xquat):
            flat = np.zeros(9)
            mujoco.mju_quat2Mat(flat, np.asarray(picture.body_xquat[self.body], dtype=float))
            basis = flat.reshape(3, 3)
        try:
            row = self.components.components(picture.time, vectors, basis)
        except (ValueError, FloatingPointError, IndexError, KeyError):
            return
        self.components.append(row)

    def refresh(
        self,
        sim: ReadOnlySimulation,
        values: Mapping[str, float],
        folder: str | None = None,
        *,
        state: Snapshot | None = None,
    ) -> None:
        """Rewrite the table of ``folder`` (every table when None) from ``values``, read
        from ``state`` (None: the physics state), which also gives a solid's basis."""
        if self.scene_text is not None and folder in (None, SCENE_FOLDER):
            rows, reference = self.scene_rows, self.reference(sim)
            if self.withheld:  # a challenge runs: neither the readouts nor the course's values
                rows = [r for r in rows if r.name not in self.withheld]
                reference = {k: v for k, v in reference.items() if k not in self.withheld}
            _set(self.scene_text, tables.scene_markdown(rows, values, reference))
        if folder in (None, TORSORS_FOLDER):
            point, point_name = self.chosen_point()
            basis, basis_name, axes = self.chosen_basis(sim, state.data if state else None)
            _set(
                self.torsor_text,
                tables.torsors_markdown(
                    values,
                    point=point,
                    point_name=point_name,
                    basis=basis,
                    basis_name=basis_name,
                    axes=axes,
                    zero=self.zero,
                ),
            )
        if folder in (None, ENERGY_FOLDER):
            friction = friction_on(self.sim.values)
            _set(
                self.energy_text,
                tables.energy_markdown(values, zero=self.zero, friction=friction),
            )


def _set(handle: viser.GuiMarkdownHandle, content: str) -> None:
    if handle.content != content:
        handle.content = content
