"""The paper's IK solvers: all 8 branches of eqs. (14)–(30), Algorithm 1 (all valid sets, least joint
displacement, Sec. 2.4.1) and Algorithm 2 (the finite-state machine of Fig. 3, Sec. 2.4.2).

Two implementations of the same rules: a scalar one in plain `math` (per-call latency: no NumPy
overhead for 6 numbers) and a batched NumPy one for many poses per call. Tests hold them equal.

Branch order is the paper's "first-listed +": index = 4·i1 + 2·i5 + i3 with i = 0 for the "+" sign of
eqs. (20), (21), (28) and 1 for "−".
"""

from __future__ import annotations

from dataclasses import dataclass
from math import atan2, cos, fabs, pi, sin, sqrt
from typing import NamedTuple

import numpy as np

from pipeline.papers.ur5_ik_fsm.kinematics import UR5, Geometry

TWO_PI = 2.0 * pi


@dataclass(frozen=True)
class Conventions:
    """Rules the paper states only in words, or not at all (spec §3.3, §3.5); each is a config value."""

    snap_tol: float = 1e-9          # rad: angles this close to 0 / ±π are set to 0 / π (Sec. 2.4)
    pi_sign: float = 1.0            # ±π is written as +π (paper); −1 writes −π
    wrap: bool = True               # add/subtract 2π into [−π, π] (Sec. 2.4)
    s5_min: float = 1e-12           # θ5 invalid if |s5| ≤ this (Sec. 2.4)
    s3_min: float = 1e-12           # θ3 invalid if |s3| ≤ this, or complex
    shoulder_min: float = 1e-12     # m: θ2/θ4 invalid if |d5 s234 + a2 c2 + a3 c23| ≤ this (paper: 1e-9 mm)
    sqrt_negative: str = "abs"      # eq. (20) with B²+A²−d4² slightly < 0: "abs" √|·|, "clamp" 0, "reject"
    sqrt_negative_tol: float = 1e-12  # m² (the paper-implied 1e-6 mm²): how negative is "slightly"
    tie_tol: float = 1e-9           # rad: the first-listed option wins unless the other is closer by more
    signed_s3: bool = True          # eq. (29) with sin θ3 of the branch (erratum 11); False: printed +√

    def __post_init__(self) -> None:
        if self.sqrt_negative not in ("abs", "clamp", "reject"):
            raise ValueError(f"sqrt_negative must be abs, clamp or reject, not {self.sqrt_negative!r}")


PAPER = Conventions()


class Selection(NamedTuple):
    """One selected joint set with what it cost to find."""

    q: tuple[float, ...] | None     # None: no valid set
    branch: int                     # 0…7, −1 if none
    sets_evaluated: int             # complete sets (θ2, θ4 computed) the algorithm had to build
    valid_sets: int                 # valid sets it knew of (Algorithm 2 stops at the first)
    trace: str                      # visited states, e.g. "1-5-6-3-24"


def normalize(x: float, c: Conventions = PAPER) -> float:
    if c.wrap:
        x = (x + pi) % TWO_PI - pi
    if fabs(x) < c.snap_tol:
        return 0.0
    if fabs(fabs(x) - pi) < c.snap_tol:
        return c.pi_sign * pi
    return x


class _Pose:
    """The pose entries the IK reads, as floats, and the branch-independent eq. (20) terms."""

    __slots__ = ("px", "py", "pz", "r11", "r12", "r13", "r21", "r22", "r23", "r31", "theta1")

    def __init__(self, T, g: Geometry, c: Conventions):
        (r11, r12, r13, px), (r21, r22, r23, py), (r31, _, _, pz) = (row[:4] for row in T.tolist()[:3])
        self.r11, self.r12, self.r13, self.r21, self.r22, self.r23 = r11, r12, r13, r21, r22, r23
        self.r31, self.px, self.py, self.pz = r31, px, py, pz
        A = py - g.d6 * r23                                              # eq. (14)
        B = px - g.d6 * r13                                              # eq. (15)
        arg = B * B + A * A - g.d4 * g.d4
        if arg < 0.0:  # complex θ1 unless within round-off (erratum 4)
            if arg < -c.sqrt_negative_tol or c.sqrt_negative == "reject":
                self.theta1 = None
                return
            arg = -arg if c.sqrt_negative == "abs" else 0.0
        t, phi = atan2(sqrt(arg), g.d4), atan2(B, -A)
        self.theta1 = (normalize(t + phi, c), normalize(-t + phi, c))   # eq. (20)


