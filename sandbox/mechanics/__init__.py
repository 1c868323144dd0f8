"""The course's mathematics with numpy only: torsors and inertia (no MuJoCo, no viser)."""

from sandbox.mechanics.inertia import (
    MassProperties,
    block,
    change_basis,
    coefficients,
    combine,
    cylinder,
    hollow_cylinder,
    huygens,
    huygens_to_G,
    inertia_matrix,
    move_inertia,
    point_mass,
    principal_axes,
    rod,
    rotation_matrix,
    sphere,
)
from sandbox.mechanics.torsor import Torsor, kinematic_torsor, sum_torsors

__all__ = [
    "MassProperties",
    "Torsor",
    "block",
    "change_basis",
    "coefficients",
    "combine",
    "cylinder",
    "hollow_cylinder",
    "huygens",
    "huygens_to_G",
    "inertia_matrix",
    "kinematic_torsor",
    "move_inertia",
    "point_mass",
    "principal_axes",
    "rod",
    "rotation_matrix",
    "sphere",
    "sum_torsors",
]
