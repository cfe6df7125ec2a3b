"""`ur5-ik-fsm`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pipeline.core.runlog import Run
from pipeline.papers.ur5_ik_fsm.kinematics import Geometry, shoulder_term

JOINT_COLUMNS = [f"position.joint{i}" for i in range(1, 7)]


ALGORITHMS = ("alg1", "alg2")


AGREE_TOL = 1e-6     # rad: two selections are the same set


JUMP_THRESHOLD = 0.5  # rad: a step between samples larger than this is a jump (assumption)


TARGETS = Path(__file__).with_name("targets.csv")


def wrap(x: np.ndarray) -> np.ndarray:
    return np.remainder(np.asarray(x) + np.pi, 2 * np.pi) - np.pi


def _nonsingular(q: np.ndarray, config: dict) -> np.ndarray:
    """Sec. 2.4 validity: |s3|, |s5| and the shoulder term above their thresholds."""
    c, g = config["system"]["conventions"], Geometry(**config["system"]["geometry"])
    return ((np.abs(np.sin(q[:, 2])) > c["s3_min"]) & (np.abs(np.sin(q[:, 4])) > c["s5_min"])
            & (np.abs(shoulder_term(q, g)) > c["shoulder_min"]))


def _path_metrics(run: Run) -> tuple[dict, np.ndarray, np.ndarray]:
    alg = run.metadata["case"].rsplit("-", 1)[1]
    ik = run[f"/ik/{alg}"]
    q = ik[JOINT_COLUMNS].to_numpy()
    found = ik["found"].to_numpy(bool)
    qf = q[found]
    steps = np.abs(wrap(np.diff(qf, axis=0))).max(axis=1) if len(qf) > 1 else np.zeros(1)
    branch = ik["branch"].to_numpy()[found]
    limits = np.asarray(run.config["system"]["dynamics"]["torque_limit"])
    tau = run["/command"][[f"value.joint{i}" for i in range(1, 7)]].to_numpy()
    joint_err = run["/tracking_error"]["norm"].to_numpy()
    flange = run["/tracking_error/flange"]
    values = {
        "max_joint_jump": (steps.max(), "rad"),
        "jumps": (int((steps > JUMP_THRESHOLD).sum()), "count"),
        "branch_switches": (int((np.diff(branch) != 0).sum()), "count"),
        "rejected_samples": (int((~found).sum()), "count"),
        "min_abs_det_j": (np.nanmin(np.abs(ik["det_j"].to_numpy())), "m^3"),
        "max_ik_fk_error": (np.nanmax(ik["fk_error_position"].to_numpy()), "m"),
        "all_selected_nonsingular": (float(_nonsingular(qf, run.config).all()), "bool"),
        "max_joint_error": (joint_err.max(), "rad"),
        "rms_joint_error": (np.sqrt(np.mean(joint_err ** 2)), "rad"),
        "max_flange_error": (flange["norm"].max(), "m"),
        "rms_flange_error": (np.sqrt(np.mean(flange["norm"].to_numpy() ** 2)), "m"),
        "max_flange_rotation_error": (flange["error.rotation"].max(), "rad"),
        "max_torque_ratio": ((np.abs(tau) / limits).max(), "ratio"),
        "saturated_fraction": (((np.abs(tau) / limits) > 0.999).any(axis=1).mean(), "fraction"),
    }
    return values, np.where(found[:, None], q, np.nan), ik.index.to_numpy()