def _theta5(p: _Pose, q1: float, c: Conventions):
    """Both θ5 (eq. 21) for a θ1, their validity, and the D, E of eqs. (17)–(18)."""
    c1, s1 = cos(q1), sin(q1)
    D = c1 * p.r22 - s1 * p.r12                                          # eq. (17)
    E = s1 * p.r11 - c1 * p.r21                                          # eq. (18)
    t = atan2(sqrt(E * E + D * D), s1 * p.r13 - c1 * p.r23)              # eq. (21)
    pair = (normalize(t, c), normalize(-t, c))
    return pair, fabs(sin(pair[0])) > c.s5_min, D, E


def _theta3(p: _Pose, q1: float, q5: float, D: float, E: float, g: Geometry, c: Conventions):
    """θ6 (eq. 22), θ234 (eq. 23), both θ3 (eq. 28) or None if complex/invalid, and K_S, K_C, c3."""
    c1, s1, s5 = cos(q1), sin(q1), sin(q5)
    q6 = normalize(atan2(D / s5, E / s5), c)                             # eq. (22)
    c6, s6 = cos(q6), sin(q6)
    C = c1 * p.r11 + s1 * p.r21                                          # eq. (16)
    F = cos(q5) * c6                                                     # eq. (19)
    q234 = atan2(p.r31 * F - s6 * C, F * C + s6 * p.r31)                 # eq. (23)
    c234, s234 = cos(q234), sin(q234)
    KC = c1 * p.px + s1 * p.py - s234 * g.d5 + c234 * s5 * g.d6          # eq. (24)
    KS = p.pz - g.d1 + c234 * g.d5 + s234 * s5 * g.d6                    # eq. (25)
    c3 = (KS * KS + KC * KC - g.a2 * g.a2 - g.a3 * g.a3) / (2.0 * g.a2 * g.a3)  # eq. (26)
    if fabs(c3) > 1.0:
        return q6, None, q234, KS, KC, c3
    t = atan2(sqrt(1.0 - c3 * c3), c3)                                   # eqs. (27)–(28)
    pair = (normalize(t, c), normalize(-t, c))
    return q6, (pair if fabs(sin(pair[0])) > c.s3_min else None), q234, KS, KC, c3


def _theta24(q3: float, q234: float, KS: float, KC: float, c3: float, g: Geometry, c: Conventions):
    """θ2 (eq. 29), θ4 (eq. 30), and whether the set is away from the shoulder singularity."""
    s3 = sin(q3) if c.signed_s3 else sqrt(max(0.0, 1.0 - c3 * c3))
    q2 = normalize(atan2(KS, KC) - atan2(s3 * g.a3, c3 * g.a3 + g.a2), c)  # eq. (29)
    q4 = normalize(q234 - q2 - q3, c)                                    # eq. (30)
    shoulder = g.d5 * sin(q2 + q3 + q4) + g.a2 * cos(q2) + g.a3 * cos(q2 + q3)
    return q2, q4, fabs(shoulder) > c.shoulder_min


def _second_is_closer(pair, previous: float, c: Conventions) -> int:
    """1 if the second option is closer to the previous angle by more than the tie tolerance."""
    return 1 if fabs(pair[1] - previous) < fabs(pair[0] - previous) - c.tie_tol else 0


def branches(T, g: Geometry = UR5, c: Conventions = PAPER) -> list[tuple[int, tuple[float, ...], bool]]:
    """All 8 branch sets in the paper's order: (branch, (θ1…θ6), valid). Invalid sets carry NaN where
    an angle could not be computed."""
    p = _Pose(T, g, c)
    nan6 = (float("nan"),) * 6
    if p.theta1 is None:
        return [(b, nan6, False) for b in range(8)]
    out = []
    for i1, q1 in enumerate(p.theta1):
        pair5, ok5, D, E = _theta5(p, q1, c)
        for i5, q5 in enumerate(pair5):
            if not ok5:
                out += [(4 * i1 + 2 * i5 + i3, (q1, nan6[1], nan6[2], nan6[3], q5, nan6[5]), False)
                        for i3 in (0, 1)]
                continue
            q6, pair3, q234, KS, KC, c3 = _theta3(p, q1, q5, D, E, g, c)
            for i3 in (0, 1):
                if pair3 is None:
                    out.append((4 * i1 + 2 * i5 + i3, (q1, nan6[1], nan6[2], nan6[3], q5, q6), False))
                    continue
                q3 = pair3[i3]
                q2, q4, ok = _theta24(q3, q234, KS, KC, c3, g, c)
                out.append((4 * i1 + 2 * i5 + i3, (q1, q2, q3, q4, q5, q6), ok))
    return out


