"""A run of `srs-collision-avoidance` read back as the arrays the metrics and figures use (SI units), and its
tidy metrics: IK exactness, swivel and joint smoothness, clearance (safety volume and bodies, with MuJoCo's
audit), the replay's tracking, and the filter's own constants."""

from __future__ import annotations

import cmath
from dataclasses import dataclass

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from pipeline.core.runlog import Run
from pipeline.papers.srs_collision_avoidance.kinematics import JOINTS, Geometry, chain
from pipeline.papers.srs_collision_avoidance.swivel_filter import Coefficients

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


REGULAR_RATIO = 0.1   # α_f is "a regular curve" (Fig. 7) if its peak second difference is ≤ 10 % of α_c's


def _max_abs(x: np.ndarray) -> float:
    return float(np.max(np.abs(x))) if x.size else float("nan")


def episodes(flags: np.ndarray) -> int:
    """Number of runs of consecutive True samples."""
    return int(np.count_nonzero(np.diff(np.r_[0, flags.astype(int)]) == 1))


def filter_metrics(config: dict) -> dict[str, tuple[float, str]]:
    """m, the sample rate, the run's duration, and the DC gain, damping ratio and coefficients of the discrete
    filter the run used (the damping ratio from its poles: s = ln z / T)."""
    f = config["system"]["filter"]
    c = Coefficients.zoh(f["p"], f["dt"])
    poles = np.roots(c.denominator)
    s = [cmath.log(complex(z)) / f["dt"] for z in poles]
    zeta = min(-x.real / abs(x) for x in s)
    return {"filter.m": (f["p"] * f["dt"], ""), "filter.sample_rate": (1 / f["dt"], "Hz"),
            "task.duration": (config["system"]["task"]["samples"] * f["dt"], "s"), "filter.dc_gain": (c.dc_gain, ""),
            "filter.damping_ratio": (zeta, ""), "filter.h1": (c.h1, ""), "filter.h2": (c.h2, ""),
            "filter.b1": (c.b1, ""), "filter.b2": (c.b2, ""),
            "filter.time_constant": (1 / f["p"], "s")}


def smoothness(s: Signals) -> dict[str, tuple[float, str]]:
    dt = s.dt
    rate_c, rate_f = differences(s.alpha_c, dt, 1), differences(s.alpha_f, dt, 1)
    acc_c, acc_f = differences(s.alpha_c, dt, 2), differences(s.alpha_f, dt, 2)
    qd, qdd, qddd = (differences(s.q, dt, k) for k in (1, 2, 3))
    values = {
        "alpha_c.max_abs": (_max_abs(s.alpha_c), "rad"), "alpha_f.max_abs": (_max_abs(s.alpha_f), "rad"),
        "alpha_c.rate.max_abs": (_max_abs(rate_c), "rad/s"), "alpha_f.rate.max_abs": (_max_abs(rate_f), "rad/s"),
        "alpha_c.acceleration.max_abs": (_max_abs(acc_c), "rad/s^2"),
        "alpha_f.acceleration.max_abs": (_max_abs(acc_f), "rad/s^2"),
        "alpha_c.total_variation": (float(np.abs(np.diff(s.alpha_c)).sum()), "rad"),
        "alpha_f.total_variation": (float(np.abs(np.diff(s.alpha_f)).sum()), "rad"),
        "joint.max_step": (_max_abs(np.diff(s.q, axis=0)), "rad"),
        "joint.rate.max_abs": (_max_abs(qd), "rad/s"),
        "joint.acceleration.max_abs": (_max_abs(qdd), "rad/s^2"),
        "joint.acceleration.rms": (float(np.sqrt(np.mean(qdd ** 2))), "rad/s^2"),
        "joint.jerk.max_abs": (_max_abs(qddd), "rad/s^3"),
        # Σ_i ∫ q⃛_i² dt: the squared-jerk cost of minimum-jerk planning, a scalar smoothness measure
        "joint.squared_jerk_integral": (float(np.sum(qddd ** 2) * dt), "rad^2/s^5"),
    }
    peak_c = values["alpha_c.acceleration.max_abs"][0]
    if peak_c > 0:
        values["claim.alpha_f_regular"] = (float(values["alpha_f.acceleration.max_abs"][0] <= REGULAR_RATIO * peak_c),
                                           "bool")
    return values


