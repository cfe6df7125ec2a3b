"""A run of `srs-collision-avoidance` read back as the arrays the metrics and figures use (SI units)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from pipeline.core.runlog import Run
from pipeline.papers.srs_collision_avoidance.kinematics import JOINTS, Geometry, chain

# The iterations the paper draws (Fig. 5: 390; Fig. 6: 76, 179, 407), counted from 1 as MATLAB does
SNAPSHOTS = (76, 179, 390, 407)


def _matrix(frame: pd.DataFrame, prefix: str) -> np.ndarray:
    return frame[[c for c in frame.columns if c.startswith(prefix)]].to_numpy()


@dataclass
class Signals:
    run_id: str
    t: np.ndarray                 # (N,) s, the planning samples
    dt: float                     # s, T
    alpha_c: np.ndarray           # (N,) rad
    alpha_f: np.ndarray
    q: np.ndarray                 # (N, 7) rad, the planned joints (IK at α_f), continuous
    q0: np.ndarray                # (N, 7) rad, IK at α = 0
    case: np.ndarray              # (N,) str, where Algorithm 1 found an imminent collision
    d_mc: np.ndarray              # (N,) m, the allowed distance it aimed at (0 when none)
    actual: np.ndarray            # (N,) m, the distance P_c had from P_col (NaN when none)
    volume: np.ndarray            # (N, 6) m, margins of the human points outside the safety volume (executed)
    volume_alpha0: np.ndarray     # (N, 6) m, the same at α = 0
    capsules: np.ndarray          # (N, 16) m, human capsules to link capsules, planned joints (ours)
    capsules_mujoco: np.ndarray | None   # (N, 16) m, MuJoCo's mj_geomDistance on the same
    capsules_replay: np.ndarray | None   # (N, 16) m, MuJoCo, at the joints the replay reached
    ik_error: np.ndarray          # (N,) m, tool position error of FK(IK)
    ik_rotation_error: np.ndarray  # (N,) rad
    humans: np.ndarray            # (N, 6, 3) m, human shoulders, elbows, hands
    P_c: np.ndarray               # (N, 3) m
    P_col: np.ndarray             # (N, 3) m, NaN when none
    replay: pd.DataFrame | None   # /tracking_error (joints) of the replay
    replay_tool: pd.DataFrame | None  # /tracking_error/tool
    config: dict

    @property
    def find(self) -> np.ndarray:
        return self.case != "none"

    @property
    def geometry(self) -> Geometry:
        return Geometry(**self.config["system"]["geometry"])

    def chain_points(self, q: np.ndarray) -> np.ndarray:
        """(N, 4, 3) O_b, P_s, P_e, P_w of configurations q (N, 7)."""
        c = chain(q, self.geometry)
        return np.stack([np.zeros_like(c.P_s), c.P_s, c.P_e, c.P_w], axis=1)


def read(run: Run) -> Signals:
    swivel, avoidance = run["/swivel"], run["/avoidance"]
    humans = run["/humans"]
    names = [c.removeprefix("x_m.") for c in humans.columns if c.startswith("x_m.")]
    tool_error = run["/ik/tool_error"]
    has_replay = "/clearance/capsules_replay" in run.topic_names
    return Signals(
        run_id=run.run_id, t=swivel.index.to_numpy(), dt=float(run.config["system"]["filter"]["dt"]),
        alpha_c=swivel["alpha_c_rad"].to_numpy(), alpha_f=swivel["alpha_f_rad"].to_numpy(),
        q=run["/ik/joints"][[f"position.{j}" for j in JOINTS]].to_numpy(),
        q0=run["/ik/alpha0"][[f"position.{j}" for j in JOINTS]].to_numpy(),
        case=avoidance["case"].to_numpy(dtype=str), d_mc=avoidance["d_mc_m"].to_numpy(),
        actual=avoidance["actual_distance_m"].to_numpy(),
        volume=_matrix(run["/clearance/volume"], "distance_m."),
        volume_alpha0=_matrix(run["/clearance/volume_alpha0"], "distance_m."),
        capsules=_matrix(run["/clearance/capsules"], "distance_m."),
        capsules_mujoco=_matrix(run["/clearance/capsules_mujoco"], "distance_m.") if has_replay else None,
        capsules_replay=_matrix(run["/clearance/capsules_replay"], "distance_m.") if has_replay else None,
        ik_error=tool_error["norm"].to_numpy(), ik_rotation_error=tool_error["error.rotation"].to_numpy(),
        humans=np.stack([humans[[f"{a}_m.{n}" for n in names]].to_numpy() for a in "xyz"], axis=-1),
        P_c=_matrix(avoidance, "p_c_m["), P_col=_matrix(avoidance, "p_col_m["),
        replay=run["/tracking_error"] if has_replay else None,
        replay_tool=run["/tracking_error/tool"] if has_replay else None,
        config=run.config,
    )


def differences(x: np.ndarray, dt: float, order: int) -> np.ndarray:
    """The paper's first-order approximations (Figs. 8-9, 12-13): `order` backward differences over T."""
    return np.diff(x, n=order, axis=0) / dt ** order
