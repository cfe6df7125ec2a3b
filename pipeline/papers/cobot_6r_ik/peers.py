"""IK solvers a user would pick instead, as adapters to this paper's convention (Table 1 DH, rad, base at
the floor, flange frame {6}). Each is optional: the [bench] extra installs them; one that is missing or
refuses this arm says why.

Only `call` is timed: the pose is converted to the peer's own input beforehand (`prepare`), and its
output back to ours afterwards (`convert`).
"""

from __future__ import annotations

import importlib.metadata
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from pipeline.papers.cobot_6r_ik.kinematics import CRX10IAL, Geometry, wrap
from pipeline.robotics import dh as dhk


@dataclass
class Peer:
    name: str                                  # metric prefix
    label: str                                 # what it is, for tables
    all_solutions: bool                        # claims every solution (not a numerical single-solution method)
    prepare: Callable[[np.ndarray], Any] | None = None
    call: Callable[[Any], Any] | None = None
    convert: Callable[[Any], np.ndarray] | None = None
    reason: str = ""                           # why it is not available, if it is not
    match_tol: float = 1e-6                    # rad: a peer solution equals one of ours within this

    @property
    def available(self) -> bool:
        return self.call is not None

    def solve(self, T: np.ndarray) -> np.ndarray:
        return self.convert(self.call(self.prepare(T)))


def _version(dist: str) -> str:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def crx_kinematics(g: Geometry = CRX10IAL) -> Peer:
    """mattj23's crx-kinematics (Rust, all solutions of the CRX family). FANUC convention, found by FK
    matching: base at the J2 height, mm, degrees, J3 measured against J2:
    q = (j1, 90° − j2, −j2 − j3, −j4, j5, −j6)."""
    label = f"crx-kinematics {_version('crx-kinematics')} (CRX-specific, Rust)"
    try:
        from crx_kinematics import Crx
    except ImportError:
        return Peer("crx", label, True, reason="not installed: pip install -e '.[bench]'")
    robot = Crx.from_params(g.a2 * 1e3, g.d4 * 1e3, g.d6 * 1e3, g.d5 * 1e3)

    def prepare(T: np.ndarray) -> np.ndarray:
        Tp = np.array(T, dtype=float)
        Tp[2, 3] -= g.d1
        Tp[:3, 3] *= 1e3
        return Tp

    def convert(j: np.ndarray) -> np.ndarray:
        j = np.deg2rad(np.asarray(j, dtype=float).reshape(-1, 6))
        q = np.column_stack([j[:, 0], np.pi / 2 - j[:, 1], -j[:, 1] - j[:, 2], -j[:, 3], j[:, 4], -j[:, 5]])
        return wrap(q)

    return Peer("crx", label, True, prepare, robot.ik, convert)


