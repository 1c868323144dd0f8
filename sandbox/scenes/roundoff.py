"""Round-off of the scenes driven at constant speed (rotor, compressor, engine).

A scene's ``zero`` maps a contract unit to the absolute value under which a reading is
round-off and shows as 0. The three machines turning at constant speed share these
entries; each adds its own (lengths, unbalances) beside them.
"""

from __future__ import annotations

from collections.abc import Mapping

ROUND_OFF: Mapping[str, float] = {
    # the imposed motion's inverse dynamics (loops closed by Newton to 1e-12 m) leaves
    # about 1e-9 of the largest value in a component that is 0 at a dead centre (the
    # compressor's tamis read −2,622×10⁻⁷ N beside a 269,8 N pilon, its torque
    # −1,969×10⁻⁹ N·m): these floors hide that, and stay 1e8 times below the smallest
    # scene's largest values (tests/scenes/test_labels.py)
    "N": 5e-7,
    "N·m": 5e-9,
    "W": 1e-6,
    "J": 1e-12,
    "kg·m/s": 1e-12,
    "kg·m²/s": 1e-12,
}
"""Round-off by unit of the machines turning at constant speed (rotor, compressor, engine):
forces, moments, powers, energies and momenta."""
