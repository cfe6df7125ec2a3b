"""The four-bar built from two synthesised dyads, and its closed-form position analysis and defects.

Dyad A (ground pivot a0, moving pivot a1) and dyad B (b0, b1) share the coupler, which carries the tracer
point p. Every angle is a rotation from position 1, as in the standard form: β_A of the crank a0→a1, α of
the coupler, β_B of the rocker b0→b1. The loop W_A e^{iβ_A} + C e^{iα} − W_B e^{iβ_B} = b0 − a0 (C = b1 − a1)
is closed by the law of cosines (the same triangle as a compatibility loop): given the driver's rotation,
`branch` ±1 picks one of the two assemblies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pipeline.papers.dyad_triad_synthesis.compatibility import BRANCHES, close_pair, reachable_intervals
from pipeline.papers.dyad_triad_synthesis.standard_form import turns

DRIVERS = ("A", "B")
LINKS = ("crank_A", "coupler", "rocker_B")


@dataclass(frozen=True)
class FourBar:
    a0: complex   # ground pivot of dyad A [m]
    a1: complex   # moving pivot of dyad A in position 1 [m]
    b0: complex
    b1: complex
    p: complex    # tracer (precision) point in position 1 [m]

    @classmethod
    def from_dyads(cls, point: complex, dyad_a: tuple[complex, complex], dyad_b: tuple[complex, complex]) -> FourBar:
        """Dyads as (W, Z): ground pivot = P_1 − Z − W, moving pivot = P_1 − Z."""
        (wa, za), (wb, zb) = dyad_a, dyad_b
        return cls(a0=point - za - wa, a1=point - za, b0=point - zb - wb, b1=point - zb, p=point)

    @property
    def lengths(self) -> dict[str, float]:
        return {"ground": abs(self.b0 - self.a0), "crank_A": abs(self.a1 - self.a0),
                "coupler": abs(self.b1 - self.a1), "rocker_B": abs(self.b1 - self.b0)}

    def grashof_margin(self) -> float:
        """p + q − s − l [m]: ≥ 0 for a Grashof linkage (a link turns fully), < 0 for a triple rocker."""
        lengths = sorted(self.lengths.values())
        return lengths[1] + lengths[2] - lengths[0] - lengths[3]

    # -- position analysis ---------------------------------------------------------------------------------
    def solve(self, driver: str, rotation, branch: int) -> dict[str, np.ndarray]:
        """Closed-form configuration at the driver's rotation(s) [rad]: the rotations of crank, coupler and
        rocker (rad, NaN where the loop does not close), the moving pivots and the tracer [m]."""
        rotation = np.asarray(rotation, dtype=float)
        wa, wb, c = self.a1 - self.a0, self.b1 - self.b0, self.b1 - self.a1
        ground = self.b0 - self.a0
        if driver == "A":
            beta_a = rotation
            alpha, beta_b = close_pair(ground - wa * turns(rotation), c, -wb, branch)
        elif driver == "B":
            beta_b = rotation
            beta_a, alpha = close_pair(ground + wb * turns(rotation), wa, c, branch)
        else:
            raise ValueError(f"driver must be one of {DRIVERS}, not {driver!r}")
        a1 = self.a0 + wa * turns(beta_a)
        return {"crank_A": np.asarray(beta_a), "coupler": np.asarray(alpha), "rocker_B": np.asarray(beta_b),
                "a1": a1, "b1": self.b0 + wb * turns(beta_b), "p": a1 + (self.p - self.a1) * turns(alpha)}

    def driver_range(self, driver: str) -> tuple[float, float]:
        """The driver's rotations (lo, hi) [rad] where the loop closes, as one arc from lo up to hi (hi may
        exceed π; a full turn is (−π, π))."""
        wa, wb, c = self.a1 - self.a0, self.b1 - self.b0, self.b1 - self.a1
        if driver == "A":
            arcs = reachable_intervals(self.b0 - self.a0, -wa, abs(abs(c) - abs(wb)), abs(c) + abs(wb))
        else:
            arcs = reachable_intervals(self.b0 - self.a0, wb, abs(abs(c) - abs(wa)), abs(c) + abs(wa))
        if len(arcs) == 2 and math.isclose(arcs[0][0], -math.pi) and math.isclose(arcs[1][1], math.pi):
            return arcs[1][0], arcs[0][1] + 2 * math.pi          # one arc through ±π
        if len(arcs) != 1:
            raise ValueError(f"driver {driver} moves on {len(arcs)} separate arcs (a Grashof double rocker)")
        return arcs[0]

    def branch_at(self, driver: str, rotations, alpha) -> np.ndarray:
        """The assembly (±1) that puts the coupler at rotation α for the driver's rotation: 0 if neither."""
        out = []
        for rotation, a in zip(np.atleast_1d(rotations), np.atleast_1d(alpha), strict=True):
            errors = [abs(math.remainder(float(self.solve(driver, rotation, b)["coupler"]) - a, 2 * math.pi))
                      for b in BRANCHES]
            k = int(np.nanargmin(errors))
            out.append(BRANCHES[k] if errors[k] < 1e-6 else 0)
        return np.array(out)

    def transmission_angle(self, config: dict[str, np.ndarray], driver: str) -> np.ndarray:
        """Angle [rad] between the coupler and the driven link at their joint (0 or π at a dead centre)."""
        a1, b1 = config["a1"], config["b1"]
        if driver == "A":
            return np.abs(np.angle((a1 - b1) / (self.b0 - b1)))
        return np.abs(np.angle((b1 - a1) / (self.a0 - a1)))


