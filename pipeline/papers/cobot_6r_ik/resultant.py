"""The polynomial system of Sec. 3 and its elimination to Λ(c1), assembled numerically (compiled).

Unknowns p = (c1, c2, c3, P4) (eq. 7). P4 is eliminated linearly (eq. 18), leaving three quadrics
Φ4, Φ5, Φ6 in (c1, c2, c3) whose coefficients φ_{h,ijk} (eq. 19, Appendix A) are read off the pose.
c3 is eliminated with the 4×4 Sylvester determinants of eq. (21), giving Ψ1, Ψ2 of total degree 4
in (c1, c2) (eq. 22); c2 with the 8×8 Sylvester determinant of eq. (24), giving Λ of degree 16 (eq. 25).

As in Sec. 4 (eqs. 26–28) every product of polynomials in c1 is a convolution of coefficient arrays;
nothing is symbolic at run time. The 8×8 determinant of eq. (24) is evaluated as the 4×4 Bézout
determinant of the same two quartics in c2, which is the same polynomial (the resultant of two
quartics; det Bez = det Syl for n = 4), with 12 products instead of Appendix D's 219 terms.

Arrays are ascending in powers. Bivariate arrays are [power of c1, power of c2]. Lengths are scaled by
a2 before the elimination (each Φ is homogeneous in the lengths, so the roots are unchanged).
"""

from __future__ import annotations

import numba
import numpy as np

