"""Error statistics defined once, used by every paper: tracking errors and force errors alike.

A paper's own definitions (ICE, eq. 18 of one paper; "sag" of another) build on these; where a paper
defines an integral differently, its analysis says so and computes it there.
"""

from __future__ import annotations

import numpy as np


def error_stats(t: np.ndarray, error: np.ndarray, prefix: str, unit: str) -> dict[str, tuple[float, str]]:
    """max |e|, mean |e| (MAE), RMS and ∫e² dt (ISE, trapezoidal) of a sampled error signal."""
    t, e = np.asarray(t, dtype=float), np.asarray(error, dtype=float)
    a = np.abs(e)
    square_unit = f"{unit}^2*s" if unit else "s"
    return {
        f"{prefix}.max": (float(a.max()), unit),
        f"{prefix}.mean": (float(a.mean()), unit),
        f"{prefix}.rms": (float(np.sqrt(np.mean(e * e))), unit),
        f"{prefix}.ise": (float(np.trapezoid(e * e, t)), square_unit),
    }


def force_error_stats(t: np.ndarray, measured: np.ndarray, commanded: np.ndarray,
                      prefix: str = "force_error") -> dict[str, tuple[float, str]]:
    """Force error |F_measured − F_commanded| (N): max, mean, RMS, ISE; and the sag, the largest drop of
    the measured force below the set point as a fraction of it (the set point is the commanded force)."""
    measured, commanded = np.asarray(measured, dtype=float), np.asarray(commanded, dtype=float)
    stats = error_stats(t, measured - commanded, prefix, "N")
    with np.errstate(divide="ignore", invalid="ignore"):
        drop = np.where(commanded != 0, (commanded - measured) / np.abs(commanded), np.nan)
    stats[f"{prefix}.sag"] = (float(np.nanmax(drop)) if np.isfinite(drop).any() else float("nan"), "fraction")
    return stats
