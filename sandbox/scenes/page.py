"""What a scene declares for the page, so that the web layer names no scene: the arrows
of the 3D view (:class:`Arrow`), the French names of its solids and markers
(:class:`Names`), the arrows plotted by component (:class:`Components`), and the diagrams
it draws (:class:`UnbalanceDiagram`: a rotor's static and couple unbalance for given
parameter values, course 7.2, as two polar diagrams in the folder « Diagramme des
balourds »).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from sandbox.mechanics.unbalance import Unbalance
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.units import display_unit


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
