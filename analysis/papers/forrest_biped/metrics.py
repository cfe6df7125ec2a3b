"""Metrics of `forrest-biped` from the runs: drive curves, generator properties, walking errors, the Eq. (59) shares,
contact forces, compute time, and the band of the shares over the robustness sweep.

Rules fixed before looking at the results (paper.yaml says why):
- Eq. (59) share: f(t) = |e_trad(t)| − |e_ext(t)| on the controller's 1 ms grid, share = #(f > 0)/N in the window
  `scenario.window` (the two steps, 1-3 s), per axis; also over the whole walk.
- "tracked accurately": the largest horizontal CoM error of both generators below ACCURATE (1 cm).
- "not very significant": the RMS horizontal CoM errors of the two generators within NOT_SIGNIFICANT (50 %) of the
  larger one, on both axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run

XYZ = ("x", "y", "z")
ACCURATE = 0.01             # m
NOT_SIGNIFICANT = 0.5       # relative RMS difference
STANDING = (0.0, 0.2)       # s: the first 0.2 s, double support, the CoM nearly at rest (Σ f_z ≈ M g)
GENERATORS = ("extended", "traditional")
CONTINUOUS_ACC_STEP = 0.1   # m/s² per 1 ms sample: ω² × 7 mm of ZMP


def xyz(frame: pd.DataFrame, field: str, axes=XYZ) -> np.ndarray:
    return frame[[f"{field}.{a}" for a in axes]].to_numpy()


def window_mask(t: np.ndarray, window) -> np.ndarray:
    return (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)


def scenario_window(run: Run) -> tuple[float, float]:
    return tuple(run.config["scenario"]["window"])


def share(e_trad: np.ndarray, e_ext: np.ndarray) -> np.ndarray:
    """Eq. (59) per column: the fraction of samples where |e_trad| − |e_ext| > 0."""
    return (np.abs(e_trad) - np.abs(e_ext) > 0).mean(axis=0)


# -- mechanisms ----------------------------------------------------------------------------------------------


def curve(run: Run, topic: str) -> pd.DataFrame:
    """A /knee or /ankle curve as a table, one column per named quantity."""
    frame = run[topic]
    return frame.rename(columns=lambda c: c.removeprefix("value."))


def mechanism_metrics(run: Run) -> dict[str, tuple[float, str]]:
    knee = curve(run, "/knee")
    flex = knee["flexion_rad"].to_numpy()
    out = {f"knee.argmax_{k}": (float(flex[int(np.argmax(knee[c]))]), "rad")
           for k, c in (("arm", "arm_m"), ("torque", "torque_Nm"), ("stiffness", "stiffness_Nm_per_rad"))}
    out["knee.argmin_speed"] = (float(flex[int(np.argmin(knee["speed_rad_s"]))]), "rad")
    out["knee.arm_max"] = (float(knee["arm_m"].max()), "m")
    out["knee.torque_max"] = (float(knee["torque_Nm"].max()), "N*m")
    out["knee.stiffness_max"] = (float(knee["stiffness_Nm_per_rad"].max()), "N*m/rad")
    out["knee.moment_arm_identity"] = (float(np.abs(np.abs(knee["J_AB_m_per_rad"]) - knee["arm_m"]).max()), "m")
    power = knee["torque_Nm"] * knee["speed_rad_s"]
    out["knee.power_spread"] = (float((power.max() - power.min()) / power.mean()), "ratio")
    ankle = curve(run, "/ankle")
    out["ankle.rod_error"] = (float(ankle["rod_error_m"].max()), "m")
    zero = ankle[(ankle["q11_rad"].abs() < 1e-9) & (ankle["q12_rad"].abs() < 1e-9)]
    for column, name, unit in (("stiffness_q11_Nm_per_rad", "stiffness_q11", "N*m/rad"),
                               ("stiffness_q12_Nm_per_rad", "stiffness_q12", "N*m/rad"),
                               ("torque_same_q11_Nm", "torque_q11", "N*m"),
                               ("torque_opposite_q12_Nm", "torque_q12", "N*m"),
                               ("speed_same_q11_rad_s", "speed_q11", "rad/s"),
                               ("speed_opposite_q12_rad_s", "speed_q12", "rad/s")):
        out[f"ankle.zero_pose.{name}"] = (float(zero[column].iloc[0]) if not zero.empty else float("nan"), unit)
    claims = curve(run, "/claims").iloc[0]
    units = {"J": "J", "m_s": "m/s", "m": "m", "kg": "kg"}
    for name, value in claims.items():
        unit = next(u for k, u in units.items() if name.endswith(k))
        out[f"claim.{name}"] = (float(value), unit)
    return out


# -- pattern generator ---------------------------------------------------------------------------------------


def generator_metrics(run: Run) -> dict[str, tuple[float, str]]:
    com, cp, zmp = run["/reference/com"], run["/reference/cp"], run["/reference/zmp"]
    t = com.index.to_numpy()
    dt = t[1] - t[0]
    x, v, a = xyz(com, "position"), xyz(com, "velocity"), xyz(com, "acceleration")
    p = xyz(zmp, "position")
    steps = run["/pattern/steps"]
    miss = steps[[f"value.cp_end_miss.{k}" for k in XYZ]].to_numpy()
    out = {"cp_end_miss.max": (float(np.nanmax(np.abs(miss))), "m"),
           "zmp_jump.max": (float(np.abs(np.diff(p, axis=0)).max()), "m"),
           "com_acc_jump.max": (float(np.abs(np.diff(a, axis=0)).max()), "m/s^2"),
           "com_vel_jump.max": (float(np.abs(np.diff(v, axis=0)).max()), "m/s"),
           "cp_identity.max": (float(np.abs(xyz(cp, "position") - (x + v / run_omega(run))).max()), "m"),
           "com_height.start": (float(x[0, 2]), "m"), "com_height.end": (float(x[-1, 2]), "m"),
           "com_height.final_deviation": (float(abs(x[-1, 2] - run.config["system"]["walk"]["z_c"])), "m"),
           "com_height.monotone": (float((np.diff(x[:, 2]) <= 1e-12).all()), "bool"),
           "dt": (float(dt), "s")}
    # a continuous ZMP keeps ẍ = ω²(x − p) continuous: per sample it changes by ω²|ẋ − ṗ|·dt, centimetres per
    # second squared; a ZMP switch of Δp makes it jump by ω²|Δp| (0.24 m: 3.3 m/s²)
    out["claim.continuous_acceleration"] = (float(out["com_acc_jump.max"][0] < CONTINUOUS_ACC_STEP), "bool")
    out["claim.height_settles"] = (float(out["com_height.monotone"][0] == 1.0
                                         and out["com_height.final_deviation"][0] < 1e-3), "bool")
    p1 = steps[[f"value.P1.{k}" for k in XYZ]].to_numpy()
    for i, row in enumerate(p1):
        for k, axis in enumerate(XYZ):
            out[f"step{i}.P1.{axis}"] = (float(row[k]), "m")
    return out


def run_omega(run: Run) -> float:
    s = run.config["system"]
    return float(np.sqrt(s["gravity"] / s["walk"]["z_c"]))


# -- walking --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Walk:
    """What the walking metrics need from one run (errors on the 1 ms grid)."""

    t: np.ndarray
    com_error: np.ndarray        # (n, 3) reference − measured
    cp_error: np.ndarray


def walk_errors(run: Run) -> Walk:
    com, cp = run["/tracking_error"], run["/tracking_error/cp"]
    return Walk(com.index.to_numpy(), xyz(com, "error"), xyz(cp, "error"))


def error_metrics(w: Walk, window, prefix: str = "") -> dict[str, tuple[float, str]]:
    out = {}
    for label, mask in (("window", window_mask(w.t, window)), ("all", np.ones(len(w.t), bool))):
        for name, err in (("com", w.com_error), ("cp", w.cp_error)):
            for k, axis in enumerate(XYZ):
                stats = error_stats(w.t[mask], err[mask, k], f"{prefix}{name}_error.{axis}.{label}", "m")
                out.update({key: val for key, val in stats.items() if not key.endswith(".ise")})
    return out


def walking_run_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """Per MuJoCo walk: tracking, contact and compute metrics."""
    w = walk_errors(run)
    out = error_metrics(w, scenario_window(run))
    duration = run.config["system"]["walk"]["duration"]
    out["completed"] = (float(run.ok and w.t[-1] >= duration - 1e-6), "bool")
    bal = run["/balance"]
    t = bal.index.to_numpy()
    zmp, cmd = xyz(bal, "zmp", XYZ[:2]), xyz(bal, "zmp_cmd", XYZ[:2])
    ok = np.isfinite(zmp[:, 0])
    for k, axis in enumerate(XYZ[:2]):
        out.update({key: v for key, v in error_stats(t[ok], cmd[ok, k] - zmp[ok, k], f"zmp_error.{axis}", "m")
                    .items() if not key.endswith(".ise")})
    out["qp.not_optimal"] = (float((bal["qp_flag"] != 1).sum()), "count")
    out["qp.iterations_mean"] = (float(bal["qp_iterations"].mean()), "count")
    # contact wrenches: the QP's command against what the four corner contacts carried
    fz_total = np.zeros(len(t))
    for side in ("left_foot", "right_foot"):
        wr = run[f"/wrench/{side}"]
        meas = wr[["force_x.measured", "force_y.measured", "force_z.measured"]].to_numpy()
        cmd_f = wr[["force_x.commanded", "force_y.commanded", "force_z.commanded"]].to_numpy()
        fz_total += meas[:, 2]
        err = np.linalg.norm(meas - cmd_f, axis=1)
        out[f"force_error.{side}.rms"] = (float(np.sqrt(np.mean(err**2))), "N")
        out[f"force_error.{side}.max"] = (float(err.max()), "N")
    com_w = run["/wrench/com"]
    force = [f"force_{a}" for a in XYZ]
    torque = [f"torque_{a}" for a in XYZ]
    res_f = np.linalg.norm(com_w[[f"{c}.desired" for c in force]].to_numpy()
                           - com_w[[f"{c}.optimized" for c in force]].to_numpy(), axis=1)
    res_m = np.linalg.norm(com_w[[f"{c}.desired" for c in torque]].to_numpy()
                           - com_w[[f"{c}.optimized" for c in torque]].to_numpy(), axis=1)
    out["wrench_residual.force.rms"] = (float(np.sqrt(np.mean(res_f**2))), "N")
    out["wrench_residual.moment.rms"] = (float(np.sqrt(np.mean(res_m**2))), "N*m")
    standing = window_mask(t, STANDING)
    out["standing.normal_force"] = (float(fz_total[standing].mean()), "N")
    # compute time per controller cycle
    ct = run["/compute_time"]
    for name in ("controller", "qp", "model_update"):
        out.update(timing_metrics(f"compute.{name}", ct[f"seconds.{name}"].to_numpy()))
    out["compute.controller.over_budget"] = (float((ct["seconds.controller"] > 1e-3).mean()), "fraction")
    out["wall_time"] = (float(run.metadata.get("wall_time_s", "nan")), "s")
    out["simulated_time"] = (float(w.t[-1]), "s")
    # step lengths as simulated: at the end of each stepping step, the landed sole ahead of the stance sole (x);
    # and how far a stance sole slid while it supported
    soles = np.stack([xyz(bal, "left_sole"), xyz(bal, "right_sole")], axis=1)        # (n, 2, 3)
    support = bal["support"].to_numpy()
    walk = run.config["system"]["walk"]
    lengths, slip = [], 0.0
    for k in range(1, int(walk["steps"]) + 1):
        t0, t1 = k * walk["step_time"], (k + 1) * walk["step_time"]
        if t1 > t[-1] + 1e-9:
            break                        # a step the (shortened) walk did not finish
        stance = 0 if k % 2 else 1
        i0, i1 = np.searchsorted(t, t0 - 1e-9), np.searchsorted(t, t1 - 1e-9)
        lengths.append(soles[i1, 1 - stance, 0] - soles[i1, stance, 0])
        slip = max(slip, float(np.linalg.norm(soles[i0:i1 + 1, stance, :2] - soles[i0, stance, :2], axis=1).max()))
    lengths = np.array(lengths) if lengths else np.full(1, np.nan)
    out["step_length.mean"] = (float(np.mean(lengths)), "m")
    out["step_length.max_deviation"] = (float(np.max(np.abs(lengths - walk["step_length"]))), "m")
    out["stance_slip.max"] = (slip, "m")
    double = support == 0
    last = soles[double & (t >= (int(walk["steps"]) + 1) * walk["step_time"])]
    out["final_slip.max"] = (float(np.abs(last[:, :, :2] - last[0, :, :2]).max()) if len(last) else 0.0, "m")
    return out


def pair_metrics(errors: dict[str, Walk], window, prefix: str) -> dict[str, tuple[float, str]]:
    """Eq. (59) shares and the two claims on the extended/traditional pair of one model."""
    ext, trad = errors["extended"], errors["traditional"]
    n = min(len(ext.t), len(trad.t))
    out = {}
    for label, mask in (("window", window_mask(ext.t[:n], window)), ("all", np.ones(n, bool))):
        s = share(trad.com_error[:n][mask], ext.com_error[:n][mask])
        for k, axis in enumerate(XYZ):
            out[f"{prefix}share.{axis}.{label}"] = (float(s[k]), "fraction")
    mask = window_mask(ext.t[:n], window)
    rms = {g: np.sqrt(np.mean(errors[g].com_error[:n][mask, :2] ** 2, axis=0)) for g in GENERATORS}
    worst = np.maximum(rms["extended"], rms["traditional"])
    rel = np.abs(rms["extended"] - rms["traditional"]) / worst
    for k, axis in enumerate(XYZ[:2]):
        out[f"{prefix}rms_difference.{axis}"] = (float(rel[k]), "ratio")
    out[f"{prefix}claim.not_significant"] = (float((rel <= NOT_SIGNIFICANT).all()), "bool")
    largest = max(np.abs(errors[g].com_error[:n, :2]).max() for g in GENERATORS)
    out[f"{prefix}com_error.max_xy"] = (float(largest), "m")
    out[f"{prefix}claim.accurate"] = (float(largest < ACCURATE), "bool")
    return out


def analyze_walking_metrics(runs: list[Run]) -> tuple[MetricTable, dict[str, dict[str, Walk]]]:
    """Per-run metrics, then per group of runs made with the same overrides (run id `all`, or `all__<overrides>`)
    the Eq. (59) shares of each model's extended/traditional pair. Returns the errors by group and case."""
    m = MetricTable()
    errors: dict[str, dict[str, Walk]] = {}
    for params, group in sweep_pairs(runs).items():
        errors[params] = {}
        for case, run in group.items():
            w = errors[params][case] = walk_errors(run)
            lipm = case.startswith("lipm")
            m.add_run(run, error_metrics(w, scenario_window(run)) if lipm else walking_run_metrics(run))
        window = scenario_window(next(iter(group.values())))
        pair_id = "all" if params == "default" else f"all__{params}"
        # one pair per model: "extended"/"traditional" (MuJoCo), "lipm-extended"/"lipm-traditional", ...
        for prefix in sorted({c.removesuffix("extended") for c in group if c.endswith("extended")}):
            pair = {g: errors[params].get(prefix + g) for g in GENERATORS}
            if not all(pair.values()):
                continue
            label = prefix[:-1] + "." if prefix else ""          # "lipm-lag10ms-" -> "lipm-lag10ms."
            ok = all(group[prefix + g].ok for g in GENERATORS)
            m.add(pair_id, label + "walked", float(ok), "bool")
            for key, (value, unit) in pair_metrics(pair, window, label).items():
                m.add(pair_id, key, value, unit)
    return m, errors


def sweep_pairs(runs: list[Run]) -> dict[str, dict[str, Run]]:
    """Runs grouped by their overrides (the run id after `__`; `default` without) -> case -> run."""
    jobs: dict[str, dict[str, Run]] = {}
    for run in runs:
        case, _, params = run.run_id.partition("__")
        jobs.setdefault(params or "default", {})[case] = run
    return jobs
