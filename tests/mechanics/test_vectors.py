"""The small-array cross product shared by the readouts and the scenes."""

from __future__ import annotations

import numpy as np
import pytest

from sandbox.mechanics.vectors import cross


@pytest.mark.parametrize("shape", [(3,), (1, 3), (5, 3), (40, 3)])
def test_cross_is_numpys_on_every_path(shape):
    rng = np.random.default_rng(7)
    a, b = rng.normal(size=shape), rng.normal(size=shape)
    got = cross(a, b)
    assert got.shape == shape
    assert np.array_equal(got, np.cross(a, b))  # the same IEEE operations: bit for bit


def test_cross_broadcasts_one_vector_against_many():
    a = np.array([0.0, 0.0, 1.0])
    b = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    assert cross(a, b).tolist() == [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
