"""`spherical-terrain`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.errors import error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from analysis.papers.spherical_terrain.figures import _controls, _errors, _paths_3d, _tilt, _xyz_vs_time
from analysis.papers.spherical_terrain.metrics import (
    COLOR,
    LABEL,
    MOVING,
    WINDOWS,
    _agility,
    _case,
    _per_run,
    _reference_metrics,
    convergence_time,
)
from pipeline.core.runlog import Run


def analyze_paths(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m, by_case, table = _per_run(runs)
    for name, (value, unit) in (_reference_metrics(by_case) | _agility(table)).items():
        m.add("all", name, value, unit)
    _paths_3d(by_case, "circle", "Fig. 6 regenerated: circular path on the terrain", figures, "fig06-circle-3d")
    _paths_3d(by_case, "diamond", "Fig. 7 regenerated: diamond path on the terrain", figures, "fig07-diamond-3d")
    _xyz_vs_time(by_case, "circle", "Fig. 8 regenerated: smooth path, X/Y/Z vs time", figures, "fig08-circle-xyz")
    _xyz_vs_time(by_case, "diamond", "Fig. 9 regenerated: non-smooth path, X/Y/Z vs time", figures,
                 "fig09-diamond-xyz")
    _controls(by_case, "2r", "Fig. 10 regenerated: 2R-SR control signals", figures, "fig10-2r-controls")
    _controls(by_case, "rt", "Fig. 11 regenerated: RT-SR control signals", figures, "fig11-rt-controls")
    _controls(by_case, "rs", "Fig. 12(a) regenerated: RS-SR control signals", figures, "fig12a-rs-controls")
    _tilt(by_case, figures, "fig12b-rs-tilt")
    _errors(by_case, "Tracking error, corrected equations", figures, "tracking-error")
    return m.frame()



def analyze_printed(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m, by_case, _ = _per_run(runs)
    _errors(by_case, "Tracking error with eqs. (25), (58), (60) as printed", figures, "printed-tracking-error")
    _paths_3d(by_case, "diamond", "Diamond path with eqs. (25), (58) as printed", figures, "printed-diamond-3d")
    return m.frame()



def analyze_sweep(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Per-run metrics of every sweep run on disk (swept params as columns) and a convergence-time chart."""
    m, _, _ = _per_run(runs)
    frame = m.frame()
    tc = frame[frame["metric"] == "tc_0.1"]
    if len(tc) and len(tc.columns) > 4:
        params = [c for c in tc.columns if c not in ("run_id", "metric", "value", "unit")]
        tc = tc.assign(case=tc["run_id"].str.split("__").str[0],
                       setting=tc[params].astype(str).agg(", ".join, axis=1))
        pivot = tc.pivot_table(index="case", columns="setting", values="value", aggfunc="first", dropna=False)
        fig, ax = plt.subplots(figsize=(9, 3.6))
        width = 0.8 / max(1, pivot.shape[1])
        x = np.arange(len(pivot))
        for j, setting in enumerate(pivot.columns):
            values = pivot[setting].to_numpy(dtype=float)
            ax.bar(x + j * width, np.nan_to_num(values, nan=0.0), width, label=setting)
            ax.plot(x[np.isnan(values)] + j * width, np.full(np.isnan(values).sum(), 1.0), "kx")
        ax.axhline(30.0, color="k", ls="--", lw=1)
        ax.set_xticks(x + 0.4 - width / 2, pivot.index, rotation=30, fontsize=7)
        ax.set_ylabel("t_c(0.1 m) [s]  (x: never)")
        ax.set_title(f"Sweep over {', '.join(params)}")
        ax.legend(fontsize=6, ncol=2)
        figures.save(fig, "sweep-convergence-time")
    return frame



def analyze_physics(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """The ball on the MuJoCo height field against the paper's no-slip model (eq. 31) and exact rigid
    rolling, both fed the ball's own measured ω; and closed-loop tracking against the kinematic model."""
    m = MetricTable()
    fig, axes = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    for run in runs:
        robot, _ = _case(run)
        phys = run["/physics"]
        t = phys.index.to_numpy()
        actual, paper = phys["value.actual_speed"].to_numpy(), phys["value.paper_speed"].to_numpy()
        moving = paper > MOVING
        ratio = actual[moving] / paper[moving]
        error_paper = phys["value.paper_model_error"].to_numpy()
        error_rigid = phys["value.rigid_model_error"].to_numpy()
        e, e_kin = run["/tracking_error"]["norm"].to_numpy(), run["/tracking_error/kinematic_model"]["norm"]
        window = t >= WINDOWS[0]
        if window.any():
            m.add_run(run, error_stats(t[window], e[window], "error_after_40s", "m")
                      | {f"kinematic.{k}": v for k, v in error_stats(t[window], e_kin.to_numpy()[window],
                                                                     "error_after_40s", "m").items()})
        m.add_run(run, {
            "paper_model_error.weighted": (error_paper.sum() / paper.sum(), "fraction"),
            "paper_model_error.median": (float(np.median(error_paper[moving] / paper[moving])), "fraction"),
            "rigid_model_error.weighted": (error_rigid.sum() / paper.sum(), "fraction"),
            "rigid_model_error.median": (float(np.median(error_rigid[moving] / paper[moving])), "fraction"),
            "speed_ratio.p05": (float(np.percentile(ratio, 5)), "ratio"),
            "speed_ratio.p95": (float(np.percentile(ratio, 95)), "ratio"),
            "slip.median": (float(np.median(phys["value.slip_speed"])), "m/s"),
            "slip.mean": (float(phys["value.slip_speed"].mean()), "m/s"),
            "gap.max_penetration": (max(0.0, -float(phys["value.gap"].min())), "m"),
            "drive.omega_error_median": (float(np.median(phys["value.omega_error"])), "rad/s"),
            "tc_0.1": (convergence_time(t, e, 0.1), "s"),
            "kinematic.tc_0.1": (convergence_time(t, e_kin.to_numpy(), 0.1), "s"),
        })
        axes[0].plot(t[moving], actual[moving] / paper[moving], ".", ms=1, color=COLOR[robot], label=LABEL[robot])
        axes[1].semilogy(t, np.maximum(phys["value.slip_speed"], 1e-6), color=COLOR[robot], lw=0.6)
        axes[2].semilogy(t, np.maximum(e, 1e-5), color=COLOR[robot], lw=0.9, label=f"{LABEL[robot]} MuJoCo")
        axes[2].semilogy(e_kin.index, np.maximum(e_kin, 1e-5), color=COLOR[robot], lw=0.7, ls=":")
    axes[0].set_ylabel("contact speed:\nMuJoCo / paper model")
    axes[0].set_ylim(0.5, 1.5)
    axes[0].legend(fontsize=7, markerscale=8)
    axes[1].set_ylabel("slip speed [m/s]")
    axes[2].set_ylabel("‖e_t‖ [m]\n(dotted: kinematic)")
    axes[2].set_xlabel("time [s]")
    fig.suptitle("Physics check: ball on a MuJoCo height field, the paper's controller in closed loop")
    figures.save(fig, "physics-check")
    return m.frame()



ANALYSES = {"paths": analyze_paths, "printed": analyze_printed, "sweep": analyze_sweep,
            "physics-check": analyze_physics}