def clearance(s: Signals) -> dict[str, tuple[float, str]]:
    margin, margin0 = s.volume.min(axis=1), s.volume_alpha0.min(axis=1)
    intrusion, intrusion0 = margin < 0, margin0 < 0
    bodies = s.capsules.min(axis=1)
    values = {
        "volume.min_margin": (float(margin.min()), "m"), "volume.min_margin_alpha0": (float(margin0.min()), "m"),
        "volume.intrusion_fraction": (float(intrusion.mean()), "fraction"),
        "volume.intrusion_fraction_alpha0": (float(intrusion0.mean()), "fraction"),
        "volume.intrusion_depth_integral": (float(np.sum(-margin.clip(max=0)) * s.dt), "m*s"),
        "volume.intrusion_depth_integral_alpha0": (float(np.sum(-margin0.clip(max=0)) * s.dt), "m*s"),
        "claim.fewer_intrusions": (float(intrusion.sum() < intrusion0.sum()), "bool"),
        "capsules.min_clearance": (float(bodies.min()), "m"),
        "capsules.contact_fraction": (float((bodies < 0).mean()), "fraction"),
        "find.fraction": (float(s.find.mean()), "fraction"), "find.episodes": (episodes(s.find), "count"),
        "snapshots.active_fraction": (float(np.mean([s.find[k - 1] for k in SNAPSHOTS if k <= len(s.find)])),
                                      "fraction"),
    }
    for case in ("upper_arm", "elbow", "forearm"):
        values[f"find.{case}_fraction"] = (float((s.case == case).mean()), "fraction")
    if s.capsules_mujoco is not None:
        values["capsules.min_clearance_mujoco"] = (float(s.capsules_mujoco.min()), "m")
        values["capsules.audit_max_difference"] = (float(np.abs(s.capsules_mujoco - s.capsules).max()), "m")
        values["capsules.min_clearance_replay"] = (float(s.capsules_replay.min()), "m")
    return values


def tracking(s: Signals) -> dict[str, tuple[float, str]]:
    values = {"ik.max_position_error": (float(s.ik_error.max()), "m"),
              "ik.max_rotation_error": (float(s.ik_rotation_error.max()), "rad")}
    if s.replay is not None:
        joint, tool = s.replay["norm"].to_numpy(), s.replay_tool
        values |= {"replay.joint_error.max": (float(joint.max()), "rad"),
                   "replay.joint_error.rms": (float(np.sqrt(np.mean(joint ** 2))), "rad"),
                   "replay.tool_error.max": (float(tool["norm"].max()), "m"),
                   "replay.tool_error.rms": (float(np.sqrt(np.mean(tool["norm"].to_numpy() ** 2))), "m"),
                   "replay.tool_rotation_error.max": (float(tool["error.rotation"].max()), "rad")}
    return values


def run_metrics(s: Signals) -> dict[str, tuple[float, str]]:
    return {**filter_metrics(s.config), **smoothness(s), **clearance(s), **tracking(s)}


def ratio(metrics: dict[str, dict], a: str, b: str, metric: str) -> float:
    """metric of run a over run b (NaN if either is missing or b is 0)."""
    try:
        num, den = metrics[a][metric][0], metrics[b][metric][0]
    except KeyError:
        return float("nan")
    return num / den if den else float("nan")


def compute_time_metrics(run: Run) -> dict[str, tuple[float, str]]:
    ct = run["/compute_time"]
    values: dict[str, tuple[float, str]] = {}
    for name in ("algorithm1", "ik", "algorithm1_batch"):
        per_item = (ct[f"seconds.{name}"] / ct[f"calls.{name}"]).dropna().to_numpy()
        values |= timing_metrics(name, per_item)
    per_iteration = ct["seconds.algorithm1"].dropna().to_numpy()
    samples = int(run.config["system"]["task"]["samples"])
    passes = per_iteration[: len(per_iteration) // samples * samples].reshape(-1, samples).sum(axis=1)
    values["algorithm1.run_total"] = (float(np.median(passes)), "s")
    values["algorithm1.samples"] = (samples, "count")
    values["online_vs_batch.max_difference"] = (
        float(run["/online_vs_batch"]["value.max_joint_difference_rad"].iloc[0]), "rad")
    values["realtime.p95_over_sample_time"] = (values["algorithm1.p95"][0] / run.config["system"]["filter"]["dt"],
                                               "ratio")
    return values