def _poe(g: Geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Product-of-exponentials description (axes h, offsets p) of the DH chain at q = 0, and R_06(0)."""
    F = dhk.frames(dhk.DH.from_config(g.dh), np.zeros(6))
    H = np.array([F[i, :3, 2] for i in range(6)])
    origins = F[:, :3, 3]
    return H, np.vstack([origins[0], np.diff(origins, axis=0)]), F[6, :3, :3]


def ik_geo(g: Geometry = CRX10IAL) -> Peer:
    """ik-geo (Rust port of IK-Geo). The CRX fits none of its 1-D-search families (no spherical wrist,
    three parallel or two intersecting axes at the end), so it is the general 6R solver (2-D search)."""
    label = f"ik-geo {_version('ik-geo')} gen_six_dof (general 6R, Rust)"
    try:
        import ik_geo as module
    except ImportError:
        return Peer("ik_geo", label, True, reason="not installed: pip install -e '.[bench]'")
    H, P, R0 = _poe(g)
    robot = module.Robot.gen_six_dof(H.tolist(), P.tolist())

    def prepare(T: np.ndarray) -> tuple[list, list]:
        # its forward_kinematics(q) returns R with Rᵀ·R_06(0) = our R: the input takes that R
        return (R0 @ T[:3, :3].T).tolist(), T[:3, 3].tolist()

    def convert(solutions) -> np.ndarray:
        q = [s for s, _, least_squares in solutions if not least_squares]
        return wrap(np.array(q, dtype=float).reshape(-1, 6))

    R, p = robot.forward_kinematics([0.3, 0.5, 1.0, -0.4, 0.8, 0.2])   # its own FK pose, fed back
    if not [s for s, _, least_squares in robot.get_ik_sorted(R, p) if not least_squares]:
        label += " (finds no exact solution of this arm, not even of its own FK pose)"
    return Peer("ik_geo", label, True, prepare, lambda x: robot.get_ik_sorted(*x), convert)


def eaik(g: Geometry = CRX10IAL) -> Peer:
    """EAIK (automatic subproblem decomposition, C++), given Table 1's DH."""
    label = f"eaik {_version('eaik')} (subproblem decomposition, C++)"
    try:
        from eaik.IK_DH import DhRobot
    except ImportError:
        return Peer("eaik", label, True, reason="not installed: pip install -e '.[bench]'")
    dh = g.dh
    robot = DhRobot(np.array(dh["alpha"]), np.array(dh["a"]), np.array(dh["d"]))
    if not robot.hasKnownDecomposition():
        return Peer("eaik", label, True, reason=f"refuses this arm: hasKnownDecomposition() is False "
                    f"('{robot.getKinematicFamily()}'), IK raises 'No Subproblem-Decomposition ... known'")

    def convert(solution) -> np.ndarray:
        return wrap(np.asarray(solution.Q, dtype=float).reshape(-1, 6))

    return Peer("eaik", label, True, np.asarray, robot.IK, convert)


def rtb_restarts(g: Geometry = CRX10IAL, starts: int = 50, seed: int = 0) -> Peer:
    """roboticstoolbox-python's Levenberg–Marquardt IK (C++ core) from `starts` random joint vectors per
    pose, converged solutions de-duplicated: the numerical way to ask for every solution."""
    label = f"roboticstoolbox-python {_version('roboticstoolbox-python')} ik_LM × {starts} random starts"
    try:
        import roboticstoolbox as rtb
    except ImportError:
        return Peer("rtb", label, False, reason="not installed: pip install -e '.[bench]'")
    dh = g.dh
    ets = rtb.DHRobot([rtb.RevoluteDH(d=dh["d"][i], a=dh["a"][i], alpha=dh["alpha"][i]) for i in range(6)]).ets()
    rng = np.random.default_rng(seed)

    def call(T: np.ndarray) -> list[np.ndarray]:
        found = []
        for q0 in rng.uniform(-np.pi, np.pi, (starts, 6)):
            sol = ets.ik_LM(T, q0=q0, ilimit=30, slimit=1, tol=1e-14, joint_limits=False)
            if sol.success:
                found.append(sol.q)
        return found

    def convert(found: list[np.ndarray]) -> np.ndarray:
        out: list[np.ndarray] = []
        for q in wrap(np.array(found, dtype=float).reshape(-1, 6)):
            if not any(np.abs(wrap(q - x)).max() < 1e-4 for x in out):
                out.append(q)
        return np.array(out).reshape(-1, 6)

    return Peer("rtb", label, False, np.asarray, call, convert, match_tol=1e-4)


def all_peers(g: Geometry = CRX10IAL, starts: int = 50, seed: int = 0) -> list[Peer]:
    return [crx_kinematics(g), ik_geo(g), eaik(g), rtb_restarts(g, starts, seed)]


def compare(ours: np.ndarray, theirs: np.ndarray, tol: float) -> tuple[int, int, int]:
    """(common, ours only, theirs only) between two solution sets (wrapped max-abs joint difference)."""
    if len(ours) == 0 or len(theirs) == 0:
        return 0, len(ours), len(theirs)
    d = np.abs(wrap(ours[:, None, :] - theirs[None, :, :])).max(axis=2) < tol
    return int(d.any(axis=1).sum()), int((~d.any(axis=1)).sum()), int((~d.any(axis=0)).sum())
