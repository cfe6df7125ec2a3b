"""All IK solutions of the CRX from Λ(c1) (Sec. 3–4), compiled with numba; scalar and batched.

Per pose: φ → Ψ1, Ψ2 → Λ (resultant.py); the 16 roots of Λ as companion-matrix eigenvalues (what
`numpy.roots` does), each near-real root polished by Newton on Λ; back-substitution for c2 (the null
vector of Ω1, Ω2's Bézout matrix, i.e. the common root that eq. (29) solves for), c3 (eq. 30) and P4
(eq. 18); both joint configurations of each frame {4} (the q2 / π − q2 doubling of Sec. 4) by the
corrected joint formulas (spec §3.8); then the FK filter that rejects extraneous roots (the paper has
none; Λ carries an extraneous octic factor, erratum) and de-duplication.

Every root and candidate is also reported (`Diagnostics`) for the paper's Tables 2–3. method="octic" roots
Λ's genuine factor alone (resultant.genuine, ours) instead of Λ: no extraneous root, half the degree.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import llvmlite.binding as llvm
import numba
import numpy as np
import scipy.linalg.cython_lapack  # noqa: F401  (loads the LAPACK the kernel calls)
from numba import types
from numba.extending import get_cython_function_address

from pipeline.papers.cobot_6r_ik import resultant as rs
from pipeline.papers.cobot_6r_ik.kinematics import ALPHA, CRX10IAL, Geometry, _link, cayley, fk_into

MAX_ROOTS = 16
MAX_SOLUTIONS = 16   # 8 frame-{4} solutions × 2 twins (Bézout bound of the three quadrics)
# per-root record columns (Diagnostics.records)
# per-root record columns (Diagnostics.records); errors are those of the algebraic candidate, before polishing;
# accepted: 0 rejected, 1 a new solution, 2 a duplicate of one already found
REC = ("c1", "c1_imag", "c2", "c3", "p4x", "p4y", "p4z", "pos_err_a", "rot_err_a", "pos_err_b", "rot_err_b",
       "accepted_a", "accepted_b", "polished_a", "polished_b", "lambda_residual")
R_C1, R_IM, R_C2, R_C3, R_P4, R_EP, R_ER, R_OK, R_POL, R_RES = 0, 1, 2, 3, 4, 7, 8, 11, 13, 15


@dataclass(frozen=True)
class Tolerances:
    """What the paper does not state (spec §6.2); every value is a config key."""

    imag: float = 1e-2        # a root is a real candidate if |Im c1| ≤ imag·max(1, |c1|): far looser than
                              # the spec's 1e-9, because Λ's near-double roots split into complex pairs
    newton: int = 3           # Newton steps polishing each real root on Λ
    polish_position: float = 5e-3   # m: a candidate this close to the pose is polished on the pose …
    polish_rotation: float = 5e-3   # rad: … (Gauss–Newton on the flange pose, geometric Jacobian)
    pose_newton: int = 4      # Gauss–Newton steps at most (0: accept or reject the algebraic candidate as is)
    position: float = 1e-9    # m: FK filter, flange position error of an accepted solution (spec: 1e-6 mm)
    rotation: float = 1e-9    # rad: FK filter, flange rotation error
    duplicate: float = 1e-6   # rad: two solutions are one if every joint differs by less (mod 2π)

    @property
    def array(self) -> np.ndarray:
        return np.array([self.imag, float(self.newton), self.polish_position, self.polish_rotation,
                         float(self.pose_newton), self.position, self.rotation, self.duplicate])


DEFAULT = Tolerances()


# -- compiled kernel ----------------------------------------------------------------------------------


# LAPACK's small-matrix QR (dlahqr) and balancing (dgebal) from SciPy's own LAPACK: the companion matrix is
# already upper Hessenberg, so the reduction that numpy.roots pays for (geev) is skipped.
# Bound by symbol name (not by address), so that the compiled kernels can be cached on disk.
for _name in ("dlahqr", "dgebal"):
    llvm.add_symbol(f"cobot_6r_ik_{_name}", get_cython_function_address("scipy.linalg.cython_lapack", _name))
_dlahqr = types.ExternalFunction("cobot_6r_ik_dlahqr", types.void(*[types.voidptr] * 14))
_dgebal = types.ExternalFunction("cobot_6r_ik_dgebal", types.void(*[types.voidptr] * 8))
_SCALE_ONLY = np.array([ord("S")], dtype=np.uint8)


@numba.njit(cache=True)
def _roots(lam: np.ndarray) -> tuple[np.ndarray, int]:
    """Roots of a polynomial (ascending coefficients, Λ or G) as eigenvalues of its balanced companion
    matrix; leading coefficients below 1e-14 of the largest are dropped (a root at infinity: the Cayley
    singularity of a half-turn of frame {4})."""
    scale = np.max(np.abs(lam))
    n = lam.shape[0] - 1
    while n > 0 and abs(lam[n]) <= 1e-14 * scale:
        n -= 1
    out = np.empty(MAX_ROOTS, np.complex128)
    if n == 0:
        return out, 0
    H = np.zeros((n, n))   # column-major for LAPACK: H[c, r] holds element (r, c)
    for i in range(n):
        H[i, 0] = -lam[n - 1 - i] / lam[n]
    for i in range(n - 1):
        H[i, i + 1] = 1.0
    ints = np.array([0, 0, n, 1, n, n, 1, 0], dtype=np.int32)   # wantt, wantz, n, ilo, ihi, ldh, one, info
    d = np.empty(n)
    _dgebal(_SCALE_ONLY.ctypes, ints[2:].ctypes, H.ctypes, ints[5:].ctypes, ints[3:].ctypes, ints[4:].ctypes,
            d.ctypes, ints[7:].ctypes)
    wr, wi, z = np.empty(n), np.empty(n), np.zeros(1)
    _dlahqr(ints[0:].ctypes, ints[1:].ctypes, ints[2:].ctypes, ints[3:].ctypes, ints[4:].ctypes, H.ctypes,
            ints[5:].ctypes, wr.ctypes, wi.ctypes, ints[6:].ctypes, ints[6:].ctypes, z.ctypes, ints[6:].ctypes,
            ints[7:].ctypes)
    if ints[7] != 0:   # QR did not converge: fall back to the full eigen-solver
        M = np.zeros((n, n), np.complex128)
        for i in range(n):
            M[0, i] = -lam[n - 1 - i] / lam[n]
        for i in range(n - 1):
            M[i + 1, i] = 1.0
        out[:n] = np.linalg.eigvals(M)
        return out, n
    for i in range(n):
        out[i] = complex(wr[i], wi[i])
    return out, n


@numba.njit(cache=True)
def _polish(lam: np.ndarray, x: float, steps: int) -> float:
    """Newton on the polynomial from x; a step is kept only if it lowers its modulus."""
    fx = abs(rs.polyval(lam, x))
    for _ in range(steps):
        p, dp = 0.0, 0.0
        for i in range(lam.shape[0] - 1, -1, -1):
            dp = dp * x + p
            p = p * x + lam[i]
        if dp == 0.0:
            break
        x1 = x - p / dp
        f1 = abs(rs.polyval(lam, x1))
        if not f1 < fx:
            break
        x, fx = x1, f1
    return x


@numba.njit(cache=True)
def _common_c2(psi1: np.ndarray, psi2: np.ndarray, c1: float) -> float:
    """The common root c2 of Ω1, Ω2 at c1 (what eq. 29 solves for): the Bézout matrix B(c1) has the null
    vector (1, c2, c2², c2³); taken as the adjugate column of largest norm, read at its better-scaled end."""
    w1, w2 = rs.omegas(psi1, c1), rs.omegas(psi2, c1)
    B = np.zeros((4, 4))
    for a in range(5):
        for b in range(a):
            m = w1[a] * w2[b] - w1[b] * w2[a]
            for k in range(a - b):
                B[b + k, a - 1 - k] += m
    best, v = -1.0, np.zeros(4)
    col = np.empty(4)
    idx = np.empty(3, np.int64)
    jdx = np.empty(3, np.int64)
    for j in range(4):   # column j of adj(B): cofactors C[j, i] for i = 0..3
        for i in range(4):
            r = 0
            for rr in range(4):
                if rr != j:
                    idx[r] = rr
                    r += 1
            c = 0
            for cc in range(4):
                if cc != i:
                    jdx[c] = cc
                    c += 1
            m = (B[idx[0], jdx[0]] * (B[idx[1], jdx[1]] * B[idx[2], jdx[2]] - B[idx[1], jdx[2]] * B[idx[2], jdx[1]])
                 - B[idx[0], jdx[1]] * (B[idx[1], jdx[0]] * B[idx[2], jdx[2]] - B[idx[1], jdx[2]] * B[idx[2], jdx[0]])
                 + B[idx[0], jdx[2]] * (B[idx[1], jdx[0]] * B[idx[2], jdx[1]] - B[idx[1], jdx[1]] * B[idx[2], jdx[0]]))
            col[i] = m if (i + j) % 2 == 0 else -m
        norm = col[0] * col[0] + col[1] * col[1] + col[2] * col[2] + col[3] * col[3]
        if norm > best:
            best = norm
            v[:] = col
    if abs(v[0]) >= abs(v[3]):
        return v[1] / v[0]
    return v[3] / v[2]


@numba.njit(cache=True)
def _c3(f: np.ndarray, c1: float, c2: float) -> float:
    """c3 from two of X4, X5, X6 (eq. 30 uses X4, X5): the linear system in (c3², c3) of the pair whose
    2×2 matrix is best conditioned. For a genuine root every pair gives the same c3."""
    x = np.empty((3, 3))
    for h in range(3):
        x[h, 0], x[h, 1], x[h, 2] = rs.chi(f, h, c1, c2)
    best, c3 = -1.0, 0.0
    for a, b in ((0, 1), (0, 2), (1, 2)):
        det = x[a, 0] * x[b, 1] - x[b, 0] * x[a, 1]
        norm = (abs(x[a, 0]) + abs(x[a, 1])) * (abs(x[b, 0]) + abs(x[b, 1]))
        if norm > 0.0 and abs(det) / norm > best:
            best = abs(det) / norm
            c3 = (x[a, 0] * -x[b, 2] - x[b, 0] * -x[a, 2]) / det
    return c3


@numba.njit(cache=True)
def _rz_rx(R: np.ndarray, q: float, alpha: float) -> np.ndarray:
    """R · Rz(q) · Rx(α)."""
    cq, sq, ca, sa = np.cos(q), np.sin(q), np.cos(alpha), np.sin(alpha)
    out = np.empty((3, 3))
    for r in range(3):
        x = R[r, 0] * cq + R[r, 1] * sq
        y = -R[r, 0] * sq + R[r, 1] * cq
        out[r, 0] = x
        out[r, 1] = y * ca + R[r, 2] * sa
        out[r, 2] = -y * sa + R[r, 2] * ca
    return out


@numba.njit(cache=True)
def _wrap(x: float) -> float:
    return pi - np.remainder(pi - x, 2 * pi)


@numba.njit(cache=True)
def _joints(R4: np.ndarray, P3: np.ndarray, R6: np.ndarray, d1: float, a2: float, twin: int, q: np.ndarray) -> bool:
    """q1…q6 of one twin from frame {4} (spec §3.8, replacing Appendix E's garbled forms); False where
    q1 is undefined (P3 on the z0 axis, cos q2 = 0)."""
    s2 = min(1.0, max(-1.0, (P3[2] - d1) / a2))
    q2 = np.arcsin(s2)                                   # Appendix E with (P3z − P1z), erratum
    if twin:
        q2 = pi - q2
    c2 = np.cos(q2)
    if abs(c2) < 1e-12:
        return False
    q1 = np.arctan2(P3[1] / c2, P3[0] / c2)
    eye = np.eye(3)
    R2 = _rz_rx(_rz_rx(eye, q1, ALPHA[0]), q2, ALPHA[1])
    # z3 = −y4; in frame 2 it is (−sin q3, cos q3, 0)
    v0 = -(R2[0, 0] * R4[0, 1] + R2[1, 0] * R4[1, 1] + R2[2, 0] * R4[2, 1])
    v1 = -(R2[0, 1] * R4[0, 1] + R2[1, 1] * R4[1, 1] + R2[2, 1] * R4[2, 1])
    q3 = np.arctan2(-v0, v1)
    R3 = _rz_rx(R2, q3, ALPHA[2])
    # R3ᵀ R4 = Rz(q4) Rx(−π/2): its first column is (cos q4, sin q4, 0)
    q4 = np.arctan2(R3[0, 1] * R4[0, 0] + R3[1, 1] * R4[1, 0] + R3[2, 1] * R4[2, 0],
                    R3[0, 0] * R4[0, 0] + R3[1, 0] * R4[1, 0] + R3[2, 0] * R4[2, 0])
    # R4ᵀ R6 = Rz(q5) Rx(π/2) Rz(q6): its third column is (sin q5, −cos q5, 0)
    R46 = R4.T @ R6
    q5 = np.arctan2(R46[0, 2], -R46[1, 2])
    R56 = _rz_rx(np.eye(3), q5, ALPHA[4]).T @ R46        # = Rz(q6)
    q6 = np.arctan2(R56[1, 0], R56[0, 0])
    q[0], q[1], q[2], q[3], q[4], q[5] = _wrap(q1), _wrap(q2), _wrap(q3), _wrap(q4), q5, q6
    return True


@numba.njit(cache=True)
def pose_error(q: np.ndarray, geo: np.ndarray, T: np.ndarray, work: np.ndarray) -> tuple[float, float]:
    """(position error in m, rotation angle in rad) of FK(q) against T."""
    fk_into(q, geo, work)
    dp = 0.0
    dr = 0.0
    for r in range(3):
        dp += (work[r, 3] - T[r, 3]) ** 2
        for c in range(3):
            dr += (work[r, c] - T[r, c]) ** 2
    # ‖R1 − R2‖_F = 2√2 sin(θ/2)
    return np.sqrt(dp), 2.0 * np.arcsin(min(1.0, np.sqrt(dr) / (2.0 * np.sqrt(2.0))))


@numba.njit(cache=True)
def pose_residual(q: np.ndarray, geo: np.ndarray, T: np.ndarray, J: np.ndarray, e: np.ndarray) -> None:
    """Geometric Jacobian J (6, 6) of the flange at q and the pose error e (6,) = (Δp, rotation vector)
    still to go from FK(q) to T, both in the base frame."""
    F = np.eye(4)
    z = np.empty((6, 3))
    p = np.empty((6, 3))
    d = (geo[0], geo[2], geo[3], geo[4], geo[5], geo[6])
    a = (0.0, geo[1], 0.0, 0.0, 0.0, 0.0)
    for i in range(6):
        z[i] = F[:3, 2]
        p[i] = F[:3, 3]
        _link(F, q[i], d[i], a[i], ALPHA[i])
    for i in range(6):
        r = F[:3, 3] - p[i]
        J[0, i] = z[i, 1] * r[2] - z[i, 2] * r[1]
        J[1, i] = z[i, 2] * r[0] - z[i, 0] * r[2]
        J[2, i] = z[i, 0] * r[1] - z[i, 1] * r[0]
        J[3, i], J[4, i], J[5, i] = z[i, 0], z[i, 1], z[i, 2]
    E = np.empty((3, 3))   # R_T R_Fᵀ, written out: `@` on the 4x4s' 3x3 blocks (strided) takes Numba's slow path
    for i in range(3):
        e[i] = T[i, 3] - F[i, 3]
        for j in range(3):
            E[i, j] = T[i, 0] * F[j, 0] + T[i, 1] * F[j, 1] + T[i, 2] * F[j, 2]
    e[3], e[4], e[5] = 0.5 * (E[2, 1] - E[1, 2]), 0.5 * (E[0, 2] - E[2, 0]), 0.5 * (E[1, 0] - E[0, 1])


@numba.njit(cache=True)
def polish_pose(q: np.ndarray, geo: np.ndarray, T: np.ndarray, steps: int, pos_tol: float, rot_tol: float,
                work: np.ndarray) -> tuple[float, float]:
    """Gauss–Newton on the flange pose from q (in place); returns the final (position, rotation) error."""
    ep, er = pose_error(q, geo, T, work)
    J = np.empty((6, 6))
    e = np.empty(6)
    for _ in range(steps):
        if ep <= pos_tol and er <= rot_tol:
            break
        pose_residual(q, geo, T, J, e)
        q += np.linalg.solve(J, e)
        for i in range(6):
            q[i] = _wrap(q[i])
        ep, er = pose_error(q, geo, T, work)
    return ep, er


@numba.njit(cache=True)
def solve_pose(T: np.ndarray, geo: np.ndarray, tol: np.ndarray, octic: bool, q_out: np.ndarray, roots: np.ndarray,
               records: np.ndarray) -> tuple[int, int, int]:
    """All solutions of one pose into q_out (16, 6); every root of Λ (octic: of its genuine factor G) into
    roots (16,) and one record per real candidate into records (16, len(REC)). Returns (solutions, roots,
    real candidates)."""
    d1, a2, d4, d5, d6 = geo[0], geo[1], geo[4], geo[5], geo[6]
    P6 = T[:3, 3] / a2
    P5 = np.empty(3)
    for i in range(3):
        P5[i] = P6[i] - d6 / a2 * T[i, 2]
    f = rs.phi(P5, P6, d1 / a2, d4 / a2, d5 / a2, 1.0)
    psi1, psi2 = rs.psi(f, 0, 2), rs.psi(f, 1, 2)
    lam = rs.genuine(f) if octic else rs.lam(psi1, psi2)
    lam = lam / np.max(np.abs(lam))
    r, n = _roots(lam)
    roots[:n] = r[:n]
    R6 = np.ascontiguousarray(T[:3, :3])
    work = np.empty((4, 4))
    q = np.empty(6)
    n_sol = 0
    n_cand = 0
    for k in range(n):
        x = r[k]
        if abs(x.imag) > tol[0] * max(1.0, abs(x.real)):
            continue
        rec = records[n_cand]
        rec[:] = np.nan
        rec[R_IM] = x.imag
        c1 = _polish(lam, x.real, int(tol[1]))
        rec[R_C1] = c1
        rec[R_RES] = abs(rs.polyval(lam, c1))
        c2 = _common_c2(psi1, psi2, c1)
        c3 = _c3(f, c1, c2)
        s = 1.0 + c1 * c1 + c2 * c2 + c3 * c3
        R4 = np.empty((3, 3))   # eq. (6)
        R4[0, 0], R4[0, 1], R4[0, 2] = c1 * c1 - c2 * c2 - c3 * c3 + 1, 2 * c1 * c2 - 2 * c3, 2 * c2 + 2 * c1 * c3
        R4[1, 0], R4[1, 1], R4[1, 2] = 2 * c3 + 2 * c1 * c2, -c1 * c1 + c2 * c2 - c3 * c3 + 1, 2 * c2 * c3 - 2 * c1
        R4[2, 0], R4[2, 1], R4[2, 2] = 2 * c1 * c3 - 2 * c2, 2 * c1 + 2 * c2 * c3, -c1 * c1 - c2 * c2 + c3 * c3 + 1
        R4 /= s
        P4 = np.empty(3)
        P3 = np.empty(3)
        for i in range(3):
            P4[i] = T[i, 3] - d6 * T[i, 2] - d5 * R4[i, 2]   # eq. (18): P4 = P5 − d5 z4
            P3[i] = P4[i] + d4 * R4[i, 1]                    # P3 = P4 + R4 (0, d4, 0)
        rec[R_C2], rec[R_C3] = c2, c3
        rec[R_P4], rec[R_P4 + 1], rec[R_P4 + 2] = P4[0], P4[1], P4[2]
        rec[R_OK], rec[R_OK + 1], rec[R_POL], rec[R_POL + 1] = 0.0, 0.0, 0.0, 0.0
        n_cand += 1
        if not _joints(R4, P3, R6, d1, a2, 0, q):
            continue
        # the twin (q2 -> π − q2) shares frame {4} and reaches the same flange pose: one FK check serves both
        ep, er = pose_error(q, geo, T, work)
        rec[R_EP], rec[R_ER], rec[R_EP + 2], rec[R_ER + 2] = ep, er, ep, er
        if (ep > tol[5] or er > tol[6]) and ep <= tol[2] and er <= tol[3] and tol[4] > 0:
            ep, er = polish_pose(q, geo, T, int(tol[4]), tol[5], tol[6], work)
            rec[R_POL], rec[R_POL + 1] = 1.0, 1.0
        if ep > tol[5] or er > tol[6]:
            continue
        for twin in range(2):
            if twin:
                q[0], q[1], q[2], q[3] = _wrap(q[0] + pi), _wrap(pi - q[1]), _wrap(pi - q[2]), _wrap(q[3] + pi)
            duplicate = False
            for s_ in range(n_sol):
                same = True
                for j in range(6):
                    if abs(_wrap(q_out[s_, j] - q[j])) >= tol[7]:
                        same = False
                        break
                if same:
                    duplicate = True
                    break
            rec[R_OK + twin] = 2.0 if duplicate else 1.0
            if not duplicate and n_sol < MAX_SOLUTIONS:
                q_out[n_sol] = q
                n_sol += 1
    return n_sol, n, n_cand


@numba.njit(cache=True)
def solve_many(T: np.ndarray, geo: np.ndarray, tol: np.ndarray, octic: bool, q_out: np.ndarray,
               counts: np.ndarray) -> None:
    roots = np.empty(MAX_ROOTS, np.complex128)
    records = np.empty((MAX_ROOTS, len(REC)))
    for i in range(T.shape[0]):
        counts[i] = solve_pose(T[i], geo, tol, octic, q_out[i], roots, records)[0]


# -- Python API ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Diagnostics:
    """Everything one pose's solve went through (Tables 2–3)."""

    q: np.ndarray          # (k, 6) accepted solutions, rad
    roots: np.ndarray      # (n,) complex roots of Λ
    records: np.ndarray    # (m, len(REC)) one row per real candidate root, columns REC (SI units)
    lam: np.ndarray        # Λ's (17) or G's (9) coefficients, ascending, lengths scaled by a2, max 1


def _pose(T) -> np.ndarray:
    T = np.ascontiguousarray(T, dtype=float)
    if T.shape != (4, 4) or not np.isfinite(T).all():
        raise ValueError(f"T must be a finite 4×4 homogeneous transform, got shape {T.shape}")
    return T


METHODS = ("lambda16", "octic")


def _octic(method: str) -> bool:
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, not {method!r}")
    return method == "octic"


def solve(T, g: Geometry = CRX10IAL, tol: Tolerances = DEFAULT, method: str = "lambda16") -> np.ndarray:
    """Every solution of pose T: (k, 6), k ≤ 16, angles in (−π, π]. method: "lambda16" (the paper's Λ, with
    the FK filter rejecting its extraneous roots) or "octic" (its genuine factor G only, ours)."""
    q = np.empty((MAX_SOLUTIONS, 6))
    roots = np.empty(MAX_ROOTS, np.complex128)
    records = np.empty((MAX_ROOTS, len(REC)))
    k = solve_pose(_pose(T), g.array, tol.array, _octic(method), q, roots, records)[0]
    return q[:k].copy()


def diagnose(T, g: Geometry = CRX10IAL, tol: Tolerances = DEFAULT, method: str = "lambda16") -> Diagnostics:
    q = np.empty((MAX_SOLUTIONS, 6))
    roots = np.empty(MAX_ROOTS, np.complex128)
    records = np.empty((MAX_ROOTS, len(REC)))
    T = _pose(T)
    k, n, m = solve_pose(T, g.array, tol.array, _octic(method), q, roots, records)
    f, _, _, lam = rs.system(T, g.array)
    if method == "octic":
        lam = rs.genuine(f)
    return Diagnostics(q[:k].copy(), roots[:n].copy(), records[:m].copy(), lam / np.max(np.abs(lam)))


def candidate_joints(T, g: Geometry, c: np.ndarray) -> np.ndarray:
    """Both joint configurations (2, 6) of the frame {4} given by Cayley parameters c (NaN where undefined),
    as the solver builds them, before any filter or polishing."""
    T = _pose(T)
    c1, c2, c3 = (float(x) for x in c)
    R4 = np.ascontiguousarray(cayley([c1, c2, c3]))
    P4 = T[:3, 3] - g.d6 * T[:3, 2] - g.d5 * R4[:, 2]
    P3 = P4 + g.d4 * R4[:, 1]
    out = np.full((2, 6), np.nan)
    for twin in range(2):
        q = np.empty(6)
        if _joints(R4, P3, np.ascontiguousarray(T[:3, :3]), g.d1, g.a2, twin, q):
            out[twin] = q
    return out


def solve_batch(T, g: Geometry = CRX10IAL, tol: Tolerances = DEFAULT,
                method: str = "lambda16") -> tuple[np.ndarray, np.ndarray]:
    """Many poses: T (N, 4, 4) -> (q (N, 16, 6) NaN-padded, counts (N,))."""
    T = np.ascontiguousarray(T, dtype=float)
    if T.ndim != 3 or T.shape[1:] != (4, 4) or not np.isfinite(T).all():
        raise ValueError(f"T must be finite 4×4 transforms of shape (N, 4, 4), got {T.shape}")
    q = np.full((len(T), MAX_SOLUTIONS, 6), np.nan)
    counts = np.zeros(len(T), dtype=np.int64)
    solve_many(T, g.array, tol.array, _octic(method), q, counts)
    return q, counts
