"""The safety volume of Sec. 4.2 and the collision-avoidance angle of Sec. 4.3: which point of the chain is
under imminent collision (Algorithm 1, lines 10-40) and the swivel angle α_c that moves it away (eqs. 18-19).

Batched over samples. The printed listing differs from the text in three places that change results; each is
a choice of `Forms` (the defaults are the text's / the corrected forms):

- `link_checks`: `both` checks both links (the text: "all three distances"); `elseif` is line 19, which skips
  link P_e P_w whenever P_c projects inside P_s P_e (and then compares with a d_a that was never computed:
  read here as +∞).
- `d_m2`: `eq17` is (1 − u2) d_cmax + u2 d_cmin (the cone is widest at P_e); `printed` is line 21's
  (1 − u2) d_cmin + u2 d_cmax.
- `sphere_distance`: `allowed` keeps the allowed distance d_cmax for the elbow sphere, like the link cases,
  and selects by actual distance; `printed` (lines 33, 37) stores the actual distance d_b in d_mc, so eq. (19)
  then aims at the distance P_c already has.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.srs_collision_avoidance.humans import segment_parameter
from pipeline.papers.srs_collision_avoidance.kinematics import cross, dot, norm, unit

NONE, UPPER_ARM, ELBOW, FOREARM = 0, 1, 2, 3
CASES = ("none", "upper_arm", "elbow", "forearm")


@dataclass(frozen=True)
class SafetyVolume:
    """Truncated cones on P_s P_e and P_e P_w (radius d_cmin at P_s and P_w, d_cmax at P_e) and a sphere of
    radius d_cmax at P_e (m)."""

    d_cmin: float
    d_cmax: float

    def upper_radius(self, u1: np.ndarray) -> np.ndarray:
        return (1 - u1) * self.d_cmin + u1 * self.d_cmax                       # eq. (17), d_m1

    def fore_radius(self, u2: np.ndarray, printed: bool = False) -> np.ndarray:
        if printed:
            return (1 - u2) * self.d_cmin + u2 * self.d_cmax                   # Algorithm 1, line 21 (misprint)
        return (1 - u2) * self.d_cmax + u2 * self.d_cmin                       # eq. (17), d_m2

    def margin(self, X: np.ndarray, P_s: np.ndarray, P_e: np.ndarray, P_w: np.ndarray,
               clearance: float | np.ndarray = 0.0) -> np.ndarray:
        """Signed distance (m) of points X (..., 3) outside the safety volume by the paper's rule (distance to
        a link minus the allowed distance of eq. 17 where the projection falls inside it; distance to P_e
        minus d_cmax), less `clearance` (a capsule radius): negative inside."""
        m = norm(X - P_e) - self.d_cmax
        for A, B, allowed in ((P_s, P_e, self.upper_radius), (P_w, P_e, self.upper_radius)):
            t = segment_parameter(X, A, B)         # the forearm measured from P_w: the same cone, mirrored
            d = norm(X - (A + t[..., None] * (B - A))) - allowed(t)
            m = np.minimum(m, np.where((t >= 0) & (t <= 1), d, np.inf))
        return m - clearance


@dataclass(frozen=True)
class Forms:
    """How Algorithm 1 and eq. (19) are read (see the module docstring)."""

    link_checks: str = "both"          # both | elseif
    d_m2: str = "eq17"                 # eq17 | printed
    sphere_distance: str = "allowed"   # allowed | printed
    alpha_c: str = "paper"             # paper (eq. 19) | exact (rotates P_col to exactly d_m from P_c)


@dataclass(frozen=True)
class Selection:
    """Lines 10-40 of Algorithm 1, per sample."""

    case: np.ndarray        # (N,) NONE | UPPER_ARM | ELBOW | FOREARM: where the collision is imminent
    P_col: np.ndarray       # (N, 3) the point of the chain under imminent collision (NaN if none)
    d_mc: np.ndarray        # (N,) the distance eq. (19) aims at: the allowed distance (0 if none)
    actual: np.ndarray      # (N,) the distance P_c has from P_col (NaN if none)

    @property
    def find(self) -> np.ndarray:
        return self.case != NONE


def select(P_c: np.ndarray, P_s: np.ndarray, P_e: np.ndarray, P_w: np.ndarray, volume: SafetyVolume,
           forms: Forms = Forms()) -> Selection:
    """Algorithm 1, lines 10-40, on the α = 0 points (lines 3-4)."""
    n = len(P_c)
    u1 = segment_parameter(P_c, P_s, P_e)                                       # eq. (16) as a signed parameter
    u2 = segment_parameter(P_c, P_e, P_w)
    P_c1 = P_s + u1[:, None] * (P_e - P_s)                                      # eq. (15)
    P_c2 = P_e + u2[:, None] * (P_w - P_e)
    in1, in2 = (u1 >= 0) & (u1 <= 1), (u2 >= 0) & (u2 <= 1)
    d_a = np.where(in1, norm(P_c - P_c1), np.inf)
    d_c = np.where(in2, norm(P_c - P_c2), np.inf)
    d_b = norm(P_c - P_e)
    d_m1 = volume.upper_radius(u1)
    d_m2 = volume.fore_radius(u2, printed=forms.d_m2 == "printed")

    case = np.full(n, NONE)
    P_col = np.full((n, 3), np.nan)
    d_mc, actual = np.zeros(n), np.full(n, np.nan)

    def take(mask, which, point, allowed, distance):
        case[mask] = which
        P_col[mask] = point[mask]
        d_mc[mask] = allowed[mask] if np.ndim(allowed) else allowed
        actual[mask] = distance[mask]

    take(in1 & (d_a < d_m1), UPPER_ARM, P_c1, d_m1, d_a)                        # lines 11-18
    check2 = in2 if forms.link_checks == "both" else in2 & ~in1                  # line 19: elseif
    # line 23 compares with d_a: the actual distance of the case already found (+∞ if none)
    take(check2 & (d_c < d_m2) & (d_c < np.where(case == NONE, np.inf, actual)), FOREARM, P_c2, d_m2, d_c)
    inside = d_b < volume.d_cmax                                                # lines 30-40
    if forms.sphere_distance == "printed":
        # lines 32-38: d_mc <- d_b, compared with d_mc (an allowed distance in the link cases)
        elbow = inside & ((case == NONE) | (d_b < d_mc))
        take(elbow, ELBOW, np.broadcast_to(P_e, P_c.shape), d_b, d_b)
    else:
        take(inside & ((case == NONE) | (d_b < actual)), ELBOW, np.broadcast_to(P_e, P_c.shape), volume.d_cmax, d_b)
    return Selection(case, P_col, d_mc, actual)


def avoidance_angle(P_c: np.ndarray, sel: Selection, P_s: np.ndarray, P_e: np.ndarray, P_w: np.ndarray,
                    form: str = "paper") -> tuple[np.ndarray, np.ndarray]:
    """α_c(n) (rad) of the samples with a selection (0 elsewhere) and g of eq. (19) (NaN where none).

    `paper`: eq. (19), α_c = γ − β with γ from the triangle (k1, k2, d_mc) at P_cu and β between P_col and
    P_c seen from P_eu (P_co of the text read as P_col; cos γ and v1·v2 clipped to [−1, 1]).
    `exact`: the rotation about P_s P_w that puts the same point P_col exactly d_mc from P_c (0 if it is
    already as far)."""
    axis = P_w - P_s
    u = unit(axis)
    find = sel.find
    X = np.where(find[:, None], sel.P_col, P_e)          # any finite point where nothing was found
    P_cu = P_s + dot(P_c - P_s, u)[:, None] * u                                 # eq. (18)
    g = dot(cross(P_c - P_cu, X - P_cu), axis)
    sign = np.sign(g)
    d_m = sel.d_mc
    if form == "exact":
        X_u = P_s + dot(X - P_s, u)[:, None] * u
        r_x, r_c = norm(X - X_u), norm(P_c - P_cu)
        h = dot(X - P_c, u)
        with np.errstate(divide="ignore", invalid="ignore"):
            gamma0 = np.arccos(np.clip((h * h + r_x * r_x + r_c * r_c - d_m * d_m) / (2 * r_x * r_c), -1.0, 1.0))
            cos_beta = dot(unit(X - X_u), unit(P_c - P_cu))
        beta0 = np.arccos(np.clip(cos_beta, -1.0, 1.0))
        alpha = sign * np.maximum(gamma0 - beta0, 0.0)
    else:
        P_eu = P_s + dot(P_e - P_s, u)[:, None] * u
        k1, k2 = norm(X - P_cu), norm(P_c - P_cu)
        with np.errstate(divide="ignore", invalid="ignore"):
            c_gamma = np.clip((k1 * k1 + k2 * k2 - d_m * d_m) / (2 * k1 * k2), -1.0, 1.0)
            v12 = np.clip(dot(unit(X - P_eu), unit(P_c - P_eu)), -1.0, 1.0)
        gamma = np.arctan2(sign * np.sqrt(1 - c_gamma * c_gamma), c_gamma)      # eq. (19)
        beta = np.arctan2(sign * np.sqrt(1 - v12 * v12), v12)
        alpha = gamma - beta
    alpha = np.where(find & np.isfinite(alpha), alpha, 0.0)
    return alpha, np.where(find, g, np.nan)
