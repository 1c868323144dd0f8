"""Vector arithmetic on the small arrays of one mechanism (a handful of bodies), where a
numpy call per operation costs more than the arithmetic itself.
"""

from __future__ import annotations

import numpy as np

_SMALL = 32
"""Up to this many vectors, :func:`cross` works on Python floats (a handful of bodies:
one numpy call per component would cost more than the arithmetic)."""


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a ∧ b on the last axis, for (3,) or (n, 3) arrays (cheaper than np.cross).

    Each component is a1 b2 − a2 b1 (and its cyclic shifts) in IEEE double arithmetic,
    the same operations whichever path computes it.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.ndim == 1 and b.ndim == 1:
        a0, a1, a2 = a.tolist()
        b0, b1, b2 = b.tolist()
        return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])
    if a.shape != b.shape:
        a, b = np.broadcast_arrays(a, b)
    if a.ndim == 2 and 0 < len(a) <= _SMALL:
        return np.array(
            [
                (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)
                for (a0, a1, a2), (b0, b1, b2) in zip(a.tolist(), b.tolist(), strict=True)
            ]
        )
    out = np.empty(a.shape)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out
