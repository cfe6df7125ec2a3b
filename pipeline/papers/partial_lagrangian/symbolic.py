"""The paper's counts, Sect. 4.1-4.2, taken literally: the terms of the expanded symbolic Lagrangian of an
n-link planar chain (point masses, springs, gravity) and of its derivatives, with SymPy.

Link i's partial Lagrangian in the paper's postural-operator form (eqs. 15-22, generalised to link i; links
0-based here, φ_j = θ_0 + … + θ_j, a relative angle sum kept as one cos/sin):

    L_i = ½ m_i (Σ_j l_j² φ̇_j² + 2 Σ_{j<k} l_j l_k φ̇_j φ̇_k cos(φ_k − φ_j))
          − ½ k_i (Σ_j l_j² + 2 Σ_{j<k} l_j l_k cos(φ_k − φ_j)) − m_i g Σ_j l_j sin φ_j          (j, k ≤ i)

with every parameter a symbol. τ_ki = D_k L_i = d/dt ∂L_i/∂θ̇_k − ∂L_i/∂θ_k (eq. 5). A term is one summand of
the fully expanded expression (products and powers multiplied out, trigonometric functions not expanded).

`link_counts` works in a SymPy polynomial ring whose generators are the rates, the parameters and the cos/sin
of the angle sums (treated as independent symbols, exactly as `sympy.expand` treats them), with the chain rule
for the angles written out: the same counts as expanding the expressions (`expanded_counts`, tested), about
100× faster (all ten links in about a second).

Because every link carries its own m_i and k_i, no term of one link's partial Lagrangian merges with another's:
the usual Lagrangian L = Σ L_i and its τ_k = Σ_i τ_ki have exactly the terms of Table 1's entries summed.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.polys.rings import ring


@dataclass(frozen=True)
class LinkTerms:
    """Term counts of link i's partial Lagrangian (0-based i) and of its derivatives, k = 0 … i."""

    lagrangian: int          # terms of L_i
    d_angle: list[int]       # terms of ∂L_i/∂θ_k
    d_rate: list[int]        # terms of ∂L_i/∂θ̇_k
    tau: list[int]           # terms of τ_ki = D_k L_i (column i of Table 1)


def link_counts(i: int) -> LinkTerms:
    """Term counts of link i's partial Lagrangian and of its derivatives (see the module docstring)."""
    n = i + 1
    pairs = [(j, k) for j in range(n) for k in range(j + 1, n)]
    names = ([f"qd{a}" for a in range(n)] + [f"qdd{a}" for a in range(n)] + [f"l{a}" for a in range(n)]
             + ["m", "k", "g"] + [f"C{j}_{k}" for j, k in pairs] + [f"S{j}_{k}" for j, k in pairs]
             + [f"c{j}" for j in range(n)] + [f"s{j}" for j in range(n)])
    R, *gens = ring(names, sp.QQ)
    rate, acceleration, length = gens[:n], gens[n:2 * n], gens[2 * n:3 * n]
    m, k_spring, g = gens[3 * n:3 * n + 3]
    trig = gens[3 * n + 3:]
    p = len(pairs)
    cos_rel, sin_rel = dict(zip(pairs, trig[:p], strict=True)), dict(zip(pairs, trig[p:2 * p], strict=True))
    cos_abs, sin_abs = trig[2 * p:2 * p + n], trig[2 * p + n:]
    phi_rate = [sum(rate[:j + 1], R.zero) for j in range(n)]
    speed2 = (sum((length[j] ** 2 * phi_rate[j] ** 2 for j in range(n)), R.zero)
              + 2 * sum((length[j] * length[k] * phi_rate[j] * phi_rate[k] * cos_rel[j, k] for j, k in pairs), R.zero))
    reach2 = (sum((length[j] ** 2 for j in range(n)), R.zero)
              + 2 * sum((length[j] * length[k] * cos_rel[j, k] for j, k in pairs), R.zero))
    height = sum((length[j] * sin_abs[j] for j in range(n)), R.zero)
    half = sp.QQ(1, 2)
    lagrangian = half * m * speed2 - half * k_spring * reach2 - m * g * height     # eqs. (15)-(16), (21)-(22)

    def d_angle(P, a: int):
        """∂P/∂θ_a by the chain rule: cos(φ_k − φ_j) depends on θ_a for j < a ≤ k, cos φ_j for a ≤ j."""
        out = R.zero
        for j, k in pairs:
            if j < a <= k:
                out += -sin_rel[j, k] * P.diff(cos_rel[j, k]) + cos_rel[j, k] * P.diff(sin_rel[j, k])
        for j in range(a, n):
            out += -sin_abs[j] * P.diff(cos_abs[j]) + cos_abs[j] * P.diff(sin_abs[j])
        return out

    def d_dt(P):
        return sum((d_angle(P, a) * rate[a] + P.diff(rate[a]) * acceleration[a] for a in range(n)), R.zero)

    by_angle = [d_angle(lagrangian, a) for a in range(n)]
    by_rate = [lagrangian.diff(rate[a]) for a in range(n)]
    tau = [d_dt(by_rate[a]) - by_angle[a] for a in range(n)]                  # eq. (5): τ_ki = D_k L_i
    return LinkTerms(len(lagrangian), [len(x) for x in by_angle], [len(x) for x in by_rate], [len(x) for x in tau])


def expanded_counts(n: int) -> tuple[int, list[int]]:
    """(terms of the usual L of an n-link chain, terms of each τ_k = D_k L), by building the expressions and
    expanding them with `sympy.expand`: the slow reference `link_counts` is checked against."""
    q, qd, qdd = sp.symbols(f"q0:{n}"), sp.symbols(f"qd0:{n}"), sp.symbols(f"qdd0:{n}")
    m, length, k_spring, g = sp.symbols(f"m0:{n}"), sp.symbols(f"l0:{n}"), sp.symbols(f"k0:{n}"), sp.Symbol("g")
    phi = [sum(q[:j + 1]) for j in range(n)]
    phi_rate = [sum(qd[:j + 1]) for j in range(n)]
    lagrangian = 0
    for i in range(n):
        pairs = [(j, k) for j in range(i + 1) for k in range(j + 1, i + 1)]
        interference = {(j, k): length[j] * length[k] * sp.cos(phi[k] - phi[j]) for j, k in pairs}
        speed2 = (sum(length[j] ** 2 * phi_rate[j] ** 2 for j in range(i + 1))
                  + 2 * sum(interference[j, k] * phi_rate[j] * phi_rate[k] for j, k in pairs))
        reach2 = sum(length[j] ** 2 for j in range(i + 1)) + 2 * sum(interference.values())
        height = sum(length[j] * sp.sin(phi[j]) for j in range(i + 1))
        lagrangian += m[i] * speed2 / 2 - k_spring[i] * reach2 / 2 - m[i] * g * height
    lagrangian = sp.expand(lagrangian)
    taus = []
    for a in range(n):
        momentum = sp.diff(lagrangian, qd[a])
        tau = sum(sp.diff(momentum, q[b]) * qd[b] + sp.diff(momentum, qd[b]) * qdd[b] for b in range(n)) \
            - sp.diff(lagrangian, q[a])
        taus.append(len(sp.Add.make_args(sp.expand(tau))))
    return len(sp.Add.make_args(lagrangian)), taus
