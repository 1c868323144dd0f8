"""The rotor's polar diagram of unbalance (course 7.2): its vectors for given parameter
values, which the page's folder « Diagramme des balourds » draws.

The rotor without its correction masses (shaft, skewed disk, flanges, defect) comes from
the scene's closed form (:func:`~sandbox.scenes.rotor.course.unbalance`); each correction
mass adds ``m r`` and ``x m r`` in its direction (:mod:`sandbox.mechanics.unbalance`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from sandbox.mechanics.unbalance import PointMass, Unbalance
from sandbox.physics.page import UnbalanceDiagram
from sandbox.scenes.rotor.course import unbalance
from sandbox.scenes.rotor.params import CORRECTION_RADIUS, PLANE_X

DEPENDS_ON = ("defect_mass_g", "skew_deg", "mass1_g", "angle1_deg", "mass2_g", "angle2_deg")
"""Parameters the diagram depends on (the speed does not change the unbalance)."""


def correction_masses(values: Mapping[str, float]) -> tuple[PointMass, PointMass]:
    """The two correction masses as point masses (plane 1 at x = −c, plane 2 at +c)."""
    return (
        PointMass(
            values["mass1_g"] / 1000.0,
            -PLANE_X,
            CORRECTION_RADIUS,
            values["angle1_deg"],
        ),
        PointMass(
            values["mass2_g"] / 1000.0,
            PLANE_X,
            CORRECTION_RADIUS,
            values["angle2_deg"],
        ),
    )


def rotor_unbalance(values: Mapping[str, float]) -> Unbalance:
    """The unbalance vectors of the rotor scene for parameter ``values``.

    The rotor without its correction masses (shaft, skewed disk, flanges, defect) comes
    from the scene's closed form (:func:`~sandbox.scenes.rotor.course.unbalance`); the correction
    masses add ``m r`` and ``x m r`` in their direction.
    """
    bare = {**values, "mass1_g": 0.0, "mass2_g": 0.0}
    mass, g, e, f = unbalance(bare)
    m1, m2 = correction_masses(values)
    return Unbalance(
        static={"rotor": mass * np.array([g[1], g[2]]), "m1": m1.static, "m2": m2.static},
        couple={"rotor": np.array([f, e]), "m1": m1.couple, "m2": m2.couple},
    )


DIAGRAM = UnbalanceDiagram(rotor_unbalance, DEPENDS_ON)
"""What the rotor declares: its unbalance for parameter values, and what it depends on."""
