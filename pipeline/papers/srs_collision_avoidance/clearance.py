"""How far the obstacles stay from the arm, measured two ways: the paper's safety volume (how deep an obstacle
point is inside the cones and the elbow sphere) and the bodies themselves (human capsules against the arm's
link capsules, which MuJoCo's distance query audits)."""

from __future__ import annotations

import numpy as np

from pipeline.papers.srs_collision_avoidance.avoidance import SafetyVolume
from pipeline.papers.srs_collision_avoidance.humans import closest_on_segments


def volume_margins(volume: SafetyVolume, obstacle_points: np.ndarray, chain_points: np.ndarray) -> np.ndarray:
    """(N, k) margin (m) of k obstacle points (N, k, 3) outside the safety volume of the chain P_s, P_e, P_w
    (N, 3, 3): negative inside."""
    P_s, P_e, P_w = (chain_points[:, None, i] for i in range(3))
    return volume.margin(obstacle_points, P_s, P_e, P_w)


def link_segments(chain_points: np.ndarray, tool_origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(start, end) (N, 4, 3) of the arm's links as segments: O_b P_s, P_s P_e, P_e P_w, P_w O_e."""
    P_s, P_e, P_w = (chain_points[:, i] for i in range(3))
    start = np.stack([np.zeros_like(P_s), P_s, P_e, P_w], axis=1)
    end = np.stack([P_s, P_e, P_w, tool_origin], axis=1)
    return start, end


def capsule_clearance(link_start: np.ndarray, link_end: np.ndarray, link_radius: float, start: np.ndarray,
                      end: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """(N, m, 4) distance (m) between the m human capsules (start, end (N, m, 3), radius (m,)) and the 4 link
    capsules of the arm: negative where they overlap."""
    on_human, on_link = closest_on_segments(start[:, :, None], end[:, :, None], link_start[:, None],
                                            link_end[:, None])
    return np.linalg.norm(on_human - on_link, axis=-1) - radius[None, :, None] - link_radius
