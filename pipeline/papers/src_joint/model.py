"""The paper's SRC joint model (Sec. II) and the kinematics of the SRC joint manipulator (Sec. III-A).

Quaternions are scalar-first [η, ε] with the Hamilton product; R(q) is eq. (74). Per joint i the state is
q_{i,1} (B_i relative to the tangent plane P_i, R(q_{i,1}) = ^{P_i}R_{B_i}) and q_{i-1,2} (B_{i-1}
relative to P_i, R(q_{i-1,2}) = ^{P_i}R_{B_{i-1}}); the joint rotation is q_i = conj(q_{i-1,2}) ⊗ q_{i,1}
(eq. 6). The joint velocity w_i = [ω_x, ω_y] is the angular velocity of B_i relative to B_{i-1} expressed
in P_i (eq. 1); Ω^B = ^{P_i}ω_{B_i} and Ω^A = ^{P_i}ω_{B_{i-1}} are the bodies' rates relative to P_i.

Two printed forms change results and are selectable (`ModelForm`):
- radius convention. Rolling without slip traces the same arc on both spheres, so l_i θ_{i,1} = l_{i-1}
  θ_{i-1,2}; the paper prints the reverse in (4) and hence l_i and l_{i-1} swapped in (1), (5), (13)-(16).
  Both forms agree for equal radii (every manipulator of the paper) and differ for the joint of Sec. V-A.
- sign of the linear free modes: eq. (16) prints −l f3^× f_k, Table I prints +l f3^× f_k.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CONVENTIONS = ("corrected", "printed")
JOINT_UPDATES = ("incremental", "global")


# -- quaternions (scalar first), batched over leading axes ----------------------------------------------


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b over the last axis (np.cross costs 10x more on the small arrays used here)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def _hamilton(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return np.array([pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw])


# p ⊗ q is bilinear: (p ⊗ q)_k = Σ_ab p_a q_b HAMILTON[a, b, k]. One einsum on the table is 5x faster on the
# small arrays used here than the sixteen products written out.
HAMILTON = np.array([[_hamilton(a, b) for b in np.eye(4)] for a in np.eye(4)])


def qmul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product p ⊗ q."""
    return np.einsum("...a,abk,...b->...k", p, HAMILTON, q)