def min_displacement(T, previous, g: Geometry = UR5, c: Conventions = PAPER) -> Selection:
    """Algorithm 1: every valid set (steps 1–5), then the least Euclidean joint displacement from the
    previous set, eqs. (47)–(48), without angle wrapping (step 6)."""
    prev = [float(x) for x in previous]
    best, best_diff, best_branch, evaluated, valid = None, float("inf"), -1, 0, 0
    p = _Pose(T, g, c)
    if p.theta1 is None:
        return Selection(None, -1, 0, 0, "1")
    for i1, q1 in enumerate(p.theta1):
        pair5, ok5, D, E = _theta5(p, q1, c)
        if not ok5:
            continue
        for i5, q5 in enumerate(pair5):
            q6, pair3, q234, KS, KC, c3 = _theta3(p, q1, q5, D, E, g, c)
            if pair3 is None:
                continue
            for i3, q3 in enumerate(pair3):
                q2, q4, ok = _theta24(q3, q234, KS, KC, c3, g, c)
                evaluated += 1
                if not ok:
                    continue
                valid += 1
                q = (q1, q2, q3, q4, q5, q6)
                diff = sqrt(sum((a - b) * (a - b) for a, b in zip(prev, q, strict=True)))  # eq. (48)
                if diff < best_diff - c.tie_tol:
                    best, best_diff, best_branch = q, diff, 4 * i1 + 2 * i5 + i3
    return Selection(best, best_branch, evaluated, valid, "all")


def fsm(T, previous, g: Geometry = UR5, c: Conventions = PAPER) -> Selection:
    """Algorithm 2, the FSM of Fig. 3: pick the option closer to the previous angle at each branching
    state (θ1 in S1, θ5 in S5, θ3 in S3), backtrack θ3 → θ5 → θ1 only on an invalid value."""
    prev1, _, prev3, _, prev5, _ = (float(x) for x in previous)
    trace = ["1"]
    p = _Pose(T, g, c)
    if p.theta1 is None:                       # S1: both θ1 complex
        return Selection(None, -1, 0, 0, "1")
    i1 = _second_is_closer(p.theta1, prev1, c)
    changed1 = changed5 = changed3 = False
    i5 = i3 = 0
    pair5 = pair3 = None
    evaluated = 0
    state = "5"
    while True:
        trace.append(state)
        if state == "5":
            pair5, ok5, D, E = _theta5(p, p.theta1[i1], c)
            if not ok5:
                if changed1:
                    return Selection(None, -1, evaluated, 0, "-".join(trace))
                i1, changed1 = 1 - i1, True
                continue
            i5, changed5 = _second_is_closer(pair5, prev5, c), False
            state = "6"
        elif state == "6":
            q6, pair3, q234, KS, KC, c3 = _theta3(p, p.theta1[i1], pair5[i5], D, E, g, c)
            state = "3"
        elif state == "3":
            if pair3 is None:
                if not changed5:
                    i5, changed5, state = 1 - i5, True, "6"
                elif not changed1:
                    i1, changed1, state = 1 - i1, True, "5"
                else:
                    return Selection(None, -1, evaluated, 0, "-".join(trace))
                continue
            i3, changed3 = _second_is_closer(pair3, prev3, c), False
            state = "24"
        else:  # "24"
            q2, q4, ok = _theta24(pair3[i3], q234, KS, KC, c3, g, c)
            evaluated += 1
            if ok:
                q = (p.theta1[i1], q2, pair3[i3], q4, pair5[i5], q6)
                return Selection(q, 4 * i1 + 2 * i5 + i3, evaluated, 1, "-".join(trace))
            if not changed3:
                i3, changed3 = 1 - i3, True
            elif not changed5:
                i5, changed5, state = 1 - i5, True, "6"
            elif not changed1:
                i1, changed1, state = 1 - i1, True, "5"
            else:
                return Selection(None, -1, evaluated, 0, "-".join(trace))


# ---------------------------------------------------------------------------------------------------
# Batched: the same rules on (N, 4, 4) poses at once.


