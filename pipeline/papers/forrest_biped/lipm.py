"""The simplified model the full simulation is compared with: a point mass on the LIP (eq. 39) under the CP
controller of eq. (50), its ZMP clamped to the support polygon, with no whole body, no contacts and no QP.

Every controller cycle the commanded ZMP p^c is held for dt (zero-order hold) and the LIP is advanced in closed
form (eq. 45 with k = 0), so the only approximations are the hold and, optionally, a first-order lag of the
realised ZMP behind p^c (`zmp_lag`, s): a real foot cannot move its CoP instantly, and the generators differ
exactly in how fast their ZMP moves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.forrest_biped.generator import Pattern
from pipeline.papers.forrest_biped.support import clamp


@dataclass(frozen=True)
class LipmLog:
    t: np.ndarray
    com: np.ndarray       # (n, 3) m
    com_vel: np.ndarray   # (n, 3) m/s
    cp: np.ndarray        # (n, 3)
    zmp_cmd: np.ndarray   # (n, 3) p^c after the clamp
    zmp: np.ndarray       # (n, 3) the realised ZMP driving the LIP


def simulate(pattern: Pattern, cp_gain: float, polygons: list | None, dt: float, zmp_lag: float = 0.0,
             x0: np.ndarray | None = None, v0: np.ndarray | None = None) -> LipmLog:
    """Closed loop of the LIP from (x0, v0) (default: the pattern's start) tracking `pattern` with gain k.

    `polygons[i]` = (A, b) of the support polygon at cycle i (None: no clamp)."""
    omega = pattern.omega
    n = len(pattern.t)
    x = np.array(pattern.com[0] if x0 is None else x0, dtype=float)
    v = np.array(pattern.com_vel[0] if v0 is None else v0, dtype=float)
    com, vel, cmd, real = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    ch, sh = np.cosh(omega * dt), np.sinh(omega * dt)
    lag = np.exp(-dt / zmp_lag) if zmp_lag > 0 else 0.0
    p = pattern.zmp[0].copy()
    gain = 1 + cp_gain / omega
    for i in range(n):
        com[i], vel[i] = x, v
        xi = x + v / omega
        p_c = pattern.zmp[i] + gain * (xi - pattern.cp[i])                 # eq. (50)
        if polygons is not None:
            p_c[:2] = clamp(p_c[:2], polygons[i])
        cmd[i] = p_c
        p = lag * p + (1 - lag) * p_c        # the realised ZMP, held over the cycle
        real[i] = p
        x, v = (x - p) * ch + v / omega * sh + p, omega * (x - p) * sh + v * ch   # eq. (45), k = 0
    return LipmLog(t=pattern.t, com=com, com_vel=vel, cp=com + vel / omega, zmp_cmd=cmd, zmp=real)