# φ_{h,ijk} column order (the exponents of c1, c2, c3)
MONOMIALS = ((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (2, 0, 0), (0, 2, 0), (0, 0, 2), (1, 1, 0), (1, 0, 1),
             (0, 1, 1))
I000, I100, I010, I001, I200, I020, I002, I110, I101, I011 = range(10)


@numba.njit(cache=True)
def phi(P5: np.ndarray, P6: np.ndarray, d1: float, d4: float, d5: float, a2: float) -> np.ndarray:
    """φ_{h,ijk} of Φ4, Φ5, Φ6 (eq. 19, Appendix A) -> (3, 10) in MONOMIALS order.

    Appendix A with its misprints corrected (errata): φ6 has −a2² where the paper prints −d2², and
    φ6,200 has (d1 − d5) where it prints (d1 + d5)."""
    x, y, z = P5[0], P5[1], P5[2]
    ex, ey, ez = P5[0] - P6[0], P5[1] - P6[1], P5[2] - P6[2]
    K = x * x + y * y + z * z + d1 * d1 + d4 * d4 + d5 * d5 - a2 * a2
    f = np.empty((3, 10))
    # Φ4 = P5x(c1² − c2² + c3² − 1) + 2 P5y (c1c2 − c3) − 2 d5 (c1c3 − c2), eqs. (13) + (18)
    f[0, I000], f[0, I100], f[0, I010], f[0, I001] = -x, 0.0, 2 * d5, -2 * y
    f[0, I200], f[0, I020], f[0, I002] = x, -x, x
    f[0, I110], f[0, I101], f[0, I011] = 2 * y, -2 * d5, 0.0
    # Φ5 = 2(c1c3 + c2)(P5x − P6x) + 2(c2c3 − c1)(P5y − P6y) − (c1² + c2² − c3² − 1)(P5z − P6z), eq. (15)
    f[1, I000], f[1, I100], f[1, I010], f[1, I001] = ez, -2 * ey, 2 * ex, 0.0
    f[1, I200], f[1, I020], f[1, I002] = -ez, -ez, ez
    f[1, I110], f[1, I101], f[1, I011] = 0.0, 2 * ex, 2 * ey
    # Φ6 = |P3 − P1|² − a2², eq. (16) with eq. (18), × S (Appendix A, corrected)
    f[2, I000] = K + 2 * y * d4 - 2 * z * (d1 + d5) + 2 * d1 * d5
    f[2, I100] = 4 * y * d5 + 4 * z * d4 - 4 * d1 * d4
    f[2, I010] = -4 * x * d5
    f[2, I001] = -4 * x * d4
    f[2, I200] = K - 2 * y * d4 - 2 * z * (d1 - d5) - 2 * d1 * d5
    f[2, I020] = K + 2 * y * d4 - 2 * z * (d1 - d5) - 2 * d1 * d5
    f[2, I002] = K - 2 * y * d4 - 2 * z * (d1 + d5) + 2 * d1 * d5
    f[2, I110] = 4 * x * d4
    f[2, I101] = -4 * x * d5
    f[2, I011] = 4 * z * d4 - 4 * y * d5 - 4 * d1 * d4
    return f


@numba.njit(cache=True)
def chi(f: np.ndarray, h: int, c1: float, c2: float) -> tuple[float, float, float]:
    """χ_{h,2}, χ_{h,1}, χ_{h,0} of eq. (20) at (c1, c2): X_h = χ2 c3² + χ1 c3 + χ0 (Appendix B)."""
    return (f[h, I002], f[h, I001] + f[h, I101] * c1 + f[h, I011] * c2,
            f[h, I000] + f[h, I100] * c1 + f[h, I010] * c2 + f[h, I200] * c1 * c1 + f[h, I110] * c1 * c2
            + f[h, I020] * c2 * c2)


@numba.njit(cache=True)
def _conv2_acc(a: np.ndarray, na: int, b: np.ndarray, nb: int, sign: float, out: np.ndarray) -> None:
    """out += sign · a * b for bivariate arrays of total degree na, nb (2-D convolution)."""
    for i in range(na + 1):
        for j in range(na + 1 - i):
            x = a[i, j]
            if x == 0.0:
                continue
            x *= sign
            for k in range(nb + 1):
                for m in range(nb + 1 - k):
                    out[i + k, j + m] += x * b[k, m]


@numba.njit(cache=True)
def _chi_arrays(f: np.ndarray, h: int) -> tuple[float, np.ndarray, np.ndarray]:
    """χ_{h,2} (a number), χ_{h,1} and χ_{h,0} as bivariate arrays in (c1, c2)."""
    x1 = np.zeros((2, 2))
    x1[0, 0], x1[1, 0], x1[0, 1] = f[h, I001], f[h, I101], f[h, I011]
    x0 = np.zeros((3, 3))
    x0[0, 0], x0[1, 0], x0[0, 1] = f[h, I000], f[h, I100], f[h, I010]
    x0[2, 0], x0[1, 1], x0[0, 2] = f[h, I200], f[h, I110], f[h, I020]
    return f[h, I002], x1, x0


@numba.njit(cache=True)
def psi(f: np.ndarray, ha: int, hb: int) -> np.ndarray:
    """Ψ = det of the 4×4 Sylvester matrix of X_ha, X_hb in c3 (eq. 21), as a bivariate array (5, 5):
    (a2 b0 − a0 b2)² − (a2 b1 − a1 b2)(a1 b0 − a0 b1) for X_ha = a2 c3² + a1 c3 + a0, X_hb likewise."""
    a2, a1, a0 = _chi_arrays(f, ha)
    b2, b1, b0 = _chi_arrays(f, hb)
    u = a2 * b0 - b2 * a0
    v = a2 * b1 - b2 * a1
    w = np.zeros((4, 4))
    _conv2_acc(a1, 1, b0, 2, 1.0, w)
    _conv2_acc(a0, 2, b1, 1, -1.0, w)
    out = np.zeros((5, 5))
    _conv2_acc(u, 2, u, 2, 1.0, out)
    _conv2_acc(v, 1, w, 3, -1.0, out)
    return out


@numba.njit(cache=True)
def _conv_acc(a: np.ndarray, na: int, b: np.ndarray, nb: int, sign: float, out: np.ndarray) -> None:
    """out += sign · a * b for univariate arrays of degree na, nb (eq. 27)."""
    for i in range(na + 1):
        x = sign * a[i]
        for k in range(nb + 1):
            out[i + k] += x * b[k]


@numba.njit(cache=True)
def bezout(psi1: np.ndarray, psi2: np.ndarray) -> np.ndarray:
    """Bézout matrix of Ω1 = Ψ1, Ω2 = Ψ2 as quartics in c2 (eq. 23), with entries polynomial in c1:
    (4, 4, 8) ascending; entry (i, j) has degree 7 − i − j. Ω_h's coefficient ω_{h,j} is psi_h[:, j]."""
    B = np.zeros((4, 4, 8))
    m = np.zeros(9)
    for a in range(5):
        for b in range(a):
            m[:] = 0.0   # ω1,a ω2,b − ω1,b ω2,a, degree 8 − a − b
            _conv_acc(psi1[:, a], 4 - a, psi2[:, b], 4 - b, 1.0, m)
            _conv_acc(psi1[:, b], 4 - b, psi2[:, a], 4 - a, -1.0, m)
            for k in range(a - b):
                i, j = b + k, a - 1 - k
                for e in range(8 - a - b + 1):
                    B[i, j, e] += m[e]
    return B


@numba.njit(cache=True)
def lam(psi1: np.ndarray, psi2: np.ndarray) -> np.ndarray:
    """Λ(c1) (eq. 25), 17 coefficients ascending: det of the Bézout matrix by Laplace expansion along
    its first two rows (six 2×2 minors times their complements), each product a convolution."""
    B = bezout(psi1, psi2)
    out = np.zeros(17)
    top = np.zeros(17)
    bottom = np.zeros(17)
    for s0 in range(4):
        for s1 in range(s0 + 1, 4):
            t0, t1 = -1, -1
            for c in range(4):
                if c != s0 and c != s1:
                    if t0 < 0:
                        t0 = c
                    else:
                        t1 = c
            top[:] = 0.0
            bottom[:] = 0.0
            _conv_acc(B[0, s0], 7 - s0, B[1, s1], 6 - s1, 1.0, top)
            _conv_acc(B[0, s1], 7 - s1, B[1, s0], 6 - s0, -1.0, top)
            _conv_acc(B[2, t0], 5 - t0, B[3, t1], 4 - t1, 1.0, bottom)
            _conv_acc(B[2, t1], 5 - t1, B[3, t0], 4 - t0, -1.0, bottom)
            sign = -1.0 if (1 + s0 + s1) % 2 else 1.0
            _conv_acc(top, 13 - s0 - s1, bottom, 9 - t0 - t1, sign, out)
    return out


@numba.njit(cache=True)
def genuine(f: np.ndarray) -> np.ndarray:
    """The genuine octic factor G of Λ (ours, not in the paper), 9 coefficients ascending.

    With L1 = χ5,2·X4 − χ4,2·X5 = α1 c3 + β1 and L2 = χ6,2·X4 − χ4,2·X6 = α2 c3 + β2 (the c3² terms cancel,
    χ_h,2 being constants), a common root of X4, X5, X6 satisfies Q = α1β2 − α2β1 = 0 (a cubic in c1, c2)
    and R = X4(c3 = −β1/α1)·α1² = χ4,2β1² − χ4,1α1β1 + χ4,0α1² = 0 (a quartic). Their resultant in c2 has
    degree 12 and is G·H², H = Res_c2(α1, β1): R vanishes doubly where α1 = β1 = 0 (tests check it against
    SymPy's factorisation of Λ). Only G's roots are solutions, so no extraneous root is ever found."""
    a42, a41, a40 = _chi_arrays(f, 0)
    a52, a51, a50 = _chi_arrays(f, 1)
    a62, a61, a60 = _chi_arrays(f, 2)
    al1, al2 = a52 * a41 - a42 * a51, a62 * a41 - a42 * a61      # linear
    be1, be2 = a52 * a40 - a42 * a50, a62 * a40 - a42 * a60      # quadratic
    Q = np.zeros((5, 5))
    _conv2_acc(al1, 1, be2, 2, 1.0, Q)
    _conv2_acc(al2, 1, be1, 2, -1.0, Q)
    R = np.zeros((5, 5))
    _conv2_acc(be1, 2, be1, 2, a42, R)
    t = np.zeros((3, 3))
    _conv2_acc(a41, 1, al1, 1, 1.0, t)
    _conv2_acc(t, 2, be1, 2, -1.0, R)
    t[:] = 0.0
    _conv2_acc(al1, 1, al1, 1, 1.0, t)
    _conv2_acc(a40, 2, t, 2, 1.0, R)
    P = lam(R, Q)   # det Bez(R, Q) = R's constant leading coefficient × Res_c2(R, Q): degree 12
    # H = Res_c2(α1, β1) for α1 = A0(c1) + A1 c2, β1 = B0(c1) + B1(c1) c2 + B2 c2²: A1² B0 − A1 A0 B1 + A0² B2
    A1, B2 = al1[0, 1], be1[0, 2]
    H = np.zeros(3)
    for i in range(3):
        H[i] += A1 * A1 * be1[i, 0]
    for i in range(2):
        for k in range(2):
            H[i + k] += -A1 * al1[i, 0] * be1[k, 1] + B2 * al1[i, 0] * al1[k, 0]
    H2 = np.zeros(5)
    _conv_acc(H, 2, H, 2, 1.0, H2)
    return _divide(P[:13] / np.max(np.abs(P)), H2 / np.max(np.abs(H2)))


@numba.njit(cache=True)
def _divide(P: np.ndarray, D: np.ndarray) -> np.ndarray:
    """The quotient G of P (13) by D (5), ascending, as the least-squares solution of conv(D, G) = P (Givens
    QR of the banded 13×9 system): long division from either end loses the roots of G near D's."""
    A = np.zeros((13, 10))
    for k in range(9):
        for j in range(5):
            A[k + j, k] = D[j]
    A[:, 9] = P
    for k in range(9):
        for i in range(k + 1, min(k + 5, 13)):
            a, b = A[k, k], A[i, k]
            if b == 0.0:
                continue
            r = np.hypot(a, b)
            c, s = a / r, b / r
            for j in range(k, 10):
                x, y = A[k, j], A[i, j]
                A[k, j] = c * x + s * y
                A[i, j] = -s * x + c * y
    G = np.zeros(9)
    for k in range(8, -1, -1):
        acc = A[k, 9]
        for j in range(k + 1, 9):
            acc -= A[k, j] * G[j]
        G[k] = acc / A[k, k]
    return G


@numba.njit(cache=True)
def polyval(p: np.ndarray, x: float) -> float:
    y = 0.0
    for i in range(p.shape[0] - 1, -1, -1):
        y = y * x + p[i]
    return y


@numba.njit(cache=True)
def omegas(psi_h: np.ndarray, c1: float) -> np.ndarray:
    """ω_{h,j}(c1), j = 0…4 (Appendix C), from Ψ_h's bivariate array."""
    w = np.empty(5)
    for j in range(5):
        w[j] = polyval(psi_h[:, j], c1)
    return w


def system(T: np.ndarray, geo: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For one pose: (φ (3, 10), Ψ1, Ψ2 (5, 5), Λ (17,)), lengths scaled by a2 (for tests and tables)."""
    T = np.asarray(T, dtype=float)
    d1, a2, _, _, d4, d5, d6 = geo
    P6 = T[:3, 3] / a2
    P5 = P6 - d6 / a2 * T[:3, 2]
    f = phi(P5, P6, d1 / a2, d4 / a2, d5 / a2, 1.0)
    p1, p2 = psi(f, 0, 2), psi(f, 1, 2)
    return f, p1, p2, lam(p1, p2)
