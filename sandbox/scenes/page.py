"""What a scene declares for the page, so that the web layer names no scene: the French
names of its solids and markers (:class:`Names`), and the diagrams it draws
(:class:`UnbalanceDiagram`: a rotor's static and couple unbalance for given parameter
values, course 7.2, as two polar diagrams in the folder « Diagramme des balourds »).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from sandbox.mechanics.unbalance import Unbalance


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
