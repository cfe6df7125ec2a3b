"""Moving the compatibility linkage: the numeric form of the paper's graphical procedure (Table 3, Fig. 9).

Every case is the same machine. The free choices (Table 1) fix some β; loop 1 is then closed by the
law of cosines on its two remaining unknown links (two assemblies, Fig. 7); every further loop m adds one
equation, |Δ'_1 + Σ Δ'_j e^{iβ_j}| = |Δ_last|, whose roots are where the removed parallelogram link would fit
again ("CD ∥ BE", Sec. 2.3), and then gives its own β_m. The angles swept to find those roots:

    case            free choices     swept          loop 1 closed on     roots
    dyad 4 PP       β2               —              β3, β4              2 per β2 (a curve)
    dyad 5 PP       —                β2             β3, β4              finite: bracketing + Brent
    triad 5 PP      β2, β5           —              β3, β4              2 per (β2, β5)
    triad 6 PP      β2               β3             β4, β5              finite per β2: bracketing + Brent
    triad 7 PP      —                β2, β3         β4, β5              finite: 2-D grid of sign changes + Newton

The 1-D sweeps include the exact limits of loop 1's motion (where its two assemblies meet), so a root at
a limit is not lost between samples. The 2-D search of the triad in 7 PP has no such guarantee: a root in a
cell narrower than the grid, or at the edge of the region where loop 1 closes, can be missed.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import polynomial as poly

from pipeline.papers.dyad_triad_synthesis.standard_form import Chain, Loop, link_vectors, loops, turns

BRANCHES = (1, -1)
REACH_SLACK = 1e-9      # relative: a triangle this far out of reach is closed flat (round-off at the limits)


def close_pair(r, a: complex, b: complex, branch: int) -> tuple[np.ndarray, np.ndarray]:
    """Rotations (θa, θb) with a e^{iθa} + b e^{iθb} = r, by the law of cosines; `branch` ±1 picks the
    assembly; NaN where |r| is out of reach."""
    r = np.asarray(r, dtype=complex)
    la, lb, lr = abs(a), abs(b), np.abs(r)
    with np.errstate(divide="ignore", invalid="ignore"):
        cos = (la * la + lr * lr - lb * lb) / (2 * la * lr)
    cos = np.where(np.abs(cos) <= 1 + REACH_SLACK, np.clip(cos, -1.0, 1.0), np.nan)
    va = la * np.exp(1j * (np.angle(r) + branch * np.arccos(cos)))
    return np.angle(va / a), np.angle((r - va) / b)


def reach_limits(c: complex, a: complex, radius: float) -> list[float]:
    """Angles θ in (−π, π] where |c + a e^{iθ}| = radius (none, one or two)."""
    if abs(c) == 0 or abs(a) == 0:
        return []
    cos = (radius ** 2 - abs(c) ** 2 - abs(a) ** 2) / (2 * abs(c) * abs(a))
    if abs(cos) > 1:
        return []
    base = np.angle(c) - np.angle(a)
    return sorted({math.remainder(base + s * math.acos(cos), 2 * math.pi) for s in (1, -1)})


def reachable_intervals(c: complex, a: complex, inner: float, outer: float) -> list[tuple[float, float]]:
    """Intervals of θ in [−π, π] where inner ≤ |c + a e^{iθ}| ≤ outer: where a four-bar loop with ground
    c, input a and the other two links (|p| + |q| = outer, ||p| − |q|| = inner) closes."""
    cuts = sorted({-math.pi, math.pi, *reach_limits(c, a, inner), *reach_limits(c, a, outer)})
    out: list[tuple[float, float]] = []
    for lo, hi in itertools.pairwise(cuts):
        d = abs(c + a * np.exp(1j * 0.5 * (lo + hi)))
        if inner <= d <= outer:
            if out and math.isclose(out[-1][1], lo):
                out[-1] = (out[-1][0], hi)
            else:
                out.append((lo, hi))
    return out


def intersect(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> list[tuple[float, float]]:
    return [(max(x0, y0), min(x1, y1)) for x0, x1 in a for y0, y1 in b if max(x0, y0) < min(x1, y1)]


@dataclass(frozen=True)
class Root:
    beta: np.ndarray   # (n,) rotations β of positions 1..n [rad], β_1 = 0
    branch: int        # assembly of loop 1's closing triangle (0: found by Newton on every loop at once)


class Compatibility:
    """The compatibility linkage of a chain with its free choices fixed (positions are 1-based)."""

    def __init__(self, chain: Chain, free: dict[int, float] | None = None):
        free = dict(free or {})
        self.chain, self.loops = chain, loops(chain)
        if len(free) != chain.free_choices:
            raise ValueError(f"a {chain.kind} in {chain.n} positions has {chain.free_choices} free choice(s) "
                             f"(Table 1), got {len(free)}: {sorted(free)}")
        if not self.loops:
            raise ValueError(f"a {chain.kind} in {chain.n} positions has no compatibility equation: it is linear")
        first = self.loops[0]
        k = len(first.shared)
        loop1 = [*range(2, k + 2), first.position]
        if not set(free) <= set(loop1):
            raise ValueError(f"free choices must be among positions {loop1} of the first loop, got {sorted(free)}")
        unknown = [j for j in loop1 if j not in free]
        self.free = free
        self.sweep = unknown[:len(self.loops) - 1]          # one swept angle per further loop
        self.closing = tuple(unknown[len(self.sweep):])     # loop 1's two closing links
        self._delta1 = {j: (first.shared[j - 2] if j < first.position else first.last) for j in loop1}

    # -- the linkage at given swept angles -----------------------------------------------------------------
    def evaluate(self, swept, branch: int) -> tuple[np.ndarray, np.ndarray]:
        """β (…, n) and the further loops' residuals (…, loops − 1) [m] at swept angles (…, len(sweep));
        free choices may be arrays broadcast against them. NaN where loop 1 does not close."""
        swept = np.asarray(swept, dtype=float)
        shape = np.broadcast_shapes(swept.shape[:-1], *(np.shape(v) for v in self.free.values()))
        beta = np.zeros((*shape, self.chain.n))
        for j, value in self.free.items():
            beta[..., j - 1] = value
        for i, j in enumerate(self.sweep):
            beta[..., j - 1] = swept[..., i]
        first = self.loops[0]
        c = first.fixed + sum(self._delta1[j] * turns(beta[..., j - 1]) for j in self._delta1 if j not in self.closing)
        p, q = self.closing
        beta[..., p - 1], beta[..., q - 1] = close_pair(-c, self._delta1[p], self._delta1[q], branch)
        residuals = np.zeros((*shape, len(self.loops) - 1))
        for i, loop in enumerate(self.loops[1:]):
            partial = loop.fixed + (turns(beta[..., 1:len(loop.shared) + 1]) * loop.shared).sum(axis=-1)
            residuals[..., i] = np.abs(partial) - abs(loop.last)
            beta[..., loop.position - 1] = np.angle(-partial / loop.last)
        return beta, residuals

    def sweep_limits(self) -> list[float]:
        """Angles of the single swept link where loop 1 reaches a limit (its assemblies meet)."""
        (s,) = self.sweep
        first = self.loops[0]
        c = first.fixed + sum(self._delta1[j] * np.exp(1j * v) for j, v in self.free.items())
        p, q = (abs(self._delta1[j]) for j in self.closing)
        return [*reach_limits(c, self._delta1[s], p + q), *reach_limits(c, self._delta1[s], abs(p - q))]

    # -- roots ---------------------------------------------------------------------------------------------
    def roots(self, grid: int = 3601, grid_2d: int = 241, same: float = 1e-7) -> list[Root]:
        """Every real solution of the compatibility equations the search finds (trivial and special ones
        included; see `classify`)."""
        if not self.sweep:
            found = [Root(self.evaluate(np.zeros(0), b)[0], b) for b in BRANCHES]
            found = [r for r in found if np.isfinite(r.beta).all()]
        elif len(self.sweep) == 1:
            found = self._roots_1d(grid)
        else:
            found = self._roots_2d(grid_2d)
        return unique(found, same)

    def _roots_1d(self, grid: int) -> list[Root]:
        from scipy.optimize import brentq  # 0.3 s to import: not for the experiments that find no roots

        samples = np.unique(np.concatenate([np.linspace(-math.pi, math.pi, grid), self.sweep_limits()]))
        found = []
        for branch in BRANCHES:
            f = self.evaluate(samples[:, None], branch)[1][:, 0]

            def g(x: float, b: int = branch) -> float:
                return float(self.evaluate(np.array([x]), b)[1][0])

            for i in np.flatnonzero(np.isfinite(f[:-1]) & np.isfinite(f[1:]) & (f[:-1] * f[1:] <= 0)):
                a, b = samples[i], samples[i + 1]
                fa, fb = g(a), g(b)
                if np.isfinite(fa) and np.isfinite(fb) and fa * fb < 0:
                    x = brentq(g, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps)
                else:       # a root on a sample (the start, β = 0): keep the smaller end if it is a root
                    x = a if abs(f[i]) <= abs(f[i + 1]) else b
                    if not abs(g(x)) < 1e-12 * self._scale:
                        continue
                found.append(Root(self.evaluate(np.array([x]), branch)[0], branch))
        return found

    def _roots_2d(self, grid: int) -> list[Root]:
        axis = np.linspace(-math.pi, math.pi, grid)
        mesh = np.stack(np.meshgrid(axis, axis, indexing="ij"), axis=-1)
        seeds = []
        for branch in BRANCHES:
            beta, r = self.evaluate(mesh, branch)
            corners = np.stack([r[:-1, :-1], r[1:, :-1], r[:-1, 1:], r[1:, 1:]])       # (4, g-1, g-1, 2)
            finite = np.isfinite(corners).all(axis=-1)                                  # (4, g-1, g-1)
            lo = np.where(finite[..., None], corners, np.inf).min(axis=0)
            hi = np.where(finite[..., None], corners, -np.inf).max(axis=0)
            changes = ((lo <= 0) & (hi >= 0)).all(axis=-1)
            # interior cells where both residuals change sign, and every cell on the edge of the region where
            # loop 1 closes (a root there can sit beside corners that do not close)
            cells = finite.any(axis=0) & (changes | ~finite.all(axis=0))
            # seed: the cell's closed corner with the smallest residual
            size = np.where(finite, np.abs(corners).max(axis=-1), np.inf)
            best = size.argmin(axis=0)
            i, j = np.nonzero(cells)
            k = best[i, j]
            seeds.append(beta[i + k % 2, j + k // 2])
        beta = self.newton(np.concatenate(seeds))
        beta = beta[self.converged(beta)]
        _, first = np.unique(np.round(wrapped(beta), 6), axis=0, return_index=True)   # most seeds find the same
        return [Root(b, 0) for b in beta[np.sort(first)]]

    # -- every compatibility equation at once (no closure, no branches) --------------------------------------
    @property
    def unknown(self) -> list[int]:
        """Positions whose β is unknown."""
        return [j for j in range(2, self.chain.n + 1) if j not in self.free]

    def equations(self, beta) -> tuple[np.ndarray, np.ndarray]:
        """Real and imaginary parts of every loop's residual (…, 2L) [m] and their Jacobian (…, 2L, 2L) in the
        unknown β."""
        beta = np.asarray(beta, dtype=float)
        unknown = self.unknown
        res, jac = [], []
        for loop in self.loops:
            r = loop.residual(beta)
            d = np.zeros((*beta.shape[:-1], len(unknown)), dtype=complex)
            for col, j in enumerate(unknown):
                if j <= len(loop.shared) + 1:
                    d[..., col] = 1j * loop.shared[j - 2] * turns(beta[..., j - 1])
                elif j == loop.position:
                    d[..., col] = 1j * loop.last * turns(beta[..., j - 1])
            res += [r.real, r.imag]
            jac += [d.real, d.imag]
        return np.stack(res, axis=-1), np.stack(jac, axis=-2)

    def newton(self, beta, iterations: int = 30) -> np.ndarray:
        """Newton on every compatibility equation from many starts β (m, n) at once; returns the iterates
        (test them with `converged`)."""
        beta = np.array(beta, dtype=float)
        cols = [j - 1 for j in self.unknown]
        active = np.ones(len(beta), dtype=bool)
        tol = 1e-14 * self._scale
        for _ in range(iterations):
            r, jac = self.equations(beta[active])
            solvable = np.isfinite(r).all(axis=-1) & (np.abs(np.linalg.det(jac)) > 1e-300)
            moving = solvable & (np.abs(r).max(axis=-1) > tol)
            step = np.linalg.solve(jac[moving], r[moving][..., None])[..., 0]
            index = np.flatnonzero(active)
            beta[np.ix_(index[moving], cols)] = wrapped(beta[np.ix_(index[moving], cols)] - step)
            active[index[~moving]] = False
            if not active.any():
                break
        return beta

    def converged(self, beta, tol: float = 1e-12) -> np.ndarray:
        r = self.equations(beta)[0]
        return np.isfinite(r).all(axis=-1) & (np.abs(r).max(axis=-1) < tol * self._scale)

    @property
    def _scale(self) -> float:
        return max(abs(d) for loop in self.loops for d in loop.links)


def unique(roots: list[Root], same: float) -> list[Root]:
    """Roots with distinct β (modulo 2π), sorted by β2, β3, …"""
    out: list[Root] = []
    kept = np.empty((0, len(roots[0].beta) if roots else 0))
    for root in roots:
        if not (np.abs(wrapped(kept - root.beta)).max(axis=1, initial=0.0) <= same).any():
            out.append(root)
            kept = np.vstack([kept, root.beta])
    return sorted(out, key=lambda r: tuple(np.round(wrapped(r.beta), 9)))


def wrapped(x) -> np.ndarray:
    return np.remainder(np.asarray(x, dtype=float) + math.pi, 2 * math.pi) - math.pi


def classify(chain: Chain, beta, tol: float = 1e-6, conditioning: float = 1e-9) -> str:
    """`trivial` (β ≡ 0: the start position, a slider), `special` (β ≡ the rotation of another link: the
    concurrency point of Sec. 2.3, or the slider cases of Sec. 2.6), `degenerate` (the linear system for the
    links is singular) or `solution`."""
    beta = np.asarray(beta, dtype=float)
    if np.abs(wrapped(beta)).max() < tol:
        return "trivial"
    for c in range(chain.links):
        if c != chain.unknown and np.abs(wrapped(beta - chain.known[:, c])).max() < tol:
            return "special"
    return "solution" if link_vectors(chain, beta).conditioning > conditioning else "degenerate"


def loop_table(loop_list: list[Loop]) -> dict[str, complex]:
    """The Δ vectors named as in Table 5: Δ1..Δ_last of the first loop, then Δ1', Δ2', … of the others
    (their shared last link is not repeated)."""
    out: dict[str, complex] = {}
    for m, loop in enumerate(loop_list):
        tick = "'" * m
        out[f"Δ1{tick}"] = loop.fixed
        for j, d in enumerate(loop.shared, start=2):
            out[f"Δ{j}{tick}"] = complex(d)
        if m == 0:
            out[f"Δ{len(loop.shared) + 2}"] = loop.last
    return out


@dataclass(frozen=True)
class Synthesized:
    """A root of the compatibility equations with its meaning, and the link vectors where it has them."""

    beta: np.ndarray          # (n,) rad
    branch: int
    label: str                # trivial | special | degenerate | solution (see `classify`)
    vectors: np.ndarray       # (k,) complex link vectors [m] (NaN unless a solution)
    residual: float           # m, max |A x − (δ − h)| of the link solve
    conditioning: float


def synthesize(chain: Chain, free: dict[int, float] | None = None, grid: int = 3601, grid_2d: int = 241,
               same: float = 1e-7, special_tol: float = 1e-6, conditioning: float = 1e-9) -> list[Synthesized]:
    """The whole procedure of Fig. 9: compatibility loops, their roots, then the linear solve for the links
    (eq. A4, least squares over every position) of each root that is a real solution."""
    out = []
    for root in Compatibility(chain, free).roots(grid, grid_2d, same):
        label = classify(chain, root.beta, special_tol, conditioning)
        links = link_vectors(chain, root.beta)
        vectors = links.vectors if label == "solution" else np.full(chain.links, np.nan + 0j)
        out.append(Synthesized(root.beta, root.branch, label, vectors, links.residual, links.conditioning))
    return out


def isotropic_roots(loop_list: list[Loop], tol: float = 1e-9) -> np.ndarray:
    """Every complex solution (z2, z3) of the two compatibility equations of a dyad in five positions, with
    z_j = e^{iβ_j} and e^{−iβ_j} taken as independent unknowns (isotropic coordinates). The loops are linear
    in z4, z5 and their partners, so with c = Δ1, a = Δ2, b = Δ3, r = |Δ4| (and the same with Δ') the system
    is two polynomials, quadratic in z3:

        (c + a z2 + b z3)(c̄ z2 z3 + ā z3 + b̄ z2) − r² z2 z3 = A2 z3² + A1 z3 + A0 = 0.

    Their resultant in z3 is a polynomial in z2 (z2 = 0 is spurious: the equations were multiplied by it);
    each of its roots gives z3 by eliminating z3². Real β are the roots with |z2| = |z3| = 1."""
    def coefficients(loop: Loop) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c, (a, b), r2 = loop.fixed, loop.shared, abs(loop.last) ** 2
        cc, ac, bc = np.conj(c), np.conj(a), np.conj(b)
        return (np.array([b * ac, b * cc]), np.array([c * ac, abs(c) ** 2 + abs(a) ** 2 + abs(b) ** 2 - r2, a * cc]),
                np.array([0.0, c * bc, a * bc]))

    (a2, a1, a0), (b2, b1, b0) = (coefficients(loop) for loop in loop_list)
    mul, sub = poly.polymul, poly.polysub
    p = sub(mul(a2, b0), mul(a0, b2))                       # A2 B0 − A0 B2
    q = sub(mul(a2, b1), mul(a1, b2))                       # A2 B1 − A1 B2
    resultant = sub(mul(p, p), mul(q, sub(mul(a1, b0), mul(a0, b1))))
    scale = np.abs(resultant).max()
    resultant = np.trim_zeros(np.where(np.abs(resultant) > 1e-14 * scale, resultant, 0), "b")
    out = []
    for z2 in poly.polyroots(resultant):
        if abs(z2) < tol:
            continue
        z3 = -poly.polyval(z2, p) / poly.polyval(z2, q)     # B2·E1 − A2·E2 = −(q z3 + p) = 0
        if all(max(abs(z2 - o[0]), abs(z3 - o[1])) > tol * (1 + abs(z2) + abs(z3)) for o in out):
            out.append((z2, z3))
    return np.array(out, dtype=complex).reshape(-1, 2)
