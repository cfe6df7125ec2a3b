"""Analysis of `ur5-ik-fsm`: Tables 3-6 and the agreement from the `tables` runs, joint jumps and
execution errors along the singular paths, per-call compute time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of, timing_metrics
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable, metric_value
from analysis.core.targets import load_targets
from pipeline.core.runlog import Run
from pipeline.papers.ur5_ik_fsm.kinematics import Geometry, shoulder_term

JOINT_COLUMNS = [f"position.joint{i}" for i in range(1, 7)]
ALGORITHMS = ("alg1", "alg2")
AGREE_TOL = 1e-6     # rad: two selections are the same set (spec §7)
JUMP_THRESHOLD = 0.5  # rad: a step between samples larger than this is a jump (spec §7, assumption)
TARGETS = Path(__file__).with_name("targets.csv")


def wrap(x: np.ndarray) -> np.ndarray:
    return np.remainder(np.asarray(x) + np.pi, 2 * np.pi) - np.pi


def _nonsingular(q: np.ndarray, config: dict) -> np.ndarray:
    """Sec. 2.4 validity: |s3|, |s5| and the shoulder term above their thresholds."""
    c, g = config["system"]["conventions"], Geometry(**config["system"]["geometry"])
    return ((np.abs(np.sin(q[:, 2])) > c["s3_min"]) & (np.abs(np.sin(q[:, 4])) > c["s5_min"])
            & (np.abs(shoulder_term(q, g)) > c["shoulder_min"]))


# -- tables ------------------------------------------------------------------------------------------


def analyze_tables(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        sel = {alg: run[f"/ik/{alg}"] for alg in ALGORITHMS}
        q = {alg: sel[alg][JOINT_COLUMNS].to_numpy() for alg in ALGORITHMS}
        for alg in ALGORITHMS:
            df = sel[alg]
            for k in range(len(df)):
                test = f"{alg}.test{k + 1}"
                values = {f"{test}.theta{i + 1}": (q[alg][k, i], "rad") for i in range(6)}
                values |= {f"{test}.det_j": (df["det_j"].iloc[k], "m^3"),
                           f"{test}.abs_det_j": (abs(df["det_j"].iloc[k]), "m^3"),
                           f"{test}.diff": (df["diff"].iloc[k], "rad"),
                           f"{test}.valid_sets": (df["valid_sets"].iloc[k], "count"),
                           f"{test}.fk_error": (df["fk_error_position"].iloc[k], "m")}
                m.add_run(run, values)
        same = np.abs(wrap(q["alg1"] - q["alg2"])).max(axis=1) < AGREE_TOL
        m.add_run(run, {f"agreement.test{k + 1}": (float(s), "bool") for k, s in enumerate(same)})
        m.add_run(run, {"agreement.count": (same.sum(), "count")})
        generating = run["/ik/generating"][JOINT_COLUMNS].to_numpy()
        m.add_run(run, {"generating.nonsingular_count": (_nonsingular(generating, run.config).sum(), "count")})
        dets = np.abs(np.concatenate([sel[a]["det_j"].to_numpy() for a in ALGORITHMS]))
        m.add_run(run, {"selected.min_abs_det_j": (np.nanmin(dets), "m^3"),
                        "selected.max_fk_error": (max(sel[a]["fk_error_position"].max() for a in ALGORITHMS), "m")})
    frame = m.frame()
    _table6_figure(frame, figures)
    return frame


def _table6_figure(metrics: pd.DataFrame, figures: Figures) -> None:
    targets = load_targets(TARGETS)
    paper = targets[targets["target_id"].str.startswith("T6.")]
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2), sharey=True)
    for ax, case in zip(axes, ("independent", "sequential"), strict=True):
        ours = metrics[metrics["run_id"] == case]
        if ours.empty:
            continue
        tests = np.arange(1, 11)
        for j, alg in enumerate(ALGORITHMS):
            vals = [ours.loc[ours["metric"] == f"{alg}.test{k}.diff", "value"].iloc[0] for k in tests]
            ax.bar(tests + (j - 0.5) * 0.38, vals, width=0.38, label=f"Algorithm {alg[-1]} (pipeline)")
        if case == "independent":
            for t in paper.itertuples():
                k = int(t.target_id.split(".")[1])
                alg = t.metric.split(".")[0]
                shift = (ALGORITHMS.index(alg) - 0.5) * 0.38 if t.target_id.count(".") == 2 else 0.0
                ax.plot(k + shift, float(t.value), "k_", ms=12, mew=2)
            ax.plot([], [], "k_", ms=12, mew=2, label="paper, Table 6")
        ax.set_title(f"previous joints: {'0 (paper)' if case == 'independent' else 'last selection (ours)'}")
        ax.set_xlabel("test")
        ax.set_xticks(tests)
    axes[0].set_ylabel("joint displacement, eq. (48) [rad]")
    axes[0].legend(loc="lower left")
    figures.save(fig, "table6-displacement")


# -- singular paths ----------------------------------------------------------------------------------


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


def analyze_singular_paths(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_path: dict[str, dict[str, tuple[dict, np.ndarray, np.ndarray, Run]]] = {}
    for run in runs:
        values, q, t = _path_metrics(run)
        m.add_run(run, values)
        path, alg = run.metadata["case"].rsplit("-", 1)
        key = run.run_id.replace(run.metadata["case"], path)
        by_path.setdefault(key, {})[alg] = (values, q, t, run)
    no_larger_jump, nonsingular = [], []
    for key, algs in sorted(by_path.items()):
        nonsingular += [v[0]["all_selected_nonsingular"][0] for v in algs.values()]
        if set(algs) != set(ALGORITHMS):
            continue
        (v1, q1, _, run1), (v2, q2, _, _) = algs["alg1"], algs["alg2"]
        agree = (np.abs(wrap(q1 - q2)).max(axis=1) < AGREE_TOL)
        m.add(key, "agreement", agree.mean(), "fraction", run1.params)
        no_larger_jump.append(v2["max_joint_jump"][0] <= v1["max_joint_jump"][0] + 1e-9)
        _path_figure(key, algs, figures)
    if no_larger_jump:
        m.add("all", "claim.alg2_no_larger_jump", float(all(no_larger_jump)), "bool")
    if nonsingular:
        m.add("all", "claim.all_selected_nonsingular", float(all(nonsingular)), "bool")
    return m.frame()


def _path_figure(key: str, algs: dict, figures: Figures) -> None:
    fig, axes = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    for ax, alg in zip(axes[:2], ALGORITHMS, strict=True):
        values, q, t, _ = algs[alg]
        for i in range(6):
            ax.plot(t, q[:, i], lw=1.2, label=f"θ{i + 1}")
        qf = np.where(np.isnan(q), np.nan, q)
        steps = np.abs(wrap(np.diff(qf, axis=0))).max(axis=1)
        for k in np.flatnonzero(steps > JUMP_THRESHOLD):
            ax.axvline(t[k + 1], color="r", ls="--", lw=1)
        ax.set_ylabel(f"Algorithm {alg[-1]}\nIK joints [rad]")
        ax.set_title(f"max jump {values['max_joint_jump'][0]:.3f} rad, {values['branch_switches'][0]} branch "
                     "switches (red: jumps > 0.5 rad)", fontsize=8)
    axes[0].legend(ncol=6, fontsize=7, loc="upper right")
    for alg in ALGORITHMS:
        _, _, t, run = algs[alg]
        det = np.abs(run["/singularity"]["value.det_j"].to_numpy()) * 1e9
        axes[2].semilogy(t, np.maximum(det, 1e-6), label=f"Algorithm {alg[-1]}")
        flange = run["/tracking_error/flange"]
        axes[3].plot(flange.index, flange["norm"] * 1e3, label=f"Algorithm {alg[-1]}")
    axes[2].set_ylabel("|det J| [mm³]")
    axes[2].legend()
    axes[3].set_ylabel("executed flange\nposition error [mm]")
    axes[3].set_xlabel("time [s]")
    axes[3].legend()
    fig.suptitle(f"{key}: IK selection and MuJoCo execution")
    figures.save(fig, key)


# -- compute time ------------------------------------------------------------------------------------


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        ct = run["/compute_time"]
        counts = run["/ik/counts"]
        values, stats = {}, {}
        for alg in ALGORITHMS:
            for name in (alg, f"{alg}_batch"):
                per_item = ct[f"seconds.{name}"].dropna().to_numpy() / ct[f"calls.{name}"].dropna().to_numpy()
                stats[name] = per_item
                values |= timing_metrics(name, per_item)
            values[f"{alg}.sets_evaluated_mean"] = (counts[f"value.{alg}_sets_evaluated"].mean(), "count")
        values["valid_sets.max"] = (counts["value.valid_sets"].max(), "count")
        values["valid_sets.fraction_8"] = ((counts["value.valid_sets"] == 8).mean(), "fraction")
        values["ratio.sets_evaluated"] = (values["alg2.sets_evaluated_mean"][0] / values["alg1.sets_evaluated_mean"][0],
                                          "ratio")
        values["ratio.median_time"] = (values["alg2.median"][0] / values["alg1.median"][0], "ratio")
        m.add_run(run, values)
        fig, ax = plt.subplots(figsize=(6, 3.2))
        names = list(stats)
        med = [np.median(stats[n]) * 1e6 for n in names]
        p95 = [np.percentile(stats[n], 95) * 1e6 for n in names]
        ax.bar(names, med, color=["C0", "C0", "C1", "C1"], alpha=0.8, label="median")
        ax.errorbar(names, med, yerr=[np.zeros(len(med)), np.subtract(p95, med)], fmt="none", ecolor="k",
                    capsize=4, label="p95")
        ax.set_yscale("log")
        ax.set_ylabel("time per pose [µs]")
        ax.set_title(f"{run.run_id}: scalar (per call) and batched (per pose)")
        ax.legend()
        figures.save(fig, f"{run.run_id}-per-call")
    return m.frame()


ANALYSES = {"tables": analyze_tables, "singular-paths": analyze_singular_paths,
            "compute-time": analyze_compute_time}


# -- extra report tables -----------------------------------------------------------------------------



def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = []
    tables = metrics.get("tables")
    if tables is not None and "sequential" in set(tables["run_id"]):
        rows = [{"test": k, **{f"diff Alg {a[-1]} [rad]": metric_value(tables, "sequential", f"{a}.test{k}.diff")
                               for a in ALGORITHMS},
                 "same set": bool(metric_value(tables, "sequential", f"agreement.test{k}"))} for k in range(1, 11)]
        sections.append("## Sequential variant (our extension)\n\nThe 10 poses in order, each algorithm starting "
                        "from its own previous selection instead of 0. Agreement: "
                        f"{metric_value(tables, 'sequential', 'agreement.count'):.0f}/10.\n\n"
                        + pd.DataFrame(rows).to_markdown(index=False, floatfmt=".4f"))
    paths = metrics.get("singular-paths")
    if paths is not None:
        per_run = paths[paths["metric"].isin(["max_joint_jump", "jumps", "branch_switches", "rejected_samples",
                                              "min_abs_det_j", "max_joint_error", "max_flange_error",
                                              "max_flange_rotation_error", "saturated_fraction"])]
        table = per_run.pivot(index="run_id", columns="metric", values="value")
        table["min_abs_det_j"] = table["min_abs_det_j"] * 1e9
        table["max_flange_error"] = table["max_flange_error"] * 1e3
        table = table.rename(columns={"min_abs_det_j": "min |det J| [mm³]", "max_flange_error": "max flange err [mm]",
                                      "max_joint_jump": "max jump [rad]", "max_joint_error": "max joint err [rad]",
                                      "max_flange_rotation_error": "max flange rot err [rad]"})
        agree = paths[paths["metric"] == "agreement"].set_index("run_id")["value"]
        sections.append(
            "## Singular paths (our extension, spec §6 ii)\n\nIK at 500 Hz along each flange path, previous = last "
            "selection; then executed by the MuJoCo UR5 (joint PD + gravity compensation at 1 kHz). 'near' passes "
            "0.1 mm from the singular pose, 'through' puts a sample on it. A jump is a step > 0.5 rad between "
            "samples.\n\n" + table.reset_index().to_markdown(index=False, floatfmt=".4g")
            + "\n\nAgreement of the two algorithms per path (fraction of samples with the same set):\n\n"
            + agree.to_frame("agreement").reset_index().to_markdown(index=False, floatfmt=".3f"))
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        rows = [(f"Algorithm {name[3]}" + (" (batched, per pose)" if "batch" in name else " (per call)"), name,
                 "not reported") for name in ("alg1", "alg2", "alg1_batch", "alg2_batch")]
        sets = ", ".join(f"Algorithm {a[-1]} {metric_value(ct, 'random-poses', f'{a}.sets_evaluated_mean'):.2f}"
                         for a in ALGORITHMS)
        sections.append(compute_time_section(
            "Compute time", ct, "random-poses", rows, machine_of(runs, "compute-time"),
            note=f"Python + NumPy; the paper reports no times (MATLAB R2021a). Complete sets built per call: {sets}."))
    return sections
