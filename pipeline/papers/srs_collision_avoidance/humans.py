"""The two moving human arms of Sec. 5 (Table 1) as obstacles: shoulder, elbow and hand points, and the two
links between them as capsules. The paper gives Table 1's parameters but no formulas; the motion below is
the reading stated in paper.yaml (every choice is a config key)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.srs_collision_avoidance.kinematics import dot, norm

POINTS = ("shoulder", "elbow", "hand")


@dataclass(frozen=True)
class HumanArms:
    """Table 1, one entry per arm (k arms), SI units."""

    base: np.ndarray            # (k, 3) m, centre of the shoulder's circle
    base_radius: np.ndarray     # (k,) m, "base rotation radius (around y-axis)"
    base_turns: np.ndarray      # (k,) turns of the shoulder over the run
    shoulder_range: np.ndarray  # (k,) rad
    shoulder_offset: np.ndarray
    shoulder_turns: np.ndarray
    elbow_range: np.ndarray
    elbow_offset: np.ndarray
    elbow_turns: np.ndarray
    upper_length: float         # m, shoulder-elbow (319.6 mm)
    fore_length: float          # m, elbow-hand (246.5 mm)
    radius: np.ndarray          # (2,) m, capsule radii of the upper arm and the forearm (not in the paper)
    plane: str = "xy"           # plane of the arm's angles: xy (vertical, parallel to x_b y_b) or xz
    range_is: str = "amplitude"  # "angle range": amplitude of the sine, or peak_to_peak

    def __post_init__(self) -> None:
        k = len(self.base)
        for name in ("base_radius", "base_turns", "shoulder_range", "shoulder_offset", "shoulder_turns",
                     "elbow_range", "elbow_offset", "elbow_turns"):
            if len(getattr(self, name)) != k:
                raise ValueError(f"humans.{name} needs one value per arm ({k}), got {len(getattr(self, name))}")

    def points(self, n: np.ndarray, samples: int) -> np.ndarray:
        """(N, k, 3, 3) shoulder, elbow and hand of each arm at samples n of a run of `samples` samples;
        "number of turns" is the number of cycles over the run."""
        phase = 2 * np.pi * np.asarray(n, dtype=float)[:, None] / samples            # (N, 1)
        amplitude = 0.5 if self.range_is == "peak_to_peak" else 1.0
        circle = phase * self.base_turns
        shoulder = self.base + self.base_radius[:, None] * np.stack(
            [np.cos(circle), np.zeros_like(circle), np.sin(circle)], axis=-1)         # a circle about y
        theta_s = self.shoulder_offset + amplitude * self.shoulder_range * np.sin(phase * self.shoulder_turns)
        theta_e = self.elbow_offset + amplitude * self.elbow_range * np.sin(phase * self.elbow_turns)
        elbow = shoulder + self.upper_length * self._direction(theta_s)
        hand = elbow + self.fore_length * self._direction(theta_s + theta_e)
        return np.stack([shoulder, elbow, hand], axis=-2)

    def _direction(self, angle: np.ndarray) -> np.ndarray:
        """Unit vector at `angle` from x_b, turning downwards (−y_b) in the xy plane, or towards −z_b in xz."""
        c, s, z = np.cos(angle), np.sin(angle), np.zeros_like(angle)
        return np.stack([c, -s, z] if self.plane == "xy" else [c, z, -s], axis=-1)

    def capsules(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(start, end, radius) of the 2k links: (N, 2k, 3), (N, 2k, 3), (2k,), ordered arm by arm."""
        start = points[..., :2, :].reshape(*points.shape[:-3], -1, 3)
        end = points[..., 1:, :].reshape(*points.shape[:-3], -1, 3)
        return start, end, np.tile(self.radius, len(self.base))


def segment_parameter(X: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """t of the projection of X on the line A + t(B − A) (eqs. 15-16 in signed form)."""
    d = B - A
    return dot(X - A, d) / dot(d, d)


def closest_on_segments(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Closest points (P on AB, Q on CD) of two segments, batched; parallel segments take the end that is
    nearest (any closest pair has the same distance)."""
    d1, d2, r = B - A, D - C, A - C
    a, e, f = dot(d1, d1), dot(d2, d2), dot(d2, r)
    b, c = dot(d1, d2), dot(d1, r)
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 1e-12 * a * e, np.clip((b * f - c * e) / denom, 0.0, 1.0), 0.0)
        t = (b * s + f) / e
        s = np.where(t < 0.0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / a, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    return A + s[..., None] * d1, C + t[..., None] * d2


def nearest_obstacle_point(links: tuple[np.ndarray, ...], start: np.ndarray, end: np.ndarray, radius: np.ndarray,
                           kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P_c: the obstacle point nearest to the robot's referential links (P_s P_e, P_e P_w).

    `links` = (P_s, P_e, P_w), each (N, 3); the obstacle is the capsules (start, end, radius) of the human
    links. kind `capsules`: the point of the capsule surfaces nearest to the links; kind `points`: the
    nearest of the shoulders, elbows and hands. Returns (P_c (N, 3), its distance to the links (N,), index of
    the capsule it belongs to (N,))."""
    P_s, P_e, P_w = (x[:, None, :] for x in links)
    if kind == "points":
        # each capsule contributes its start point; the last link of every arm also its end (the hand)
        hands = end[:, 1::2]
        candidates = np.concatenate([start, hands], axis=1)
        owner = np.r_[np.arange(start.shape[1]), np.arange(1, start.shape[1], 2)]
        distance = np.minimum(_point_segment_distance(candidates, P_s, P_e),
                              _point_segment_distance(candidates, P_e, P_w))
        best = np.argmin(distance, axis=1)
        rows = np.arange(len(best))
        return candidates[rows, best], distance[rows, best], owner[best]
    surface, distance = [], []
    for A, B in ((P_s, P_e), (P_e, P_w)):
        on_robot, on_human = closest_on_segments(A, B, start, end)
        gap = on_robot - on_human
        length = norm(gap)
        with np.errstate(divide="ignore", invalid="ignore"):
            direction = np.where(length[..., None] > 0, gap / length[..., None], 0.0)
        surface.append(on_human + radius[:, None] * direction)
        distance.append(length - radius)
    surface, distance = np.concatenate(surface, axis=1), np.concatenate(distance, axis=1)
    best = np.argmin(distance, axis=1)
    rows = np.arange(len(best))
    return surface[rows, best], distance[rows, best], best % start.shape[1]


def _point_segment_distance(X: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    t = np.clip(segment_parameter(X, A, B), 0.0, 1.0)
    return norm(X - (A + t[..., None] * (B - A)))
