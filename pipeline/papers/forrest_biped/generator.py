"""Capture-point walking pattern generators (Sec. 5): the paper's extended generator and the traditional one.

Both drive the LIP ẍ = ω²(x − p) (eq. 39) with a piecewise-linear (e)ZMP p(t), per axis (x, y, and z for the
CoM height, where p_z is the virtual point of eq. 37). On a segment that starts at state (x_a, ẋ_a) with
p(τ) = p_a + k τ (τ local to the segment) the CoM and the CP are closed form (eqs. 45, 46):

    x(τ) = (x_a − p_a) cosh ωτ + (ẋ_a − k)/ω sinh ωτ + k τ + p_a
    ξ(τ) = ξ_a e^{ωτ} + (p_a + k/ω)(1 − e^{ωτ}) + k τ

- **Extended** (Sec. 5, Fig. 14): each step is ramp-hold-ramp, P0 → P1 in T1, P1 for T2, P1 → P2 in T3 (eqs.
  43-44), with P0 and P2 the CP at the step's start and end, and P1 from eq. (48) so that ξ(T) = P2.
- **Traditional** (the constant-ZMP CP generator the paper compares with, ref. [34]): one constant ZMP per step,
  at the support foot, switched instantly; the end-of-step CPs by the backward recursion
  ξ_ini,i = p_i + e^{−ωT}(ξ_eos,i − p_i), ξ_eos,i−1 = ξ_ini,i, from the final stance point.

The walk (Sec. 6.3 and paper.yaml): 1 s shifting the CP from between the feet onto the left foot while the CoM
lowers from z_init to z_c, `steps` steps of `step_time` (left support first, each foot landing `step_length`
ahead of the last), and 1 s shifting the CP to between the feet. The swing foot flies for T1 + T2 of its step.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

DOUBLE, LEFT, RIGHT = 0, 1, 2     # support state: both feet, left foot only, right foot only


def p1_corrected(xi0, P0, P2, omega: float, T1: float, T2: float, T3: float):
    """Eq. (48) as derived from eq. (47) (the printed form is mis-typeset): the constant ZMP P1 that brings the CP
    from ξ0 at the step start to P2 at its end, per axis."""
    S = T1 + T2 + T3
    e_S, e_23, e_3 = np.exp(omega * S), np.exp(omega * (T2 + T3)), np.exp(omega * T3)
    numerator = (xi0 * omega * T1 * T3 * e_S + P0 * T3 * (e_S - e_23 - omega * T1 * e_S)
                 + P2 * T1 * (1 - e_3))
    return -numerator / (T1 * e_3 + T3 * e_23 - T3 * e_S - T1)


def p1_printed(xi0, P0, P2, omega: float, T1: float, T2: float, T3: float):
    """Eq. (48) exactly as typeset: −(A + B) / (C / D) with the P2 term D printed in the denominator's denominator.
    Dimensionally wrong (m² / s over s); kept so the misprint can be run (`system.walk.eq48=printed`)."""
    S = T1 + T2 + T3
    e_S, e_23, e_3 = np.exp(omega * S), np.exp(omega * (T2 + T3)), np.exp(omega * T3)
    A = xi0 * omega * T1 * T3 * e_S
    B = P0 * T3 * (e_S - e_23 - omega * T1 * e_S)
    C = T1 * e_3 + T3 * e_23 - T3 * e_S - T1
    D = P2 * T1 * (1 - e_3)
    with np.errstate(divide="ignore", invalid="ignore"):
        return -(A + B) / (C / D)


def cp_at_end(xi0, P0, P1, P2, omega: float, T1: float, T2: float, T3: float):
    """Eq. (47): the CP at the end of a ramp-hold-ramp step (three applications of eq. 46)."""
    S = T1 + T2 + T3
    e_S, e_23, e_3 = np.exp(omega * S), np.exp(omega * (T2 + T3)), np.exp(omega * T3)
    return (xi0 * e_S + P0 / (omega * T1) * (e_S - e_23 - omega * T1 * e_S)
            + P1 / (omega * T1 * T3) * (T1 * e_3 + T3 * e_23 - T3 * e_S - T1)
            + P2 / (omega * T3) * (1 - e_3 + omega * T3))


@dataclass(frozen=True)
class Segments:
    """A piecewise-linear ZMP: on [t[i], t[i+1]) p = p0[i] + slope[i]·(t − t[i]) (jumps allowed between)."""

    t: np.ndarray        # (s + 1,) segment boundaries, s
    p0: np.ndarray       # (s, 3) ZMP at each segment start, m
    slope: np.ndarray    # (s, 3) m/s

    def zmp(self, times: np.ndarray) -> np.ndarray:
        i = np.clip(np.searchsorted(self.t, times, side="right") - 1, 0, len(self.p0) - 1)
        return self.p0[i] + self.slope[i] * (times - self.t[i])[:, None]


def lip_response(seg: Segments, x0: np.ndarray, v0: np.ndarray, omega: float,
                 times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """CoM position, velocity, acceleration and CP (eqs. 45-46) at `times` for the ZMP `seg`, from the CoM state
    (x0, v0) at seg.t[0]; each segment starts from the closed-form state at the end of the one before."""
    n = len(times)
    x, v, xi = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    xa, va = np.asarray(x0, dtype=float), np.asarray(v0, dtype=float)
    xi_a = xa + va / omega
    idx = np.clip(np.searchsorted(seg.t, times, side="right") - 1, 0, len(seg.p0) - 1)
    for s in range(len(seg.p0)):
        pa, k = seg.p0[s], seg.slope[s]
        tau = times[idx == s] - seg.t[s]
        ch, sh, ex = np.cosh(omega * tau)[:, None], np.sinh(omega * tau)[:, None], np.exp(omega * tau)[:, None]
        x[idx == s] = (xa - pa) * ch + (va - k) / omega * sh + k * tau[:, None] + pa            # eq. (45)
        v[idx == s] = omega * (xa - pa) * sh + (va - k) * ch + k
        xi[idx == s] = xi_a * ex + (pa + k / omega) * (1 - ex) + k * tau[:, None]               # eq. (46)
        T = seg.t[s + 1] - seg.t[s]
        ch, sh = np.cosh(omega * T), np.sinh(omega * T)
        xa, va = (xa - pa) * ch + (va - k) / omega * sh + k * T + pa, omega * (xa - pa) * sh + (va - k) * ch + k
        xi_a = xa + va / omega
    return x, v, omega ** 2 * (x - seg.zmp(times)), xi


@dataclass(frozen=True)
class Steps:
    """The walk as steps: each step moves the CP from P0 to P2 in `T` s (P0, P2 with the CoM height as z)."""

    t0: np.ndarray        # (s,) step start times, s
    T: float
    P0: np.ndarray        # (s, 3)
    P2: np.ndarray        # (s, 3)
    support: np.ndarray   # (s,) LEFT/RIGHT for a stepping step, DOUBLE for the first and last
    swing_from: np.ndarray   # (s, 3) sole position where the swing foot lifts off (NaN if none)
    swing_to: np.ndarray     # (s, 3)
    feet0: np.ndarray     # (2, 3) initial soles: left, right


def walk_steps(walk: Mapping[str, Any]) -> Steps:
    """The footstep plan: CP between the feet → left foot → `steps` alternating steps → between the feet."""
    T, n, L, w = walk["step_time"], int(walk["steps"]), walk["step_length"], walk["foot_spacing"]
    feet = np.array([[0.0, w / 2, 0.0], [0.0, -w / 2, 0.0]])
    mid = feet.mean(axis=0)
    z0, zc = walk["z_init"], walk["z_c"]
    P0, P2, support, lift, land = [np.r_[mid[:2], z0]], [np.r_[feet[0, :2], zc]], [DOUBLE], [None], [None]
    for k in range(1, n + 1):
        stance, swing = (0, 1) if k % 2 else (1, 0)            # left supports first (Sec. 6.3)
        lift.append(feet[swing].copy())
        feet[swing] = [k * L, feet[swing, 1], 0.0]
        land.append(feet[swing].copy())
        P0.append(np.r_[feet[stance, :2], zc])
        P2.append(np.r_[feet[swing, :2], zc])
        support.append(LEFT if stance == 0 else RIGHT)
    P0.append(P2[-1])
    P2.append(np.r_[feet.mean(axis=0)[:2], zc])
    support.append(DOUBLE)
    lift.append(None)
    land.append(None)
    nan3 = np.full(3, np.nan)
    return Steps(t0=np.arange(n + 2) * T, T=T, P0=np.array(P0), P2=np.array(P2), support=np.array(support),
                 swing_from=np.array([nan3 if a is None else a for a in lift]),
                 swing_to=np.array([nan3 if a is None else a for a in land]),
                 feet0=np.array([[0.0, w / 2, 0.0], [0.0, -w / 2, 0.0]]))


def extended_zmp(steps: Steps, omega: float, T1: float, T3: float, eq48: str = "corrected") -> Segments:
    """Eqs. (43)-(44) with P1 of eq. (48): three segments per step."""
    T2 = steps.T - T1 - T3
    p1_of = p1_corrected if eq48 == "corrected" else p1_printed
    t, p0, slope = [], [], []
    for i in range(len(steps.t0)):
        P0, P2 = steps.P0[i], steps.P2[i]
        P1 = p1_of(P0, P0, P2, omega, T1, T2, T3)        # ξ0 = P0: the CP starts each step on the ZMP
        t0 = steps.t0[i]
        t += [t0, t0 + T1, t0 + T1 + T2]
        p0 += [P0, P1, P1]
        slope += [(P1 - P0) / T1, np.zeros(3), (P2 - P1) / T3]
    return Segments(np.array([*t, steps.t0[-1] + steps.T]), np.array(p0), np.array(slope))


def traditional_zmp(steps: Steps, omega: float, x0: np.ndarray) -> Segments:
    """One constant ZMP per step at the support point; the first step's ZMP is solved so the CP leaves the CoM
    at rest at x0 and meets the recursion (the initial double support has no foot to put it on)."""
    n = len(steps.t0)
    decay = np.exp(-omega * steps.T)
    p = np.array(steps.P0, dtype=float)
    xi_eos = np.empty((n, 3))
    xi_eos[-1] = p[-1] = steps.P2[-1]                    # the final stance point, at rest
    for i in range(n - 1, 0, -1):
        xi_eos[i - 1] = p[i] + decay * (xi_eos[i] - p[i])
    p[0] = (xi_eos[0] - x0 / decay) / (1 - 1 / decay)     # ξ(T) = p + e^{ωT}(x0 − p) = ξ_eos,0
    return Segments(np.r_[steps.t0, steps.t0[-1] + steps.T], p, np.zeros_like(p))


@dataclass(frozen=True)
class Pattern:
    """Every reference the controller tracks, sampled on its cycle (index i = time i·dt)."""

    name: str
    omega: float
    t: np.ndarray          # (n,)
    com: np.ndarray        # (n, 3) x_c^d
    com_vel: np.ndarray
    com_acc: np.ndarray
    cp: np.ndarray         # (n, 3) ξ_d
    zmp: np.ndarray        # (n, 3) p^d (z: the virtual eZMP height)
    feet: np.ndarray       # (2, n, 3) sole centres: left, right
    feet_vel: np.ndarray
    feet_acc: np.ndarray
    support: np.ndarray    # (n,) DOUBLE/LEFT/RIGHT
    segments: Segments
    steps: Steps


def swing(start: np.ndarray, end: np.ndarray, height: float, duration: float,
          tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Swing-foot position, velocity, acceleration at local times `tau`: a quintic in x, y (zero velocity and
    acceleration at both ends) and a (1 − cos) bump of `height` in z."""
    s = np.clip(tau / duration, 0.0, 1.0)[:, None]
    blend = 10 * s**3 - 15 * s**4 + 6 * s**5
    dblend = (30 * s**2 - 60 * s**3 + 30 * s**4) / duration
    ddblend = (60 * s - 180 * s**2 + 120 * s**3) / duration**2
    w = 2 * np.pi / duration
    bump = np.zeros((len(tau), 3))
    bump[:, 2] = height / 2
    z = bump * (1 - np.cos(w * tau[:, None]))
    zd = bump * w * np.sin(w * tau[:, None])
    zdd = bump * w * w * np.cos(w * tau[:, None])
    d = end - start
    return start + d * blend + z, d * dblend + zd, d * ddblend + zdd


