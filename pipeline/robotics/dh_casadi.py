"""Standard DH kinematics as CasADi expressions: the symbolic twin of `dh.py`, for optimal control.

Same convention, ^{i-1}T_i = Rz(θ_i + θ_offset_i) · Tz(d_i) · Tx(a_i) · Rx(α_i); works on SX and MX.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from pipeline.robotics.dh import DH


def link_transform(theta, d: float, a: float, alpha: float):
    """^{i-1}T_i of one link as a 4×4 CasADi expression (θ symbolic, the rest numbers)."""
    ct, st = ca.cos(theta), ca.sin(theta)
    c_alpha, s_alpha = float(np.cos(alpha)), float(np.sin(alpha))
    return ca.vertcat(
        ca.horzcat(ct, -st * c_alpha, st * s_alpha, a * ct),
        ca.horzcat(st, ct * c_alpha, -ct * s_alpha, a * st),
        ca.horzcat(0, s_alpha, c_alpha, d),
        ca.horzcat(0, 0, 0, 1),
    )


def frames(dh: DH, q, base: np.ndarray | None = None) -> list:
    """[base, base·^0T_1, …, base·^0T_n]: the n+1 frame poses (base = identity by default)."""
    T = ca.DM(np.eye(4) if base is None else base)
    out = [T]
    for i in range(dh.n):
        T = T @ link_transform(q[i] + dh.theta_offset[i], dh.d[i], dh.a[i], dh.alpha[i])
        out.append(T)
    return out


def geometric_jacobian(dh: DH, q, base: np.ndarray | None = None, tool: np.ndarray | None = None):
    """(6, n): [linear; angular] velocity of the point p_n = origin of (last frame · tool);
    column i = [z_{i-1} × (p_n − p_{i-1}); z_{i-1}]."""
    F = frames(dh, q, base)
    p_n = (F[-1] @ ca.DM(np.eye(4) if tool is None else tool))[:3, 3]
    cols = [ca.vertcat(ca.cross(F[i][:3, 2], p_n - F[i][:3, 3]), F[i][:3, 2]) for i in range(dh.n)]
    return ca.horzcat(*cols)