def _normalize_np(x: np.ndarray, c: Conventions) -> np.ndarray:
    if c.wrap:
        x = np.mod(x + pi, TWO_PI)
        x -= pi
    ax = np.abs(x)
    x[ax < c.snap_tol] = 0.0
    ax -= pi
    x[np.abs(ax) < c.snap_tol] = c.pi_sign * pi
    return x


def branches_batch(T: np.ndarray, g: Geometry = UR5, c: Conventions = PAPER) -> tuple[np.ndarray, np.ndarray]:
    """All 8 branches for N poses, paper order: q (N, 8, 6) and valid (N, 8). q holds the angles as
    computed even for invalid sets (NaN only where an angle does not exist, e.g. complex θ1 or θ3).

    Arrays are laid out branch-first, pose-last, so every operation runs on contiguous rows of N."""
    T = np.asarray(T, dtype=float).reshape(-1, 4, 4)
    n = len(T)
    (r11, r12, r13, px), (r21, r22, r23, py), (r31, _, _, pz) = (np.ascontiguousarray(T[:, i, :].T)
                                                                 for i in range(3))
    A, B = py - g.d6 * r23, px - g.d6 * r13                              # eqs. (14)–(15)
    arg = B * B + A * A - g.d4 * g.d4
    slightly = (arg < 0) & (arg >= -c.sqrt_negative_tol) & (c.sqrt_negative != "reject")
    ok1 = (arg >= 0) | slightly
    arg = np.where(slightly, -arg if c.sqrt_negative == "abs" else 0.0, arg)
    t1 = np.arctan2(np.sqrt(np.where(ok1, arg, 0.0)), g.d4)
    phi = np.arctan2(B, -A)
    q1 = _normalize_np(np.stack([t1 + phi, phi - t1]), c)               # (2, N), eq. (20)
    c1, s1 = np.cos(q1), np.sin(q1)
    D = c1 * r22 - s1 * r12                                              # eq. (17)
    E = s1 * r11 - c1 * r21                                              # eq. (18)
    t5 = np.arctan2(np.sqrt(E * E + D * D), s1 * r13 - c1 * r23)
    q5 = _normalize_np(np.stack([t5, -t5], axis=1), c)                  # (2, 2, N), eq. (21)
    s5, c5 = np.sin(q5), np.cos(q5)
    ok5 = np.abs(s5[:, 0]) > c.s5_min                                    # (2, N)
    with np.errstate(divide="ignore", invalid="ignore"):
        q6 = _normalize_np(np.arctan2(D[:, None] / s5, E[:, None] / s5), c)  # eq. (22)
    c6, s6 = np.cos(q6), np.sin(q6)
    C = (c1 * r11 + s1 * r21)[:, None]                                   # eq. (16)
    F = c5 * c6                                                          # eq. (19)
    q234 = np.arctan2(r31 * F - s6 * C, F * C + s6 * r31)                # eq. (23)
    c234, s234 = np.cos(q234), np.sin(q234)
    KC = (c1 * px + s1 * py)[:, None] - s234 * g.d5 + c234 * s5 * g.d6  # eq. (24)
    KS = (pz - g.d1) + c234 * g.d5 + s234 * s5 * g.d6                    # eq. (25)
    c3 = (KS * KS + KC * KC - g.a2 * g.a2 - g.a3 * g.a3) / (2.0 * g.a2 * g.a3)  # eq. (26)
    real3 = np.abs(c3) <= 1.0
    t3 = np.arctan2(np.sqrt(np.where(real3, 1.0 - c3 * c3, 0.0)), c3)
    q3 = _normalize_np(np.stack([t3, -t3], axis=2), c)                  # (2, 2, 2, N), eq. (28)
    ok3 = real3 & (np.abs(np.sin(q3[:, :, 0])) > c.s3_min)
    if c.signed_s3:
        s3 = np.sin(q3)
    else:
        s3 = np.broadcast_to(np.sqrt(np.maximum(0.0, 1.0 - c3 * c3))[:, :, None], q3.shape)
    c3e = c3[:, :, None]
    q2 = _normalize_np(np.arctan2(KS, KC)[:, :, None] - np.arctan2(s3 * g.a3, c3e * g.a3 + g.a2), c)  # eq. (29)
    q23 = q2 + q3
    q4 = _normalize_np(q234[:, :, None] - q23, c)                       # eq. (30)
    ok24 = np.abs(g.d5 * np.sin(q23 + q4) + g.a2 * np.cos(q2) + g.a3 * np.cos(q23)) > c.shoulder_min
    q = np.empty((2, 2, 2, 6, n))
    q[..., 0, :] = q1[:, None, None]
    q[..., 1, :], q[..., 2, :], q[..., 3, :] = q2, q3, q4
    q[..., 4, :] = q5[:, :, None]
    q[..., 5, :] = q6[:, :, None]
    valid = ok1 & ok5[:, None, None] & ok3[:, :, None] & ok24
    return q.reshape(8, 6, n).transpose(2, 0, 1), valid.reshape(8, n).T


