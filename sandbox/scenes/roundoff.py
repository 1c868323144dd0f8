"""Round-off of the scenes driven at constant speed (rotor, compressor, engine).

A scene's ``zero`` maps a contract unit to the absolute value under which a reading is
round-off and shows as 0. The three machines turning at constant speed share these
entries; each adds its own (lengths, unbalances) beside them.
"""

from __future__ import annotations

from collections.abc import Mapping

ROUND_OFF: Mapping[str, float] = {
    "N": 1e-9,
    "N·m": 1e-10,
    "W": 1e-9,
    "J": 1e-12,
    "kg·m/s": 1e-12,
    "kg·m²/s": 1e-12,
}
"""Round-off by unit of the machines turning at constant speed (rotor, compressor, engine):
forces, moments, powers, energies and momenta."""
