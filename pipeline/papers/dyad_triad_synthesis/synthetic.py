"""Synthetic ground truth: linkages built at random, whose precision positions are sampled from them, so a
synthesis must give the linkage back (spec §8)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.dyad_triad_synthesis.fourbar import FourBar
from pipeline.papers.dyad_triad_synthesis.standard_form import turns

MIN_TRANSMISSION = np.radians(20.0)   # keep sampled poses away from dead centres
MIN_ROTATION_STEP = 0.05              # rad: distinct coupler rotations between poses


@dataclass(frozen=True)
class FourBarSample:
    fourbar: FourBar
    points: np.ndarray       # (n,) complex precision points [m]
    alpha: np.ndarray        # (n,) coupler rotations [rad]
    beta_a: np.ndarray       # (n,) crank rotations
    beta_b: np.ndarray       # (n,) rocker rotations

    def dyads(self) -> tuple[tuple[complex, complex], tuple[complex, complex]]:
        """(W, Z) of dyads A and B."""
        f = self.fourbar
        return (f.a1 - f.a0, f.p - f.a1), (f.b1 - f.b0, f.p - f.b1)


def random_four_bar(rng: np.random.Generator, positions: int = 5) -> FourBarSample:
    """A random four-bar (lengths of order 1 m) and `positions` poses of its coupler, reached by turning the
    crank one way on one assembly, all away from dead centres."""
    while True:
        a0, b0 = 0j, complex(rng.uniform(0.8, 1.6), 0.0)
        a1 = a0 + rng.uniform(0.3, 1.0) * np.exp(1j * rng.uniform(0, 2 * np.pi))
        b1 = b0 + rng.uniform(0.6, 1.6) * np.exp(1j * rng.uniform(0, 2 * np.pi))
        p = (a1 + b1) / 2 + rng.uniform(0.2, 0.8) * np.exp(1j * rng.uniform(0, 2 * np.pi))
        fb = FourBar(a0, a1, b0, b1, p)
        if not 0.3 < fb.lengths["coupler"] < 2.5:
            continue
        try:
            lo, hi = fb.driver_range("A")
        except ValueError:
            continue
        branch = int(fb.branch_at("A", 0.0, 0.0)[0])
        direction = 1.0 if hi > -lo else -1.0
        x = np.concatenate([[0.0], np.cumsum(rng.uniform(0.15, 0.5, positions - 1))]) * direction
        if not (lo < x.min() and x.max() < hi):
            continue
        c = fb.solve("A", x, branch)
        mu = fb.transmission_angle(c, "A")
        alpha = c["coupler"]
        steps = np.abs(np.diff(np.sort(alpha)))
        if np.isfinite(alpha).all() and np.sin(mu).min() > np.sin(MIN_TRANSMISSION) \
                and steps.min() > MIN_ROTATION_STEP:
            return FourBarSample(fb, c["p"], alpha, c["crank_A"], c["rocker_B"])


@dataclass(frozen=True)
class TriadSample:
    points: np.ndarray       # (n,) complex precision points [m]
    alpha: np.ndarray        # (n,) rotations of W [rad]
    beta: np.ndarray         # (n,) rotations of V
    gamma: np.ndarray        # (n,) rotations of Z
    h: np.ndarray            # (n,) displacements of the chain's tail [m]
    vectors: np.ndarray      # (3,) W, V, Z in position 1 [m]


def random_triad(rng: np.random.Generator, positions: int, ungrounded: bool) -> TriadSample:
    """A three-link chain W-V-Z (lengths of order 1 m) turned through `positions` random poses, its tail
    fixed (grounded) or moved by random h_j (ungrounded)."""
    vectors = rng.uniform(0.4, 1.2, 3) * np.exp(1j * rng.uniform(0, 2 * np.pi, 3))
    def turning(lo: float, hi: float) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(rng.uniform(lo, hi, positions - 1))])

    alpha, beta, gamma = turning(0.1, 0.5), turning(-0.4, 0.6), turning(0.05, 0.4)
    h = np.zeros(positions, dtype=complex)
    if ungrounded:
        h[1:] = 0.2 * (rng.normal(size=positions - 1) + 1j * rng.normal(size=positions - 1))
    tail = rng.normal() + 1j * rng.normal()
    points = tail + h + (turns(np.column_stack([alpha, beta, gamma]))) @ vectors
    return TriadSample(points, alpha, beta, gamma, h, vectors)
