"""The critically damped second-order filter of Sec. 2: G(s) = p²/(s + p)² (eq. 1), discretised with a
zero-order hold (eq. 2) and run as the difference equation (3)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Coefficients:
    """h1, h2, b1, b2 of eq. (2): α_f(n) = h1 α_c(n−1) + h2 α_c(n−2) + b1 α_f(n−1) + b2 α_f(n−2)."""

    h1: float
    h2: float
    b1: float
    b2: float

    @classmethod
    def zoh(cls, p: float, T: float) -> Coefficients:
        """Eq. (2) with m = pT."""
        m = p * T
        e = math.exp(-m)
        return cls(h1=1.0 - e * (1.0 + m), h2=e * (m - 1.0 + e), b1=2.0 * e, b2=-e * e)

    @property
    def numerator(self) -> np.ndarray:
        """[0, h1, h2]: coefficients of z⁰, z⁻¹, z⁻² (SciPy's convention)."""
        return np.array([0.0, self.h1, self.h2])

    @property
    def denominator(self) -> np.ndarray:
        return np.array([1.0, -self.b1, -self.b2])

    @property
    def dc_gain(self) -> float:
        return (self.h1 + self.h2) / (1.0 - self.b1 - self.b2)

    def step(self, alpha_c: tuple[float, float], alpha_f: tuple[float, float]) -> float:
        """Eq. (3) for one sample from (α_c(n−1), α_c(n−2)) and (α_f(n−1), α_f(n−2))."""
        return self.h1 * alpha_c[0] + self.h2 * alpha_c[1] + self.b1 * alpha_f[0] + self.b2 * alpha_f[1]


def apply(c: Coefficients, alpha_c: np.ndarray, initial: float = 0.0) -> np.ndarray:
    """Eq. (3) over a whole signal, with α_c and α_f equal to `initial` at n = −1, −2 (the paper leaves them
    open). A plain loop: the recursion is sequential, and SciPy's `lfilter` (the tests' oracle) costs a
    second of import for a thousand multiply-adds."""
    alpha_c = np.asarray(alpha_c, dtype=float).tolist()
    out = np.empty(len(alpha_c))
    c1 = c2 = f1 = f2 = initial
    h1, h2, b1, b2 = c.h1, c.h2, c.b1, c.b2
    for n, x in enumerate(alpha_c):
        f = h1 * c1 + h2 * c2 + b1 * f1 + b2 * f2
        out[n] = f
        c1, c2, f1, f2 = x, c1, f, f1
    return out
