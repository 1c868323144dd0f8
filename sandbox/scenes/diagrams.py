"""Diagrams a scene declares for the page to draw, so that the web layer names no scene.

:class:`UnbalanceDiagram`: a rotor's static and couple unbalance for given parameter values
(course 7.2), drawn as two polar diagrams (folder « Diagramme des balourds »).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from sandbox.mechanics.unbalance import Unbalance


@dataclass(frozen=True)
class UnbalanceDiagram:
    """A rotor's unbalance diagram.

    Attributes:
        unbalance: The unbalance vectors of the rotor's parts for parameter values.
        depends_on: The parameters they depend on (the page redraws when one changes).
    """

    unbalance: Callable[[Mapping[str, float]], Unbalance]
    depends_on: tuple[str, ...]
