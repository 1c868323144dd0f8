"""Inertia matrix of a solid (course 5.2–5.7, formulary A.3): read it, move it, spin it.

The user picks a solid (the square-based block of 5.4, the shapes of 5.6, the rod and the
three-cylinder crankshaft of 5.7, the micro-compressor's parts), a point and a basis. The
readouts give the matrix there with the course's signs, I = [[A, −F, −E], [−F, B, −D],
[−E, −D, C]], computed from the simulated model (MuJoCo's mass, G and principal inertia,
which it integrates from the geoms), next to the course's closed form; the principal
moments at G and Huygens' transport terms. The solid floats on a free joint, weight
neglected: launched about one of its principal axes at G it spins freely (Euler's
torque-free motion), steadily about the smallest and the largest moments, while about the
intermediate one a small perturbation grows into a flip and back, with the period of
:func:`~sandbox.mechanics.inertia.torque_free_period`.

The package holds one concept per module: :mod:`~sandbox.scenes.inertia.params` (the
solids and the parameter table), :mod:`~sandbox.scenes.inertia.course` (the course's
formulas), :mod:`~sandbox.scenes.inertia.model` (the mesh edits of the model and the
launch), :mod:`~sandbox.scenes.inertia.readouts` (readouts and arrows) and
:mod:`~sandbox.scenes.inertia.scene` (the spec, its accuracy test and timestep).
"""

from __future__ import annotations

from sandbox.scenes.inertia.course import course_inertia, flip_period, parts, reference
from sandbox.scenes.inertia.params import (
    BLOCK,
    CRANKSHAFT,
    CRANKSHAFT_PARTS,
    CYLINDER,
    HOLLOW,
    PARAMS,
    ROD,
    SOLIDS,
    SPHERE,
    SQUARE_BLOCK,
)
from sandbox.scenes.inertia.scene import SCENE, flip_times

__all__ = [
    "BLOCK",
    "CRANKSHAFT",
    "CRANKSHAFT_PARTS",
    "CYLINDER",
    "HOLLOW",
    "PARAMS",
    "ROD",
    "SCENE",
    "SOLIDS",
    "SPHERE",
    "SQUARE_BLOCK",
    "course_inertia",
    "flip_period",
    "flip_times",
    "parts",
    "reference",
]
