"""Signal measures defined once, used by every paper: how much a control signal chatters.

Chattering is the fast switching of a control input (a sliding-mode controller's torque, say) on top of the
slow part that does the work. Two measures, both on a uniformly sampled signal u(t):

- total variation rate  TV = Σ_k |u_k − u_{k−1}| / (t_N − t_0)   [unit/s]
  How far the signal travels per second. A slow signal contributes little (2A/period for a sine of amplitude
  A); switching by ±δ every sample contributes 2δ/Δt. It depends on the sample rate: compare signals sampled
  alike (the control rate).
- high-frequency RMS  HF = RMS of u after a zero-phase Butterworth high-pass at `cutoff_hz`   [unit]
  The energy of the signal above the cutoff (its square is that energy per second): what shakes the
  structure, blind to the slow part however large. An order-4 filter run forwards and backwards passes the
  power 1/(1 + (f_c/f)^8)² of a sine at f: below f_c/10 less than 1e-15 of its energy, above 10 f_c more than
  1 − 1e-7.

`low_pass` keeps the slow part (the same filter as a low-pass): a force without the chattering riding on it.
`sign_change_rate` counts the zero crossings of a switching variable (a sliding surface) per second.
"""

from __future__ import annotations

import numpy as np

DEFAULT_CUTOFF_HZ = 10.0   # above the exercise's bandwidth (≲ 1 Hz), below the 1 kHz switching


def _span(t: np.ndarray) -> float:
    t = np.asarray(t, dtype=float)
    if len(t) < 2 or not t[-1] > t[0]:
        raise ValueError("a signal measure needs at least two samples over a positive time span")
    return float(t[-1] - t[0])


def total_variation_rate(t: np.ndarray, u: np.ndarray) -> float:
    """Σ |u_k − u_{k−1}| / (t_N − t_0): how far the signal travels per second."""
    return float(np.abs(np.diff(np.asarray(u, dtype=float))).sum() / _span(t))


def _filtered(t: np.ndarray, u: np.ndarray, cutoff_hz: float, kind: str, order: int) -> np.ndarray:
    from scipy import signal

    t, u = np.asarray(t, dtype=float), np.asarray(u, dtype=float)
    rate = (len(t) - 1) / _span(t)
    if not 0 < cutoff_hz < rate / 2:
        raise ValueError(f"cutoff {cutoff_hz} Hz must lie between 0 and the Nyquist rate {rate / 2:g} Hz")
    # pad by odd reflection over three periods of the cutoff: the filter's start-up transient dies out in the pad
    pad = min(len(u) - 1, int(3 * rate / cutoff_hz))
    return signal.sosfiltfilt(signal.butter(order, cutoff_hz, btype=kind, fs=rate, output="sos"), u, padlen=pad)


def high_frequency_rms(t: np.ndarray, u: np.ndarray, cutoff_hz: float = DEFAULT_CUTOFF_HZ, order: int = 4) -> float:
    """RMS of u above `cutoff_hz`: zero-phase Butterworth high-pass (scipy `sosfiltfilt`), uniform samples."""
    return float(np.sqrt(np.mean(_filtered(t, u, cutoff_hz, "highpass", order) ** 2)))


def low_pass(t: np.ndarray, u: np.ndarray, cutoff_hz: float = DEFAULT_CUTOFF_HZ, order: int = 4) -> np.ndarray:
    """The slow part of u: the same zero-phase Butterworth filter as `high_frequency_rms`, as a low-pass."""
    return _filtered(t, u, cutoff_hz, "lowpass", order)


def sign_change_rate(t: np.ndarray, s: np.ndarray) -> float:
    """Zero crossings of s per second (exact zeros do not count as a sign)."""
    signs = np.sign(np.asarray(s, dtype=float))
    signs = signs[signs != 0]
    return float((signs[1:] != signs[:-1]).sum() / _span(t))


def chattering_stats(t: np.ndarray, u: np.ndarray, prefix: str, unit: str,
                     cutoff_hz: float = DEFAULT_CUTOFF_HZ) -> dict[str, tuple[float, str]]:
    """`<prefix>.tv` (unit/s) and `<prefix>.hf_rms` (unit) of a control signal, as (value, unit)."""
    return {f"{prefix}.tv": (total_variation_rate(t, u), f"{unit}/s"),
            f"{prefix}.hf_rms": (high_frequency_rms(t, u, cutoff_hz), unit)}