def pattern(walk: Mapping[str, Any], kind: str, omega: float, dt: float, x0: np.ndarray | None = None) -> Pattern:
    """The references of the walk for the `extended` or `traditional` generator on the controller's grid."""
    steps = walk_steps(walk)
    duration = float(walk["duration"])
    t = np.arange(round(duration / dt) + 1) * dt
    start = steps.P0[0] if x0 is None else np.asarray(x0, dtype=float)
    if kind == "extended":
        seg = extended_zmp(steps, omega, walk["T1"], walk["T3"], walk.get("eq48", "corrected"))
    elif kind == "traditional":
        seg = traditional_zmp(steps, omega, start)
    else:
        raise ValueError(f"unknown generator {kind!r}: extended or traditional")
    if steps.t0[-1] + steps.T < duration - 1e-12:        # hold the last ZMP after the plan
        seg = Segments(np.r_[seg.t, duration], np.vstack([seg.p0, seg.zmp(seg.t[-1:])]),
                       np.vstack([seg.slope, np.zeros(3)]))
    com, vel, acc, cp = lip_response(seg, start, np.zeros(3), omega, t)
    feet = np.repeat(steps.feet0[:, None, :], len(t), axis=1)
    feet_vel, feet_acc = np.zeros_like(feet), np.zeros_like(feet)
    support = np.full(len(t), DOUBLE)
    flight = walk["step_time"] - walk["T3"]                 # lift-off at the step start, touch-down before T3
    for i in np.flatnonzero(steps.support != DOUBLE):
        foot = 1 if steps.support[i] == LEFT else 0
        t0 = steps.t0[i]
        during = (t >= t0 - 1e-12) & (t < t0 + flight - 1e-12)
        after = t >= t0 + flight - 1e-12
        p, v, a = swing(steps.swing_from[i], steps.swing_to[i], walk["swing_height"], flight, t[during] - t0)
        feet[foot, during], feet_vel[foot, during], feet_acc[foot, during] = p, v, a
        feet[foot, after] = steps.swing_to[i]
        support[during] = steps.support[i]
    return Pattern(name=kind, omega=omega, t=t, com=com, com_vel=vel, com_acc=acc, cp=cp, zmp=seg.zmp(t),
                   feet=feet, feet_vel=feet_vel, feet_acc=feet_acc, support=support, segments=seg, steps=steps)
