"""Cartesian paths: solutions per sample, the followed branch's joint jumps and FK error, and the MuJoCo
execution's tracking errors."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run


def analyze_trajectory(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        s = run["/ik/samples"]
        threshold = float(run.config["execute"]["jump_threshold"])
        joint = run["/tracking_error"]["norm"].to_numpy()
        flange = run["/tracking_error/flange"]
        tau = run["/command"].filter(like="value.").to_numpy()
        limits = np.asarray(run.config["system"]["dynamics"]["torque_limit"])
        m.add_run(run, {
            "samples": (len(s), "count"),
            "solutions.min": (s["count"].min(), "count"), "solutions.max": (s["count"].max(), "count"),
            "solutions.changes": (int((np.diff(s["count"].to_numpy()) != 0).sum()), "count"),
            "max_joint_jump": (s["jump"].max(), "rad"),
            "jumps": (int((s["jump"] > threshold).sum()), "count"),
            "max_ik_fk_error": (s["fk_error_position"].max(), "m"),
            "max_ik_fk_rotation_error": (s["fk_error_rotation"].max(), "rad"),
            "max_joint_error": (joint.max(), "rad"), "rms_joint_error": (np.sqrt(np.mean(joint ** 2)), "rad"),
            "max_flange_error": (flange["norm"].max(), "m"),
            "rms_flange_error": (np.sqrt(np.mean(flange["norm"].to_numpy() ** 2)), "m"),
            "max_flange_rotation_error": (flange["error.rotation"].max(), "rad"),
            "max_torque_ratio": ((np.abs(tau) / limits).max(), "ratio"),
        })
        fig, axes = plt.subplots(4, 1, figsize=(8, 8.5), sharex=True)
        t = s.index.to_numpy()
        q = s.filter(like="followed").to_numpy()
        for j in range(6):
            axes[0].plot(t, q[:, j], lw=1.2, label=f"q{j + 1}")
        axes[0].set_ylabel("followed branch\n[rad]")
        axes[0].legend(ncol=6, fontsize=7)
        axes[1].step(t, s["count"], where="post")
        axes[1].set_ylabel("solutions")
        axes[2].semilogy(t[1:], np.maximum(s["jump"].to_numpy()[1:], 1e-12))
        axes[2].axhline(threshold, color="r", ls="--", lw=1)
        axes[2].set_ylabel("joint step per\nsample [rad]")
        axes[3].plot(flange.index, flange["norm"] * 1e3, label="MuJoCo flange position error")
        axes[3].set_ylabel("executed flange\nerror [mm]")
        axes[3].set_xlabel("time [s]")
        fig.suptitle(f"{run.run_id}: all solutions per sample, branch by continuity, MuJoCo execution")
        figures.save(fig, run.run_id)
    return m.frame()