def _second_closer_np(a: np.ndarray, b: np.ndarray, prev: np.ndarray, c: Conventions) -> np.ndarray:
    return (np.abs(b - prev) < np.abs(a - prev) - c.tie_tol).astype(int)


def select_batch(q: np.ndarray, valid: np.ndarray, previous: np.ndarray, algorithm: str,
                 c: Conventions = PAPER) -> tuple[np.ndarray, np.ndarray]:
    """Pick one set per pose from `branches_batch`: (q (N, 6) with NaN rows where none, branch (N,),
    −1 where none).

    Algorithm 2's state machine visits sets depth-first — θ1 preferred/other, then θ5, then θ3, each
    ordered by closeness to the previous angle — and stops at the first valid one; this is that order.
    """
    n = len(q)
    prev = np.broadcast_to(np.asarray(previous, dtype=float), (n, 6))
    rows = np.arange(n)
    if algorithm == "alg1":
        diff = np.sqrt(np.sum((prev[:, None, :] - q) ** 2, axis=2))     # eq. (48)
        diff = np.where(valid, diff, np.inf)
        # first-listed wins ties within tie_tol, as in the scalar loop
        best = np.argmin(diff, axis=1)
        near = valid & (diff < diff[rows, best][:, None] + c.tie_tol)
        branch = np.argmax(near, axis=1)
    elif algorithm == "alg2":
        # Preferences use the options as computed, valid or not, like the states do; where an option
        # is NaN its whole subtree is invalid, so its rank does not matter.
        qb = q.reshape(n, 2, 2, 2, 6)
        i1 = _second_closer_np(qb[:, 0, 0, 0, 0], qb[:, 1, 0, 0, 0], prev[:, 0], c)
        order = np.empty((n, 8), dtype=int)
        k = 0
        for a in (0, 1):
            ia = np.where(a == 0, i1, 1 - i1)
            q5 = qb[rows, ia, :, 0, 4]                                   # (n, 2)
            i5 = _second_closer_np(q5[:, 0], q5[:, 1], prev[:, 4], c)
            for b in (0, 1):
                ib = np.where(b == 0, i5, 1 - i5)
                q3 = qb[rows, ia, ib, :, 2]
                i3 = _second_closer_np(q3[:, 0], q3[:, 1], prev[:, 2], c)
                for cc in (0, 1):
                    order[:, k] = 4 * ia + 2 * ib + np.where(cc == 0, i3, 1 - i3)
                    k += 1
        ok = valid[rows[:, None], order]
        branch = order[rows, np.argmax(ok, axis=1)]
    else:
        raise ValueError(f"algorithm must be alg1 or alg2, not {algorithm!r}")
    found = valid[rows, branch]
    out = np.where(found[:, None], q[rows, branch], np.nan)
    return out, np.where(found, branch, -1)


BLOCK = 2048  # poses per block: keeps every temporary small enough to be reused, not re-mapped, per call


def solve_batch(T: np.ndarray, previous: np.ndarray, algorithm: str, g: Geometry = UR5,
                c: Conventions = PAPER) -> tuple[np.ndarray, np.ndarray]:
    """Algorithm 1 or 2 on N poses: (q (N, 6), NaN rows where none; branch (N,), −1 where none)."""
    T = np.asarray(T, dtype=float).reshape(-1, 4, 4)
    prev = np.broadcast_to(np.asarray(previous, dtype=float), (len(T), 6))
    q, branch = np.empty((len(T), 6)), np.empty(len(T), dtype=int)
    for s in range(0, len(T), BLOCK):
        qb, valid = branches_batch(T[s:s + BLOCK], g, c)
        q[s:s + BLOCK], branch[s:s + BLOCK] = select_batch(qb, valid, prev[s:s + BLOCK], algorithm, c)
    return q, branch