def on_arc(rotation: float, arc: tuple[float, float]) -> float:
    """The rotation written on the driver's arc (lo ≤ x ≤ hi, shifted by whole turns)."""
    lo, _ = arc
    return lo + (rotation - lo) % (2 * math.pi)


@dataclass(frozen=True)
class Leg:
    """The driver's motion between two poses on one circuit: straight on the same branch, or out to an arc
    end (a toggle, where the branches meet) and back on the other branch."""

    driver: str
    start: float
    end: float
    branches: tuple[int, ...]        # one branch, or two with the toggle between them
    via: tuple[float, ...]           # driver rotations: start, [toggle,] end

    @property
    def toggles(self) -> int:
        return len(self.branches) - 1

    def samples(self, fourbar: FourBar, per_radian: int = 200) -> dict[str, np.ndarray]:
        """Closed-form configurations along the leg (driver rotation, branch and every output)."""
        parts = []
        for (x0, x1), b in zip(zip(self.via[:-1], self.via[1:], strict=True), self.branches, strict=True):
            x = np.linspace(x0, x1, max(2, math.ceil(abs(x1 - x0) * per_radian)))
            parts.append((x, np.full(len(x), b)))
        x, b = np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
        config = {k: np.empty(len(x), dtype=complex if k in ("a1", "b1", "p") else float)
                  for k in (*LINKS, "a1", "b1", "p")}
        for branch in BRANCHES:
            sel = b == branch
            for k, v in fourbar.solve(self.driver, x[sel], branch).items():
                config[k][sel] = v
        return {"driver": x, "branch": b, **config}


def leg(fourbar: FourBar, driver: str, pose_from: dict[str, float], pose_to: dict[str, float]) -> Leg:
    """The driver's way from one pose to the next (poses as rotations of crank_A, coupler, rocker_B)."""
    arc = fourbar.driver_range(driver)
    link = LINKS[0] if driver == "A" else LINKS[2]
    x0, x1 = on_arc(pose_from[link], arc), on_arc(pose_to[link], arc)
    b0 = int(fourbar.branch_at(driver, x0, pose_from["coupler"])[0])
    b1 = int(fourbar.branch_at(driver, x1, pose_to["coupler"])[0])
    if b0 == b1:
        return Leg(driver, x0, x1, (b0,), (x0, x1))
    # a toggle at the nearer arc end that lies on the way (both ends are toggles of a non-Grashof driver)
    end = min(arc, key=lambda e: abs(e - x0) + abs(e - x1))
    return Leg(driver, x0, x1, (b0, b1), (x0, end, x1))


def circuit_order(fourbar: FourBar, driver: str, poses: list[dict[str, float]]) -> np.ndarray:
    """Each pose's place s ∈ [0, 2) on the single circuit of a non-Grashof linkage: out along branch +1 from
    the arc's start (s = 0..1), back along branch −1 (s = 1..2)."""
    lo, hi = fourbar.driver_range(driver)
    link = LINKS[0] if driver == "A" else LINKS[2]
    out = []
    for pose in poses:
        x = on_arc(pose[link], (lo, hi))
        u = (x - lo) / (hi - lo)
        out.append(u if fourbar.branch_at(driver, x, pose["coupler"])[0] == 1 else 2 - u)
    return np.array(out)


def cyclic_order_kept(places: np.ndarray) -> bool:
    """True if the places visit the poses in their numbered order (either way round the circuit)."""
    order = np.argsort(places)
    k = int(np.flatnonzero(order == 0)[0])
    rolled = np.roll(order, -k)
    n = len(order)
    return bool((rolled == np.arange(n)).all() or (np.roll(rolled[::-1], 1) == np.arange(n)).all())
