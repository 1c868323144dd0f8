"""The kinetic-energy theorem checked on the generic readouts.

dT/dt = P_ext + P_int + P_frame: the power of the accelerations ``P_acc`` (= dT/dt)
equals the powers of the outside actions and of the inter-efforts plus the power of the
frame's reactions, which is 0 for perfect fixed joints. What is left over is shown by
the readout panel as a check of the model's hypotheses.
"""

from __future__ import annotations

import math
from collections.abc import Mapping


def frame_power(values: Mapping[str, float]) -> float:
    """Power of the frame's reactions P_frame = P_acc − P_ext − P_int [W].

    Args:
        values: Readouts by name, including ``P_acc``, ``P_ext`` and ``P_int`` (a missing
            one gives nan).
    """
    p_acc = values.get("P_acc", math.nan)
    return p_acc - values.get("P_ext", math.nan) - values.get("P_int", math.nan)
