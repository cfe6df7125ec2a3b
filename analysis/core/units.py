"""Unit conversion at the edge: metrics are SI; a paper's table may use mm, degrees, µs, …"""

from __future__ import annotations

import math

# factor such that value_in_unit = value_in_SI * factor
_TO_SI_FACTOR = {
    "": 1.0, "1": 1.0, "count": 1.0, "bool": 1.0, "ratio": 1.0,
    "m": 1.0, "mm": 1e3, "cm": 1e2, "um": 1e6,
    "m^2": 1.0, "mm^2": 1e6, "m^3": 1.0, "mm^3": 1e9,
    "rad": 1.0, "deg": 180.0 / math.pi, "mrad": 1e3,
    "rad/s": 1.0, "deg/s": 180.0 / math.pi, "rad/s^2": 1.0,
    "m/s": 1.0, "mm/s": 1e3, "m/s^2": 1.0,
    "s": 1.0, "ms": 1e3, "us": 1e6, "ns": 1e9,
    "N": 1.0, "N*m": 1.0, "Nm": 1.0, "kg": 1.0, "g": 1e3, "W": 1.0, "J": 1.0, "Hz": 1.0,
    "Pa": 1.0, "MPa": 1e-6, "USD": 1.0,
    "%": 100.0, "fraction": 1.0,
}
_DIMENSION = {
    "": "1", "1": "1", "count": "1", "bool": "1", "ratio": "1",
    "m": "L", "mm": "L", "cm": "L", "um": "L", "m^2": "L2", "mm^2": "L2", "m^3": "L3", "mm^3": "L3",
    "rad": "A", "deg": "A", "mrad": "A", "rad/s": "A/T", "deg/s": "A/T",
    "s": "T", "ms": "T", "us": "T", "ns": "T", "m/s": "L/T", "mm/s": "L/T", "%": "1", "fraction": "1",
    "kg": "M", "g": "M", "Pa": "P", "MPa": "P",
}


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """Convert between units of the same dimension (SI metric -> a paper's unit)."""
    if from_unit == to_unit:
        return value
    for u in (from_unit, to_unit):
        if u not in _TO_SI_FACTOR:
            raise ValueError(f"unknown unit {u!r}")
    if _DIMENSION.get(from_unit, from_unit) != _DIMENSION.get(to_unit, to_unit):
        raise ValueError(f"cannot convert {from_unit} to {to_unit}")
    return value / _TO_SI_FACTOR[from_unit] * _TO_SI_FACTOR[to_unit]
