"""Fractional-order derivatives for sampled-data controllers: the short-memory Grünwald–Letnikov filter.

    D^α f(kT) ≈ T^(−α) Σ_{j=0..n} w_j f((k−j)T),   w_0 = 1,  w_j = (1 − (1+α)/j) w_{j−1}

(w_j = (−1)^j C(α, j)); for α = 1/2 the recursion is w_j = (1 − 3/(2j)) w_{j−1}. The memory is n·T: the
samples before it are forgotten (the short-memory principle), so the filter has a nonzero DC gain
Σ w_j / T^α that a controller may have to compensate.
"""

from __future__ import annotations

import numpy as np


def gl_weights(order: float, n: int) -> np.ndarray:
    """The n + 1 Grünwald–Letnikov coefficients w_0..w_n of a derivative of `order`."""
    w = np.empty(n + 1)
    w[0] = 1.0
    for j in range(1, n + 1):
        w[j] = (1.0 - (1.0 + order) / j) * w[j - 1]
    return w


def gl_dc_gain(order: float, n: int, period: float) -> float:
    """Σ w_j / T^α: what the truncated filter returns for a constant unit input once its memory is full."""
    return float(gl_weights(order, n).sum() / period ** order)


def gl_frequency_response(order: float, n: int, period: float, omega: np.ndarray) -> np.ndarray:
    """G(e^{jωT}) = T^(−α) Σ w_j e^{−jωjT} of the filter at angular frequencies `omega` (rad/s)."""
    w = gl_weights(order, n)
    z = np.exp(-1j * np.outer(np.asarray(omega, dtype=float) * period, np.arange(n + 1)))
    return z @ w / period ** order


class GrunwaldLetnikov:
    """Streaming filter over vector samples: `push(x)` stores the sample of this period and returns the
    derivative estimate. The history before the first sample is zero."""

    def __init__(self, order: float, n: int, period: float, width: int):
        w = gl_weights(order, n) / period ** order
        # history row m holds the sample of period k with k ≡ m (mod n+1); with the newest sample in row i,
        # weights[i][m] = w[(i − m) mod (n+1)] gives it w_0, the one before w_1, …
        rows = np.arange(n + 1)
        self._weights = w[(rows[:, None] - rows[None, :]) % (n + 1)]
        self._history = np.zeros((n + 1, width))
        self._index = -1

    def push(self, sample: np.ndarray) -> np.ndarray:
        self._index = (self._index + 1) % len(self._history)
        self._history[self._index] = sample
        return self._weights[self._index] @ self._history
