"""The standard-form equations of a dyad or triad and their compatibility loops.

A planar vector is a complex number. Position 1 is the reference: every angle is a rotation from it, and
the precision point moves by δ_j = P_j − P_1. The standard form writes one vector equation per position
j = 2..n:

    dyad,  eq. (1):   W (e^{iβ_j} − 1) + Z (e^{iα_j} − 1)                    = δ_j − h_j
    triad, eq. (2):   W (e^{iα_j} − 1) + V (e^{iβ_j} − 1) + Z (e^{iγ_j} − 1) = δ_j − h_j

β is the unknown rotation (of W in a dyad, of V in a triad); the others are prescribed, h_j moves the tail of
an ungrounded chain. With k link vectors, the system is linear in them, so it has a solution only where its
augmented matrix [e^{iθ} − 1 | δ − h] has rank k: every (k+1)×(k+1) minor vanishes (eqs. 7, 14-15, A1).
Expanding such a minor along the β column gives a compatibility equation (eqs. 8, 16-17, 20, A2-A3, A5-A7)

    Δ_1 + Σ_j Δ_j e^{iβ_j} = 0,    Δ_1 = −Σ_j Δ_j   (eqs. 13, 18-19, 21, A8-A10)

whose Δ_j are the cofactors of the β entries. The minors used are rows 2..k+1 (shared by every loop) plus one
further row m = k+2..n, so there are n − 1 − k loops, and the last link of every loop (the cofactor of row
m, the minor of the shared rows) is the same vector ("Δ4 used twice", Sec. 2.3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def turns(angles) -> np.ndarray:
    """e^{iθ}."""
    return np.exp(1j * np.asarray(angles, dtype=float))


@dataclass(frozen=True)
class Chain:
    """A dyad or triad synthesis problem in n precision positions (every array has n rows, row 0 is
    position 1: zero rotation, zero displacement)."""

    kind: str                 # "dyad" | "triad"
    known: np.ndarray         # (n, k) rotations [rad] of every link, the β column ignored (NaN)
    unknown: int              # column of β in the standard form: 0 for a dyad (W), 1 for a triad (V)
    rhs: np.ndarray           # (n,) complex δ_j − h_j [m]

    @property
    def n(self) -> int:
        return len(self.rhs)

    @property
    def links(self) -> int:
        return self.known.shape[1]

    @property
    def free_choices(self) -> int:
        """Table 1: scalar unknowns (2k link components + n − 1 angles) minus scalar equations 2(n − 1)."""
        return 2 * self.links - (self.n - 1)

    def columns(self, beta) -> np.ndarray:
        """(…, n, k) rotations with β (…, n) inserted in its column."""
        beta = np.asarray(beta, dtype=float)
        angles = np.broadcast_to(self.known, (*beta.shape[:-1], *self.known.shape)).copy()
        angles[..., self.unknown] = beta
        return angles

    def matrix(self, beta) -> np.ndarray:
        """(…, n − 1, k) coefficient matrix e^{iθ_j} − 1 of positions 2..n (eq. 6, A1)."""
        return turns(self.columns(beta))[..., 1:, :] - 1.0

    def displacements(self, vectors, beta) -> np.ndarray:
        """Σ link (e^{iθ_j} − 1) for positions 1..n: the left-hand side of the standard form."""
        return (turns(self.columns(beta)) - 1.0) @ np.asarray(vectors, dtype=complex)


def dyad(points, alpha, h=None) -> Chain:
    """Eq. (1): the precision points P_j [m] and the coupler rotations α_j [rad] of positions 1..n."""
    points = np.asarray(points, dtype=complex)
    alpha = np.asarray(alpha, dtype=float)
    known = np.column_stack([np.full(len(alpha), np.nan), alpha - alpha[0]])
    return _chain("dyad", known, 0, points, h)


def triad(points, alpha, gamma, h=None) -> Chain:
    """Eq. (2): the precision points P_j [m], the rotations α_j of W and γ_j of the coupler Z [rad], and the
    tail displacements h_j [m] of an ungrounded triad (zero if None)."""
    alpha, gamma = np.asarray(alpha, dtype=float), np.asarray(gamma, dtype=float)
    known = np.column_stack([alpha - alpha[0], np.full(len(alpha), np.nan), gamma - gamma[0]])
    return _chain("triad", known, 1, np.asarray(points, dtype=complex), h)


def _chain(kind: str, known: np.ndarray, unknown: int, points: np.ndarray, h) -> Chain:
    n = len(points)
    if known.shape[0] != n:
        raise ValueError(f"{n} precision points but {known.shape[0]} rotations")
    h = np.zeros(n, dtype=complex) if h is None else np.asarray(h, dtype=complex) - complex(np.asarray(h)[0])
    rhs = points - points[0] - h
    chain = Chain(kind, known, unknown, rhs)
    if chain.free_choices < 0:
        raise ValueError(f"a {kind} has at most {2 * known.shape[1] + 1} precision positions, not {n}")
    return chain


@dataclass(frozen=True)
class Loop:
    """One compatibility equation Δ_1 + Σ_{j ∈ shared} Δ_j e^{iβ_j} + Δ_last e^{iβ_m} = 0 (a closed chain of
    Δ vectors: the compatibility linkage)."""

    fixed: complex            # Δ_1 (ground link)
    shared: np.ndarray        # Δ_2 .. Δ_{k+1}, the links of the rows every loop has
    last: complex             # Δ of row m (the same vector in every loop)
    position: int             # m: the loop's own position, 1-based

    @property
    def links(self) -> np.ndarray:
        """Δ_1, Δ_2, …, Δ_last."""
        return np.concatenate([[self.fixed], self.shared, [self.last]])

    def residual(self, beta) -> np.ndarray:
        """Δ_1 + Σ Δ_j e^{iβ_j} for β (…, n) of positions 1..n (position 1's entry unused)."""
        beta = np.asarray(beta, dtype=float)
        k = len(self.shared)
        return self.fixed + turns(beta[..., 1:k + 1]) @ self.shared + self.last * turns(beta[..., self.position - 1])


def loops(chain: Chain) -> list[Loop]:
    """The n − 1 − k compatibility loops of a chain (one for dyad 4 PP and triad 5 PP, two for dyad 5 PP
    and triad 6 PP, three for triad 7 PP): cofactors of the β column of the augmented matrix restricted to
    the shared rows 2..k+1 and row m."""
    k = chain.links
    coefficients = turns(chain.known)[1:] - 1.0              # (n − 1, k); the β column is NaN, never used
    others = [c for c in range(k) if c != chain.unknown]
    augmented = np.column_stack([coefficients[:, others], chain.rhs[1:]])   # the minors' columns
    out = []
    for m in range(k + 2, chain.n + 1):
        rows = [*range(k), m - 2]                           # matrix rows of positions 2..k+1 and m
        cofactors = np.array([(-1) ** (i + chain.unknown) * np.linalg.det(augmented[[r for r in rows if r != rows[i]]])
                              for i in range(k + 1)])
        out.append(Loop(fixed=complex(-cofactors.sum()), shared=cofactors[:k], last=complex(cofactors[k]),
                        position=m))
    return out


@dataclass(frozen=True)
class LinkSolution:
    vectors: np.ndarray       # (k,) complex link vectors [m]: W, Z (dyad) or W, V, Z (triad)
    residual: float           # max_j |A_j x − (δ_j − h_j)| [m]
    conditioning: float       # smallest / largest singular value of the coefficient matrix


def link_vectors(chain: Chain, beta) -> LinkSolution:
    """The link vectors for a complete set of rotations: least squares over all n − 1 equations (eq. A4 with
    every row); the residual is ~0 exactly where β satisfies the compatibility equations."""
    a = chain.matrix(beta)
    x, *_ = np.linalg.lstsq(a, chain.rhs[1:], rcond=None)
    s = np.linalg.svd(a, compute_uv=False)
    return LinkSolution(x, float(np.abs(a @ x - chain.rhs[1:]).max()), float(s[-1] / s[0]))


def system_rank(chain: Chain, vectors, beta, step: float = 1e-7) -> tuple[int, int, int]:
    """(scalar equations, scalar unknowns, rank of their Jacobian) of the standard form at a solution; the
    solution set's local dimension is unknowns − rank (Table 1's free choices when the rank is full)."""
    vectors = np.asarray(vectors, dtype=complex)
    beta = np.asarray(beta, dtype=float)
    x0 = np.concatenate([vectors.real, vectors.imag, beta[1:]])
    k = chain.links

    def equations(x: np.ndarray) -> np.ndarray:
        b = np.concatenate([[0.0], x[2 * k:]])
        r = chain.displacements(x[:k] + 1j * x[k:2 * k], b)[1:] - chain.rhs[1:]
        return np.concatenate([r.real, r.imag])

    jac = np.column_stack([(equations(x0 + step * e) - equations(x0 - step * e)) / (2 * step)
                           for e in np.eye(len(x0))])
    s = np.linalg.svd(jac, compute_uv=False)
    return jac.shape[0], jac.shape[1], int((s > 1e-6 * s[0]).sum())
