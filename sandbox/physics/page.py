"""What a scene declares for the page, so that the web layer names no scene: one
:class:`Page` record (``Scene.page``) holding the arrows of the 3D view (:class:`Arrow`),
the French names of its solids and markers (:class:`Names`), the arrows plotted by
component (:class:`Components`), the diagrams it draws (:class:`UnbalanceDiagram`: a
rotor's static and couple unbalance for given parameter values, course 7.2, as two polar
diagrams in the folder « Diagramme des balourds »; :class:`Bearing`: the pivots it models
as plain bearings, whose contact pressure the folder « Pression dans les paliers » draws,
course appendix B.2), its camera, plots and presets.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from sandbox.mechanics.unbalance import Unbalance
from sandbox.physics.presets import StudyPreset, XYPreset
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.units import display_unit

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Names:
    """French names the page gives a scene's parts.

    Attributes:
        solids: Body name -> the course's name of the solid (« 2 (bielle) »), in the folder
            « Isoler un solide » and the basis B1 of the torsors.
        markers: Site name -> its label in the 3D view (« m₁ », « Point lourd »).
    """

    solids: Mapping[str, str] = field(default_factory=dict)
    markers: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class UnbalanceDiagram:
    """A rotor's unbalance diagram.

    Attributes:
        unbalance: The unbalance vectors of the rotor's parts for parameter values.
        depends_on: The parameters they depend on (the page redraws when one changes).
    """

    unbalance: Callable[[Mapping[str, float]], Unbalance]
    depends_on: tuple[str, ...]


@dataclass(frozen=True)
class Bearing:
    """A pivot the scene models as a plain bearing: a shaft turning in a bore whose radius
    and length are the scene's parameters ``bearing_R`` and ``bearing_L``.

    Attributes:
        name: Its letter, as the course and the 3D view name it ("A"); its readouts are
            ``bearing_<name>_pmax`` and ``bearing_<name>_Cf``.
        label: Its French name (« Palier A »).
        load: The force of the frame on the shaft at the bearing [N], world axes, at a
            state whose forces are prepared.
        axis: The bore's axis, world axes (a unit vector, fixed with the frame).
        across: The direction of the bore's plane drawn to the right (a unit vector
            across ``axis``); the one drawn up is ``axis ∧ across``.
        words: How the page names the two drawn directions (« y₀ », « z₀ »).
    """

    name: str
    label: str
    load: Callable[[Snapshot], np.ndarray]
    axis: Vec3
    across: Vec3
    words: tuple[str, str]


@dataclass(frozen=True)
class FlowStage:
    """One organ of a power chain in the folder « Flux de puissance ».

    Attributes:
        name: Its French name (« Multiplicateur »).
        power_out: The readout of the power it passes on to the next organ [W].
        loss: The readout of the power it loses (heat; the wind the blades let through)
            [W]; "" when it loses none.
        stored: The readout of the power its inertia stores as kinetic energy (dT/dt
            of that inertia: positive while it speeds up) [W]; "" when it has none.
        loss_words: What its loss is, in French (« chaleur », « vent non capté »).
    """

    name: str
    power_out: str
    loss: str = ""
    stored: str = ""
    loss_words: str = "chaleur"


@dataclass(frozen=True)
class PowerFlow:
    """A power chain in series (course 6.4), drawn live as a Sankey diagram.

    Attributes:
        source: The readout of the power entering the chain [W].
        source_words: What enters, in French (« Vent, limite de Betz »).
        stages: The organs in order; the last one's ``power_out`` is what leaves.
        sink_words: Where the power leaving goes (« Réseau »).
        efficiency: The readout of the chain's overall efficiency (power out / in).
    """

    source: str
    source_words: str
    stages: tuple[FlowStage, ...]
    sink_words: str
    efficiency: str = ""


@dataclass(frozen=True)
class Arrow:
    """An arrow drawn in the 3D view: origin and vector (world frame) from a snapshot.

    Attributes:
        name: Contract name (lessons' ``arrows:`` lines); a scene readout of the same
            name, when there is one, is the arrow's magnitude.
        label: French words of the 3D label, e.g. "Palier A" (no unit, no value).
        color: RGB colour of the arrow (0-255).
        fn: (origin [m], vector [``unit``]) in world coordinates, from a snapshot.
        scale: Metres of arrow per unit of the vector (e.g. 4e-3 m/N).
        unit: Unit of the vector (contract form, "" when dimensionless); the label
            shows :attr:`display_unit` after the magnitude.
        point: Name of the point the arrow starts from (e.g. "A"), offered as a
            reduction point of the torsors; "" when it is not a named point.
        hint: French sentence saying what the arrow shows (legend, tooltip).
        magnitude: False for a direction (a unit vector such as a rotor's axis): the
            label is then the words alone.
    """

    name: str
    label: str
    color: tuple[int, int, int]
    fn: Callable[[Snapshot], tuple[np.ndarray, np.ndarray]]
    scale: float = 1.0
    unit: str = ""
    point: str = ""
    hint: str = ""
    magnitude: bool = True

    @property
    def display_unit(self) -> str:
        """The vector's unit as the web page shows it."""
        return display_unit(self.unit)

    def caption(self, value: str) -> str:
        """The 3D label with the magnitude already written in French (``value``, e.g.
        "0,91"): "Palier A : 0,91 N"; the words alone for a direction."""
        if not self.magnitude:
            return self.label
        return f"{self.label} : {value} {self.display_unit}".rstrip()


@dataclass(frozen=True)
class Components:
    """Components of some of a scene's arrows plotted against time: a force or a momentum
    whose magnitude stays constant can still turn, and its components show how.

    Attributes:
        arrows: Names of the scene's arrows (vectors in world coordinates).
        basis: "B0" (fixed, the world axes) or "B1" (the scene's ``body_frame``).
        axes: Which components (0, 1, 2 for x, y, z of the basis).
        words: How the basis is named in the title, e.g. "B1, tournant avec le rotor".
    """

    arrows: tuple[str, ...]
    basis: str
    axes: tuple[int, ...]
    words: str


@dataclass(frozen=True)
class Page:
    """What the web page (and a lesson, a replay) shows of a scene; the simulation reads
    none of it.

    Attributes:
        plots: Readout names plotted by default.
        arrows: Arrows drawn in the 3D view.
        body_frame: Body whose frame gives the basis B1 of the readout panel.
        names: French names of the solids and markers.
        camera: (direction from the model towards the camera, up vector) of the 3D view.
        look_at: (point [m], distance [m]) framed by the camera instead of the whole model.
        trail: A point whose path the 3D view draws (e.g. the tip of a gyroscope's axis).
        start_paused: The page waits for « Lecture ».
        leaves_view: The motion carries the mechanism out of the view: the page offers to
            follow the moving body with the camera (off at the start: following moves
            each browser's camera every frame, 0.6 ms of server CPU per frame measured
            with 30 browsers on the rolling cylinder, 48 -> 33 frames/s).
        overlay: The 3-4 key readouts written large over the 3D view (projector mode), by
            name, with the short French words written there ("" keeps the readout's
            label); empty: the scene's kinetic and potential energies.
        imposed_overlay: The overlay's words that change while the motion is imposed
            (the motor's torque becomes the torque it must give: « Couple nécessaire »).
        xy_presets: Plots of one readout against another that show the course's laws
            (folder « Tracé X–Y »; the first is shown at the start).
        study_presets: Parameter studies that show them (folder « Étude paramétrique »).
        unbalance_diagram: The rotor's polar diagram of unbalance (None: no such diagram).
        bearings: The pivots modelled as plain bearings (folder « Pression dans les
            paliers »; empty: none).
        power_flow: A power chain drawn as a Sankey diagram (folder « Flux de
            puissance »; None: none).
        components: Arrows plotted by component against time (None: scalar plots only).
        balancing: The two bearing readouts whose larger one the class board shows, what
            balancing brings down (None: the overlay's key readouts).
    """

    plots: tuple[str, ...] = ()
    arrows: tuple[Arrow, ...] = ()
    body_frame: str | None = None
    names: Names = field(default_factory=Names)
    camera: tuple[Vec3, Vec3] | None = None
    look_at: tuple[Vec3, float] | None = None
    trail: Callable[[Snapshot], np.ndarray] | None = None
    start_paused: bool = False
    leaves_view: bool = False
    overlay: Mapping[str, str] = field(default_factory=dict)
    imposed_overlay: Mapping[str, str] = field(default_factory=dict)
    xy_presets: tuple[XYPreset, ...] = ()
    study_presets: tuple[StudyPreset, ...] = ()
    unbalance_diagram: UnbalanceDiagram | None = None
    bearings: tuple[Bearing, ...] = ()
    power_flow: PowerFlow | None = None
    components: Components | None = None
    balancing: tuple[str, str] | None = None
