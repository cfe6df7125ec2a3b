"""The reaching laws of the three compared controllers, and the reaching-time analysis of Sec. 4.

Per joint, with the sliding variable v = ė + λ e (eq. 3) and Table 3's gains (K, φ_i, α, p, ϕ):

    SMC     r = −K sign(v), or −K sat(v/Φ) with a boundary layer Φ (the paper uses none)
    SMERL   r = −K / D(v) · sign(v),                 D(v) = φ_i + (1 − φ_i) exp(−α |v|^p)      (ERL [42])
    nSMERL  r = −K / D(v) · |v|^ϕ sign(v) − ω(t) K (1 − ϕ)/φ_i · sign(v),  ω = 1/(1 + t²)  (eq. 6)

The laws act on one float (with `lib=math`: the controller's per-joint call) or on NumPy arrays (`lib=np`);
sign(0) = 0. The reaching time of v̇ = r(v, t) from v(0) is measured by integrating the scalar ODE to v = 0
and compared with the paper's closed forms: eq. (7) (ERL, exact), its bound (14), eqs. (13)/(21) (nSMERL) and
Proposition 1's threshold |v(0)| > (1 − ϕ)^(−1/ϕ), eq. (27).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# scipy (0.3 s to import) is imported by the reaching-time functions: a controller needs only the laws
LAWS = ("smc", "smerl", "nsmerl")
TINY = float(np.finfo(float).tiny)


@dataclass(frozen=True)
class LawGains:
    """Table 3 (one entry per joint) and the conventional SMC's own gain and boundary layer."""

    # one entry per joint (arrays), or floats for a single joint
    K: np.ndarray          # rad/s², K_1i of ERL and nSMERL
    phi: np.ndarray        # φ_i, the ERL floor (0 < φ_i < 1)
    alpha: np.ndarray      # α_i > 0
    p: np.ndarray          # p_i > 0
    power: float           # ϕ, 0 < ϕ < 0.5 (Table 3's "Φ")
    smc_K: np.ndarray      # rad/s², the conventional SMC's gain (not given: Table 3's K × gain_scale)
    boundary_layer: float  # rad/s, Φ of sat(v/Φ); 0 = sign (the paper's SMC)
    omega_rate: float = 1.0  # 1/s: ω = 1/(1 + (c t)²) with t in s; c = 1000 reads eq. (6)'s t_i in milliseconds

    def joint(self, i: int) -> LawGains:
        """Joint i's gains as floats."""
        return LawGains(K=float(self.K[i]), phi=float(self.phi[i]), alpha=float(self.alpha[i]), p=float(self.p[i]),
                        power=self.power, smc_K=float(self.smc_K[i]), boundary_layer=self.boundary_layer,
                        omega_rate=self.omega_rate)

    @classmethod
    def from_config(cls, control) -> LawGains:
        return cls(K=_array(control.K), phi=_array(control.phi), alpha=_array(control.alpha), p=_array(control.p),
                   power=float(control.power), smc_K=_array(control.K) * float(control.smc.gain_scale),
                   boundary_layer=float(control.smc.boundary_layer), omega_rate=float(control.omega_rate))


def _array(values) -> np.ndarray:
    return np.asarray(list(values), dtype=float)


def omega(t: float | np.ndarray) -> float | np.ndarray:
    """ω(t) = 1/(1 + t²), t the time since the trajectory started (eq. 6, dimensionless: t in s by default)."""
    return 1.0 / (1.0 + t * t)


def sign(v):
    """−1, 0 or 1, for a float or element-wise for an array."""
    return (v > 0) * 1.0 - (v < 0) * 1.0


def saturation(x):
    """x clipped to [−1, 1], for a float or element-wise for an array."""
    return x - (x > 1) * (x - 1) - (x < -1) * (x + 1)


def erl_gain(v, g: LawGains, lib=np):
    """K / (φ + (1 − φ) exp(−α |v|^p)): K at v = 0, rising to K/φ far from the surface."""
    return g.K / (g.phi + (1.0 - g.phi) * lib.exp(-g.alpha * abs(v) ** g.p))


def smc(v, t: float, g: LawGains, lib=np):
    if g.boundary_layer > 0:
        return -g.smc_K * saturation(v / g.boundary_layer)
    return -g.smc_K * sign(v)


def smerl(v, t: float, g: LawGains, lib=np):
    return -erl_gain(v, g, lib) * sign(v)


def nsmerl(v, t: float, g: LawGains, lib=np, switching: bool = True):
    """Eq. (6); `switching=False` drops the ω-term (the limit t → ∞ the proof of Proposition 1 takes)."""
    s = sign(v)
    r = -erl_gain(v, g, lib) * abs(v) ** g.power * s
    if switching:
        r = r - omega(g.omega_rate * t) * g.K * (1.0 - g.power) / g.phi * s
    return r


REACHING_LAWS = {"smc": smc, "smerl": smerl, "nsmerl": nsmerl}


# -- reaching time (Sec. 4, eqs. 7-30) ------------------------------------------------------------------------


def reaching_time(law, v0: float, g: LawGains, horizon: float = 1e3, rtol: float = 1e-10) -> float:
    """Time for v̇ = law(v, t) to bring v from v0 to 0 (the scalar reaching phase), by integrating v(t) to an
    event at |v| = 1e-12 |v0| (the definition; `reaching_times` is the fast form). The last 1e-12 |v0| is left
    out: a law like |v|^ϕ sign(v) is not Lipschitz at 0, where the step control would stall. NaN if not reached
    within `horizon` s."""
    from scipy import integrate

    if v0 == 0:
        return 0.0
    end = 1e-12 * abs(v0)

    def rate(t, v):
        return law(np.asarray(v), t, g)

    def arrival(t, v):
        return abs(v[0]) - end

    arrival.terminal, arrival.direction = True, -1
    sol = integrate.solve_ivp(rate, (0.0, horizon), [v0], events=arrival, rtol=rtol, atol=1e-3 * end, method="RK45")
    return float(sol.t_events[0][0]) if len(sol.t_events[0]) else float("nan")