def qconj(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def qexp(rotvec: np.ndarray) -> np.ndarray:
    """Unit quaternion of the rotation θ·ê given as the vector θ ê (eq. 73)."""
    theta = np.linalg.norm(rotvec, axis=-1, keepdims=True)
    half = 0.5 * theta
    # sin(θ/2)/θ, with its series below 1e-8 rad where the quotient loses digits
    scale = np.where(theta > 1e-8, np.sin(half) / np.where(theta > 1e-8, theta, 1.0), 0.5 - theta ** 2 / 48)
    return np.concatenate([np.cos(half), scale * rotvec], axis=-1)


def qlog(q: np.ndarray) -> np.ndarray:
    """θ ê of a unit quaternion (eq. 72, Δθ = 2 acos Δη and ê = Δε / sin(Δθ/2)), θ in [0, 2π)."""
    vec = q[..., 1:]
    s = np.linalg.norm(vec, axis=-1, keepdims=True)
    theta = 2.0 * np.arctan2(s, q[..., :1])  # = 2 acos(η) without its loss of digits near η = ±1
    return np.where(s > 1e-12, theta / np.where(s > 1e-12, s, 1.0), 2.0) * vec


def _rotation_eq74(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


# Eq. (74) is I plus a quadratic form in q: R_ij = δ_ij + Σ_ab q_a q_b QUADRATIC[a, b, i, j], the coefficients
# read off the printed entries once.
_E = np.eye(4)
QUADRATIC = np.array([[(_rotation_eq74(_E[a] + _E[b]) - _rotation_eq74(_E[a]) - _rotation_eq74(_E[b]) + np.eye(3)) / 2
                       if a != b else _rotation_eq74(_E[a]) - np.eye(3) for b in range(4)] for a in range(4)])


def rotation(q: np.ndarray) -> np.ndarray:
    """R(q), eq. (74); (..., 3, 3)."""
    return np.eye(3) + np.einsum("...a,abij,...b->...ij", q, QUADRATIC, q)


def _scaled_quaternions(R: np.ndarray) -> np.ndarray:
    """Row k: 4 q_k · q for k = η, ε_x, ε_y, ε_z (Shepperd), written out for one matrix."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = R
    return np.array([[1 + m00 + m11 + m22, m21 - m12, m02 - m20, m10 - m01],
                     [m21 - m12, 1 + m00 - m11 - m22, m10 + m01, m02 + m20],
                     [m02 - m20, m10 + m01, 1 - m00 + m11 - m22, m21 + m12],
                     [m10 - m01, m02 + m20, m21 + m12, 1 - m00 - m11 + m22]])


# the rows are affine in R: I_4 plus a table applied to R's entries (one einsum instead of sixteen sums)
_CONSTANT = _scaled_quaternions(np.zeros((3, 3)))
_SHEPPERD = np.array([[_scaled_quaternions(basis.reshape(3, 3)) - _CONSTANT for basis in row]
                      for row in np.eye(9).reshape(3, 3, 9)])


def quaternion_of(R: np.ndarray) -> np.ndarray:
    """The unit quaternion (η ≥ 0) of rotation matrices (..., 3, 3), the inverse of eq. (74): the row of the
    largest |q_k| of `_scaled_quaternions` (Shepperd's method), normalised."""
    rows = _CONSTANT + np.einsum("...ij,ijkl->...kl", R, _SHEPPERD)
    best = np.argmax(np.diagonal(rows, axis1=-2, axis2=-1), axis=-1)
    q = np.take_along_axis(rows, best[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def skew(v: np.ndarray) -> np.ndarray:
    """v^×, the cross-product matrix; (..., 3, 3)."""
    S = np.zeros((*v.shape[:-1], 3, 3))
    S[..., 0, 1], S[..., 0, 2], S[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    S[..., 1, 0], S[..., 2, 0], S[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    return S


# -- the joint ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ModelForm:
    """Which printed form of the model is used (see the module docstring)."""

    radius_convention: str = "corrected"   # corrected | printed: eqs. (1), (4), (5), (13)-(16)
    free_mode_sign: str = "corrected"      # corrected: eq. (16), −l f3^× f | printed: Table I, +l f3^× f
    joint_update: str = "incremental"      # incremental: eq. (5) per step | global: eq. (5) on Δq since t_0

    def __post_init__(self) -> None:
        for name, allowed in (("radius_convention", CONVENTIONS), ("free_mode_sign", CONVENTIONS),
                              ("joint_update", JOINT_UPDATES)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name}={getattr(self, name)!r}: must be one of {allowed}")


CORRECTED = ModelForm()


def rolling_factors(lower: np.ndarray, upper: np.ndarray, form: ModelForm) -> tuple[np.ndarray, np.ndarray]:
    """(k_B, k_A) with Ω^B = k_B w and Ω^A = −k_A Ω^B for spheres l_{i-1} = lower, l_i = upper."""
    if form.radius_convention == "corrected":
        # eq. (1) corrected: w = (l_i + l_{i-1}) / l_{i-1} Ω^B;  eq. (5) corrected: Ω^A = −(l_i / l_{i-1}) Ω^B
        return lower / (lower + upper), upper / lower
    return upper / (lower + upper), lower / upper  # eqs. (1), (5) as printed


def rolling_radius(lower: np.ndarray, upper: np.ndarray, form: ModelForm) -> np.ndarray:
    """The lever of the linear free modes: l_i (corrected eq. 14) or l_{i-1} (printed eqs. 14-16)."""
    return upper if form.radius_convention == "corrected" else lower


class Chain:
    """n SRC joints in series on a fixed base B_0 (^I R_{B_0} = I, ^I r_{B_0} = 0, Table II).

    `radii` are l_0 … l_n. The joint state starts at `q1`, `q2` (identity: every frame aligned, Table II)."""

    def __init__(self, radii, form: ModelForm = CORRECTED, q1: np.ndarray | None = None,
                 q2: np.ndarray | None = None):
        self.radii = np.asarray(radii, dtype=float)
        self.n = len(self.radii) - 1
        self.form = form
        identity = np.tile([1.0, 0.0, 0.0, 0.0], (self.n, 1))
        self.q1 = identity.copy() if q1 is None else np.array(q1, dtype=float)
        self.q2 = identity.copy() if q2 is None else np.array(q2, dtype=float)
        self._q1_start, self._q2_start = self.q1.copy(), self.q2.copy()
        self.k_b, self.k_a = rolling_factors(self.radii[:-1], self.radii[1:], form)
        self.lever = rolling_radius(self.radii[:-1], self.radii[1:], form)
        self.sign = -1.0 if form.free_mode_sign == "corrected" else 1.0

    def copy(self) -> Chain:
        c = Chain(self.radii, self.form, self.q1, self.q2)
        c._q1_start, c._q2_start = self._q1_start.copy(), self._q2_start.copy()
        return c

    # -- state update ------------------------------------------------------------------------------
    def roll(self, omega_b: np.ndarray, dt: float) -> None:
        """Advance by dt with tangent-plane rates Ω^B (n, 2) held constant: eq. (2), then eq. (5)."""
        omega = np.zeros((self.n, 3))
        omega[:, :2] = omega_b
        if self.form.joint_update == "incremental":
            # eq. (2) for B_i, exact for constant Ω^B, and eq. (5) applied per step for B_{i-1}: Ω^A = −k_A Ω^B
            turn = qexp(np.concatenate([omega, -self.k_a[:, None] * omega]) * dt)
            both = _normalized(qmul(turn, np.concatenate([self.q1, self.q2])))
            self.q1, self.q2 = both[:self.n], both[self.n:]
        else:
            self.q1 = _normalized(qmul(qexp(omega * dt), self.q1))           # eq. (2)
            # eq. (5) on the whole displacement since t_0: Δq_{i,1} = q_{i,1}(t) ⊗ conj(q_{i,1}(t_0))
            dtheta = qlog(qmul(self.q1, qconj(self._q1_start)))              # eq. (72)
            self.q2 = qmul(qexp(-self.k_a[:, None] * dtheta), self._q2_start)  # eq. (73), then q(t)=Δq⊗q(t_0)

    def move(self, w: np.ndarray, dt: float) -> None:
        """Advance by dt at joint velocities w (n, 2), held constant (eq. 1 gives Ω^B)."""
        self.roll(self.k_b[:, None] * np.asarray(w, dtype=float).reshape(self.n, 2), dt)

    # -- joint elements (Table I) ------------------------------------------------------------------
    def joint_quaternions(self) -> np.ndarray:
        """q_i = conj(q_{i-1,2}) ⊗ q_{i,1}, eq. (6); (n, 4)."""
        return qmul(qconj(self.q2), self.q1)

    def tangent_frames(self) -> np.ndarray:
        """^{B_{i-1}}R_{P_i} = [f1 f2 f3](q_{i-1,2}), eqs. (10), (75)-(77): the transpose of R(q_{i-1,2})."""
        return np.swapaxes(rotation(self.q2), -1, -2)

    def free_modes(self, F: np.ndarray | None = None) -> np.ndarray:
        """Φ_i (n, 6, 2), eq. (16): [f1 f2; ∓ l f3^× f1, ∓ l f3^× f2], expressed in B_{i-1}."""
        F = self.tangent_frames() if F is None else F
        linear = self.sign * self.lever[:, None, None] * (skew(F[..., 2]) @ F[..., :2])   # f3^× [f1 f2]
        return np.concatenate([F[..., :2], linear], axis=-2)

    # -- manipulator (Sec. III-A) ------------------------------------------------------------------
    def frames(self, F: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(positions (n+1, 3), rotations (n+1, 3, 3)) of B_0 … B_n in ΣI, eqs. (17), (26)."""
        R_joint = rotation(self.joint_quaternions())
        F = self.tangent_frames() if F is None else F
        span = self.radii[:-1] + self.radii[1:]
        pos = np.zeros((self.n + 1, 3))
        rot = np.empty((self.n + 1, 3, 3))
        rot[0] = np.eye(3)
        for i in range(self.n):
            pos[i + 1] = pos[i] + rot[i] @ (span[i] * F[i, :, 2])   # eq. (7) in B_{i-1}: (l_i + l_{i-1}) f3
            rot[i + 1] = rot[i] @ R_joint[i]
        return pos, rot

    def jacobians(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(J_v (n+1, 3, 2n), J_ω (n+1, 3, 2n), positions, rotations): J_{B_k v}, J_{B_k ω} of every body.

        Eqs. (24), (31), (32) with the lever vectors in ΣI: J_{B_k v} = J'_{B_k v} − Σ_{i≤k} d_i^× J_{B_{i-1}ω},
        d_i = ^I r_{B_i} − ^I r_{B_{i-1}} (the printed (32)/(34)/(36) use other frames' vectors)."""
        F = self.tangent_frames()
        pos, rot = self.frames(F)
        phi = self.free_modes(F)
        n = self.n
        Jv = np.zeros((n + 1, 3, 2 * n))
        Jw = np.zeros((n + 1, 3, 2 * n))
        for i in range(n):
            cols = slice(2 * i, 2 * i + 2)
            Jw[i + 1] = Jw[i]
            Jw[i + 1][:, cols] = rot[i] @ phi[i, :3]                            # eq. (24)
            Jv[i + 1] = Jv[i] - skew(pos[i + 1] - pos[i]) @ Jw[i]               # eq. (32), lever term
            Jv[i + 1][:, cols] += rot[i] @ phi[i, 3:]                           # eq. (31)
        return Jv, Jw, pos, rot

    def orientation(self) -> np.ndarray:
        """q_{n,I} = q_1 ⊗ … ⊗ q_n, the quaternion of ^I R_{B_n} (eq. 17 with ^I R_{B_0} = I)."""
        q = self.joint_quaternions()
        out = q[0]
        for k in range(1, self.n):
            out = qmul(out, q[k])
        return out

    def jacobian(self) -> np.ndarray:
        """J_{B_n} = [J_{B_n v}; J_{B_n ω}] (6, 2n), eq. (38) with the stacking corrected."""
        Jv, Jw, _, _ = self.jacobians()
        return np.vstack([Jv[-1], Jw[-1]])


def _normalized(q: np.ndarray) -> np.ndarray:
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quaternion_error(q: np.ndarray, q_desired: np.ndarray) -> np.ndarray:
    """δ = η ε^d − η^d ε − ε^d × ε, eq. (47)."""
    return q[0] * q_desired[1:] - q_desired[0] * q[1:] - cross(q_desired[1:], q[1:])