def reaching_times(v0: float, g: LawGains) -> dict[str, float]:
    """Reaching times from v0 > 0 of every law (`g`: one joint's gains, as floats), computed as t(v) rather
    than v(t): for the autonomous laws T = ∫_0^v0 dv / |r(v)| by quadrature; for nSMERL, whose ω-term depends on
    t, the ODE dt/dv = 1/r(v, t) from v0 down to 0 (its right side stays bounded: |r| ≥ ω(t) K (1 − ϕ)/φ). Equal to
    `reaching_time` (tests) at a fraction of its cost."""
    from scipy import integrate

    def inverse_rate(law):
        return lambda v: -1.0 / law(v, 0.0, g, math)

    # the ERL gain steps from K to K/φ within |v| ~ α^(−1/p) of the surface: tell quad where
    knee = [min(float(g.alpha) ** (-1.0 / float(g.p)), v0 / 2)]
    out = {name: integrate.quad(inverse_rate(law), 0.0, v0, points=knee, limit=200, epsrel=1e-10)[0]
           for name, law in (("smc", smc), ("smerl", smerl),
                             ("nsmerl_no_switching", lambda v, t, g, lib: nsmerl(v, t, g, lib, switching=False)))}

    def dt_dv(v, t):
        return [1.0 / nsmerl(max(float(v), TINY), float(t[0]), g, math)]   # the sign at v → 0⁺

    sol = integrate.solve_ivp(dt_dv, (v0, 0.0), [0.0], rtol=1e-9, atol=1e-12, method="DOP853")
    out["nsmerl"] = float(sol.y[0, -1])
    return out


def crossover(g: LawGains, bracket: tuple[float, float], switching: bool = True) -> float:
    """The largest |v(0)| in `bracket` at which nSMERL (with or without its ω-term) and ERL take equally long to
    reach v = 0: above it nSMERL is faster. The lower end if nSMERL is faster over the whole bracket, NaN if
    it is slower at the upper end. Found by scanning a log grid, then Brent's method on the last sign change."""
    from scipy import optimize

    name = "nsmerl" if switching else "nsmerl_no_switching"

    def gap(v0: float) -> float:
        times = reaching_times(v0, g)
        return times[name] - times["smerl"]

    grid = np.geomspace(*bracket, 25)
    gaps = np.array([gap(v) for v in grid])
    if gaps[-1] >= 0:
        return float("nan")
    slower = np.flatnonzero(gaps >= 0)
    if not len(slower):
        return float(bracket[0])
    i = int(slower[-1])
    return float(optimize.brentq(gap, grid[i], grid[i + 1], xtol=1e-12, rtol=1e-10))


def erl_reaching_time(v0: float, K: float, phi: float, alpha: float, p: float) -> float:
    """Eq. (7): (φ|v0| + (1 − φ) ∫_0^|v0| exp(−α v^p) dv) / K (ERL, exact)."""
    from scipy import integrate

    integral, _ = integrate.quad(lambda v: math.exp(-alpha * v ** p), 0.0, abs(v0), epsabs=1e-13, epsrel=1e-12)
    return (phi * abs(v0) + (1 - phi) * integral) / K


def erl_bound(v0: float, K: float, phi: float, alpha: float, p: float) -> float:
    """Eq. (14): φ|v0|/K + (1 − φ)/(K α^(1/p)) (the paper's bound on eq. 7; Γ(1 + 1/p) ≤ 1 for p ≥ 1 only)."""
    return phi * abs(v0) / K + (1 - phi) / (K * alpha ** (1 / p))


def nsmerl_time_eq13(v0: float, K: float, phi: float, alpha: float, p: float, power: float, w: float) -> float:
    """Eq. (13) as printed (ω a constant; derived through the invalid split of eq. 8)."""
    return (phi * abs(v0) ** (1 - power) / (1 - power) + phi * abs(v0) / (w * (1 - power))
            + (1 - phi) * gamma_integral(v0, alpha, p, power)) / K


def nsmerl_time_eq21(v0: float, K: float, phi: float, power: float, w: float) -> float:
    """Eq. (21): (φ/K)(|v0|^(1−ϕ) + ω|v0|)/(1 − ϕ), the paper's 'desired' reaching time."""
    return phi / K * (abs(v0) ** (1 - power) + w * abs(v0)) / (1 - power)


def proposition_threshold(power: float) -> float:
    """Eq. (27): nSMERL is claimed faster than ERL for |v(0)| > (1 − ϕ)^(−1/ϕ)."""
    return (1.0 - power) ** (-1.0 / power)


def gamma_integral(v0: float, alpha: float, p: float, power: float) -> float:
    """Eq. (15) corrected: ∫_0^V exp(−α v^p) v^(−ϕ) dv = α^((ϕ−1)/p)/p · γ((1−ϕ)/p, α V^p) (lower incomplete Γ;
    the paper's 'φ function' is Euler's Γ)."""
    from scipy import special

    a = (1 - power) / p
    return alpha ** ((power - 1) / p) / p * special.gamma(a) * special.gammainc(a, alpha * abs(v0) ** p)
