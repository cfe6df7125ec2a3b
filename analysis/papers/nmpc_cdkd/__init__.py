"""Analysis of `nmpc-cdkd`: Table 3 (OCP solve times and their ratios), Fig. 3 (tracking errors), Figs. 4-5 (fixed
obstacles: clearance, swerve, detour, arrival) and Figs. 6-7 (moving obstacles)."""

from __future__ import annotations

import itertools
from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of, timing_metrics
from analysis.core.errors import error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable, metric_value
from analysis.core.targets import load_targets
from pipeline.core.runlog import Run

XYZ = ("x", "y", "z")
ARRIVAL_POSITION = 1e-3            # m   (spec §7.7)
ARRIVAL_ANGLE = np.deg2rad(0.5)    # rad
FINAL_WINDOW = 0.5                 # s: "final error" = mean over the last 0.5 s (spec §7.2)
CONTROL_HORIZON = 0.04             # s: 4 × 10 ms; solves longer than this delay the robot (Sec. 4.2)
TARGETS = Path(__file__).with_name("targets.csv")
CASE_LABELS = {"no-obstacle": "without obstacles", "obstacle": "with obstacle",
               "obstacle-height": "with obstacle and height constraints"}


@cache
def paper_table3() -> dict[tuple[str, str, int], tuple[float, float]]:
    """(model, case, k) -> Table 3's (t̄, σ) in ms, from targets.csv."""
    t = load_targets(TARGETS).set_index("target_id")["value"]
    row = "Tab3.{}.N{}.{}.{}".format
    return {(model, case, k): (float(t[row(case, n, short, "mean")]), float(t[row(case, n, short, "std")]))
            for model, short in (("decomposed", "dec"), ("full", "full")) for case in CASE_LABELS
            for n, k in ((1, 10), (2, 20))}


def _xyz(frame: pd.DataFrame, field: str) -> np.ndarray:
    return frame[[f"{field}.{a}" for a in XYZ]].to_numpy()


def _solve_metrics(solves: pd.DataFrame) -> dict[str, tuple[float, str]]:
    s = solves["seconds"].to_numpy()
    values = {"solve.mean": (s.mean(), "s"), "solve.std": (s.std(), "s"), **timing_metrics("solve", s),
              "solve.samples": (len(s), "count"), "solve.iterations_mean": (solves["iterations"].mean(), "count"),
              "solve.iterations_max": (solves["iterations"].max(), "count"),
              "solve.failures": (int((~solves["success"].astype(bool)).sum()), "count"),
              "solve.over_control_horizon": ((s > CONTROL_HORIZON).mean(), "fraction"),
              "solve.casadi_mean": (solves["solver_seconds"].mean(), "s")}
    return values


# -- Table 3 -----------------------------------------------------------------------------------------------


def _combo(run_id: str) -> tuple[str, str, int]:
    model, rest = run_id.split("__")[0].split("-", 1)
    case, k = rest.rsplit("-k", 1)
    return model, case, int(k)


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    mean, std = {}, {}
    for run in runs:
        values = _solve_metrics(run["/nmpc/solve"])
        m.add_run(run, values)
        mean[_combo(run.run_id)], std[_combo(run.run_id)] = values["solve.mean"][0], values["solve.std"][0]
    cases = sorted({c for _, c, _ in mean}, key=list(CASE_LABELS).index)
    horizons = sorted({k for *_, k in mean})
    table = {}
    for case in cases:
        for k in horizons:
            if ("decomposed", case, k) in mean and ("full", case, k) in mean:
                table[f"ratio.{case}.k{k}"] = (mean["decomposed", case, k] / mean["full", case, k], "ratio")
                table[f"sigma_ratio.{case}.k{k}"] = (std["decomposed", case, k] / std["full", case, k], "ratio")
        for model in ("decomposed", "full"):
            if len(horizons) == 2 and all((model, case, k) in mean for k in horizons):
                table[f"growth.{model}.{case}"] = (mean[model, case, horizons[1]] / mean[model, case, horizons[0]] - 1,
                                                   "fraction")
    for model in ("decomposed", "full"):
        for k in horizons:
            if (model, "no-obstacle", k) in mean and (model, "obstacle-height", k) in mean:
                table[f"complexity.{model}.k{k}"] = (mean[model, "obstacle-height", k] / mean[model, "no-obstacle", k],
                                                     "ratio")
    ratios = [v for key, (v, _) in table.items() if key.startswith("ratio.")]
    sigma = [v for key, (v, _) in table.items() if key.startswith("sigma_ratio.")]
    if ratios:
        table["claim.ratio_max"] = (max(ratios), "ratio")
        table["claim.ratio_min"] = (min(ratios), "ratio")
        table["claim.sigma_lower_everywhere"] = (float(all(v < 1 for v in sigma)), "bool")
    for model in ("decomposed", "full"):
        growth = [v for key, (v, _) in table.items() if key.startswith(f"growth.{model}.")]
        if growth:
            table[f"claim.growth_max.{model}"] = (max(growth), "fraction")
    complexity = [(table.get(f"complexity.full.k{k}"), table.get(f"complexity.decomposed.k{k}")) for k in horizons]
    if all(f and d for f, d in complexity):
        table["claim.full_grows_with_complexity_more"] = (float(all(f[0] > d[0] for f, d in complexity)), "bool")
    for metric, (value, unit) in table.items():
        m.add("table3", metric, value, unit)
    _table3_figure(mean, std, figures)
    return m.frame()


def _table3_figure(mean: dict, std: dict, figures: Figures) -> None:
    if not mean:
        return
    keys = [k for k in paper_table3() if k in mean]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    x = np.arange(len(keys))
    labels = [f"{'dec' if m == 'decomposed' else 'full'} {c.replace('obstacle', 'obst')} N{1 if k == 10 else 2}"
              for m, c, k in keys]
    for ax, (title, values) in zip(axes, (("pipeline", {k: (mean[k] * 1e3, std[k] * 1e3) for k in keys}),
                                          ("paper, Table 3 (i7-8550U, MATLAB)", paper_table3())), strict=True):
        colors = ["C0" if k[0] == "decomposed" else "C1" for k in keys]
        ax.bar(x, [values[k][0] for k in keys], yerr=[values[k][1] for k in keys], color=colors, capsize=3)
        ax.set_xticks(x, labels, rotation=60, ha="right", fontsize=7)
        ax.set_ylabel("OCP solve time t̄ ± σ [ms]")
        ax.set_title(title)
    figures.save(fig, "table3-solve-times")


# -- trajectories: Figs. 3-7 -------------------------------------------------------------------------------


def _arrival(run: Run) -> float:
    """First time from which the tool stays within 1 mm of the goal and 0.5° of the desired orientation (the
    angle from the logged quaternion error: |ẽ| = sin(angle / 2))."""
    ref, tool, orient = run["/reference/tool"], run["/tracking_error"], run["/tracking_error/orientation"]
    goal = _xyz(ref, "position")[-1]
    position = _xyz(ref, "position") - _xyz(tool, "error")
    angle = 2 * np.arcsin(np.clip(orient["norm"].to_numpy(), 0, 1))
    inside = (np.linalg.norm(position - goal, axis=1) < ARRIVAL_POSITION) & (angle < ARRIVAL_ANGLE)
    if not inside[-1]:
        return float("nan")
    outside = np.flatnonzero(~inside)
    return float(tool.index[outside[-1] + 1] if len(outside) else tool.index[0])


def _trajectory_metrics(run: Run) -> dict[str, tuple[float, str]]:
    sc = run.config["scenario"]
    tool, wrist, orient = run["/tracking_error"], run["/tracking_error/wrist"], run["/tracking_error/orientation"]
    moving = tool.index >= sc["t0"]
    t = tool.index.to_numpy()[moving]
    final = tool.index.to_numpy() >= tool.index[-1] - FINAL_WINDOW
    values = {**error_stats(t, tool["norm"].to_numpy()[moving], "tool_error", "m"),
              **error_stats(t, wrist["norm"].to_numpy()[moving], "wrist_error", "m"),
              "tool_error.final": (tool["norm"].to_numpy()[final].mean(), "m"),
              "wrist_error.final": (wrist["norm"].to_numpy()[final].mean(), "m"),
              "orientation_error.max_component": (np.abs(_xyz(orient, "error")).max(), "1"),
              **{f"tool_error.max_{a}": (np.abs(tool[f"error.{a}"]).max(), "m") for a in XYZ}}
    arrival = _arrival(run)
    values["arrival"] = (arrival, "s")
    values["arrival_delay"] = (arrival - sc["t1"], "s")
    values |= timing_metrics("planning", run["/compute_time"]["seconds.planning"].dropna())
    values |= _solve_metrics(run["/nmpc/solve"])
    return values


def _obstacle_metrics(run: Run) -> dict[str, tuple[float, str]]:
    clearance = run["/clearance"]
    band = run.config["system"]["scene"]["band"]
    wrist = run["/reference/wrist"]
    ref = _xyz(wrist, "position")
    actual = ref - _xyz(run["/tracking_error/wrist"], "error")
    cols = lambda prefix: [c for c in clearance.columns if c.startswith(f"value.{prefix}.")]  # noqa: E731
    values = {"clearance.margin_min": (clearance[cols("margin")].to_numpy().min(), "m"),
              "clearance.command_margin_min": (clearance[cols("command_margin")].to_numpy().min(), "m"),
              "clearance.tool_min": (clearance[cols("tool")].to_numpy().min(), "m"),
              "wrist.z_rise_max": ((actual[:, 2] - ref[:, 2]).max(), "m"),
              "wrist.z_max": (actual[:, 2].max(), "m"),
              "wrist.xy_deviation_max": (np.linalg.norm(actual[:, :2] - ref[:, :2], axis=1).max(), "m"),
              "wrist.band_violation_upper": (max(0.0, actual[:, 2].max() - band[1]), "m"),
              "wrist.band_violation_lower": (max(0.0, band[0] - actual[:, 2].min()), "m")}
    if cols("mujoco"):
        values["clearance.mujoco_min"] = (clearance[cols("mujoco")].to_numpy().min(), "m")
    for column in cols("margin") + cols("tool"):  # per obstacle: value.margin.I_v -> clearance.margin_min.I_v
        kind, name = column.removeprefix("value.").split(".", 1)
        values[f"clearance.{kind}_min.{name}"] = (clearance[column].min(), "m")
    return values


def _components_figure(runs: list[Run], figures: Figures, name: str, title: str) -> None:
    """Figs. 5 and 7: tool position components vs time, reference dashed."""
    fig, axes = plt.subplots(1, len(runs), figsize=(4.2 * len(runs), 3.2), sharey=True, squeeze=False)
    for ax, run in zip(axes[0], runs, strict=True):
        ref = run["/reference/tool"]
        actual = _xyz(ref, "position") - _xyz(run["/tracking_error"], "error")
        for i, a in enumerate(XYZ):
            ax.plot(ref.index, actual[:, i] * 1e3, color=f"C{i}", label=f"$p_{a}$")
            ax.plot(ref.index, ref[f"position.{a}"] * 1e3, color=f"C{i}", ls="--", lw=1, label=f"$p_{{{a},des}}$")
        ax.set_title(run.run_id)
        ax.set_xlabel("t [s]")
    axes[0, 0].set_ylabel("tool position [mm]")
    axes[0, 0].legend(ncol=2, fontsize=7)
    fig.suptitle(title)
    figures.save(fig, name)


def analyze_tracking(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    tool_error = {}
    for run in runs:
        values = _trajectory_metrics(run)
        ref_z = run["/reference/tool"]["position.z"]
        dip = (ref_z - ref_z.iloc[0]).abs()
        values["reference.z_deviation_max"] = (dip.max(), "m")
        values["reference.z_deviation_time"] = (float(dip.idxmax()), "s")
        values["claim.no_stationary_error"] = (float(values["tool_error.final"][0] < ARRIVAL_POSITION), "bool")
        values["claim.lag_from_orientation"] = (
            float(values["wrist_error.max"][0] < 0.1 * values["tool_error.max"][0]), "bool")
        m.add_run(run, values)
        tool_error[run.metadata["case"]] = (run.config["system"]["dh"]["tool_d"], values["tool_error.max"][0])
        _fig3(run, figures)
    for model in ("decomposed", "full"):  # Sec. 4.2: a shorter d_e gives smaller amplitudes in Fig. 3b
        pairs = sorted(v for case, v in tool_error.items() if case.split("-de")[0] == model)
        if len(pairs) > 1:
            m.add("all", f"claim.shorter_tool_smaller_error.{model}",
                  float(all(a[1] < b[1] for a, b in itertools.pairwise(pairs))), "bool")
    return m.frame()


def _fig3(run: Run, figures: Figures) -> None:
    tool, orient, ref = run["/tracking_error"], run["/tracking_error/orientation"], run["/reference/tool"]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2))
    actual = _xyz(ref, "position") - _xyz(tool, "error")
    for i, a in enumerate(XYZ):
        axes[0].plot(ref.index, actual[:, i] * 1e3, color=f"C{i}", label=f"$p_{a}$")
        axes[0].plot(ref.index, ref[f"position.{a}"] * 1e3, color=f"C{i}", ls="--", lw=1)
        axes[1].plot(tool.index, tool[f"error.{a}"] * 1e3, color=f"C{i}", label=f"$\\tilde p_{a}$")
        axes[2].plot(orient.index, orient[f"error.{a}"], color=f"C{i}", label=f"$\\tilde e_{a}$")
    axes[1].plot(tool.index, tool["norm"] * 1e3, "k", label="$\\|\\tilde p\\|$")
    for ax, ylabel, title in zip(axes, ("tool position [mm]", "tool position error [mm]", "quaternion error (11)"),
                                 ("(a) tracking, dashed: des", "(b) $p_{des} - p$", "(c) orientation error"),
                                 strict=True):
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.legend(fontsize=7)
    fig.suptitle(f"Fig. 3 ({run.run_id}, d_e = {run.config['system']['dh']['tool_d'] * 1e3:g} mm): no obstacles, "
                 "t0 = 0.5 s, t1 = 2 s")
    figures.save(fig, f"fig3-{run.run_id}")


def analyze_fixed_obstacles(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_case = {}
    for run in runs:
        values = _trajectory_metrics(run) | _obstacle_metrics(run)
        m.add_run(run, values)
        by_case[run.metadata["case"]] = values
    if {"a", "b"} <= set(by_case):
        a, b = by_case["a"], by_case["b"]
        m.add("all", "claim.a_swerves_up_b_stays_in_band",
              float(a["wrist.z_max"][0] > b["wrist.z_max"][0] + 0.02 and b["wrist.band_violation_upper"][0] < 1e-3),
              "bool")
        m.add("all", "claim.b_detours_more_in_xy",
              float(b["wrist.xy_deviation_max"][0] > a["wrist.xy_deviation_max"][0]), "bool")
    ordered = sorted(runs, key=lambda r: r.run_id)
    _paths_figure(ordered, figures, "fig4-paths", "Fig. 4: tool paths (a: lower height bound only, b: height band)")
    _components_figure(ordered, figures, "fig5-components", "Fig. 5: tool position vs time with four fixed obstacles")
    return m.frame()


def analyze_moving_obstacles(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _trajectory_metrics(run) | _obstacle_metrics(run))
    ordered = sorted(runs, key=lambda r: r.run_id)
    for run in ordered:
        _snapshots_figure(run, figures)
    _components_figure(ordered, figures, "fig7-components", "Fig. 7: tool position vs time with moving obstacles")
    return m.frame()


def _obstacle_layout(run: Run) -> tuple[list[str], np.ndarray, pd.DataFrame]:
    scene = run.config["system"]["scene"]
    return list(scene["obstacles"]["names"]), np.asarray(scene["obstacles"]["radii"]), run["/obstacles"]


def _paths_figure(runs: list[Run], figures: Figures, name: str, title: str) -> None:
    fig = plt.figure(figsize=(6.5, 5))
    ax = fig.add_subplot(projection="3d")
    ref = runs[0]["/reference/tool"]
    ax.plot(*(ref[f"position.{a}"] * 1e3 for a in XYZ), "b--", label="reference")
    for i, run in enumerate(runs):
        tool = _xyz(run["/reference/tool"], "position") - _xyz(run["/tracking_error"], "error")
        ax.plot(*(tool.T * 1e3), color=("C1", "C3", "C2")[i % 3], label=f"case {run.run_id}")
    names, radii, centres = _obstacle_layout(runs[0])
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 16), np.linspace(0, np.pi, 9))
    for n, r in zip(names, radii, strict=True):
        c = np.array([centres[f"value.{n}.{a}"].iloc[0] for a in XYZ]) * 1e3
        ax.plot_surface(c[0] + r * 1e3 * np.cos(u) * np.sin(v), c[1] + r * 1e3 * np.sin(u) * np.sin(v),
                        c[2] + r * 1e3 * np.cos(v), color="g", alpha=0.5)
        ax.text(*c, n)
    ax.set_box_aspect(np.ptp(np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()]), axis=1) * [1, 1, 3])
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zlabel("z [mm] (stretched 3×)")
    ax.set_zticks(np.round(np.linspace(*ax.get_zlim(), 3), -1))
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    figures.save(fig, name)


def _snapshots_figure(run: Run, figures: Figures, count: int = 7) -> None:
    """Fig. 6: the obstacles (green), their safety spheres at the wrist height (orange), the tool path so far."""
    names, radii, centres = _obstacle_layout(run)
    ref = run["/reference/tool"]
    tool = _xyz(ref, "position") - _xyz(run["/tracking_error"], "error")
    wrist = _xyz(run["/reference/wrist"], "position") - _xyz(run["/tracking_error/wrist"], "error")
    safety = radii + float(run.config["system"]["dh"]["d"][5]) + float(run.config["system"]["dh"]["tool_d"])
    times = ref.index.to_numpy()
    picks = np.linspace(0, len(times) - 1, count).round().astype(int)
    fig, axes = plt.subplots(1, count, figsize=(2.3 * count, 2.8), sharex=True, sharey=True)
    for ax, j in zip(axes, picks, strict=True):
        ax.plot(ref["position.x"] * 1e3, ref["position.y"] * 1e3, "b--", lw=0.8)
        ax.plot(tool[:j + 1, 0] * 1e3, tool[:j + 1, 1] * 1e3, color="C1")
        for n, r, s in zip(names, radii, safety, strict=True):
            c = np.array([centres[f"value.{n}.{a}"].iloc[j] for a in XYZ])
            height = abs(wrist[j, 2] - c[2])
            ax.add_patch(plt.Circle(c[:2] * 1e3, r * 1e3, color="g"))
            if height < s:
                ax.add_patch(plt.Circle(c[:2] * 1e3, np.sqrt(s * s - height * height) * 1e3, color="orange",
                                        fill=False))
        ax.set_aspect("equal")
        ax.set_title(f"t = {times[j]:.2f} s", fontsize=8)
    axes[0].set_ylabel("y [mm]")
    fig.suptitle(f"Fig. 6, case {run.run_id}: obstacles (green), safety sphere at the wrist height (orange)")
    figures.save(fig, f"fig6-{run.run_id}")


ANALYSES = {"compute-time": analyze_compute_time, "tracking": analyze_tracking,
            "fixed-obstacles": analyze_fixed_obstacles, "moving-obstacles": analyze_moving_obstacles}


# -- extra report tables -----------------------------------------------------------------------------------



TRAJECTORY_COLUMNS = [  # (metric, column, factor from SI)
    ("tool_error.max", "max ‖p̃‖ [mm]", 1e3), ("tool_error.rms", "RMS ‖p̃‖ [mm]", 1e3),
    ("tool_error.final", "final ‖p̃‖ [mm]", 1e3), ("wrist_error.max", "max wrist error [mm]", 1e3),
    ("orientation_error.max_component", "max |ẽ_i|", 1.0), ("arrival_delay", "arrival − t1 [s]", 1.0),
    ("clearance.margin_min", "min (10f) margin [mm]", 1e3),
    ("clearance.command_margin_min", "min (10f) margin, commanded [mm]", 1e3),
    ("clearance.tool_min", "min tool clearance [mm]", 1e3),
    ("clearance.mujoco_min", "min MuJoCo clearance [mm]", 1e3), ("wrist.z_max", "max wrist z [mm]", 1e3),
    ("wrist.xy_deviation_max", "max wrist xy deviation [mm]", 1e3), ("solve.mean", "t̄ solve [ms]", 1e3),
    ("solve.failures", "failed solves", 1.0), ("planning.median", "planning, median [ms]", 1e3)]


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = []
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        rows, combos = [], [r for r in ct["run_id"].unique() if r != "table3"]
        for run_id in sorted(combos, key=lambda r: (list(CASE_LABELS).index(_combo(r)[1]), _combo(r)[2], r)):
            model, case, k = _combo(run_id)
            paper = paper_table3().get((model, case, k))
            rows.append({"movement": CASE_LABELS[case], "horizon": f"N{1 if k == 10 else 2} (k = {k})", "model": model,
                         "t̄ ± σ [ms]": f"{metric_value(ct, run_id, 'solve.mean') * 1e3:.1f} ± "
                                       f"{metric_value(ct, run_id, 'solve.std') * 1e3:.1f}",
                         "paper t̄ ± σ [ms]": f"{paper[0]:g} ± {paper[1]:g}" if paper else "",
                         "median [ms]": metric_value(ct, run_id, "solve.median") * 1e3,
                         "p95 [ms]": metric_value(ct, run_id, "solve.p95") * 1e3,
                         "IPOPT iterations": metric_value(ct, run_id, "solve.iterations_mean"),
                         "failed solves": int(metric_value(ct, run_id, "solve.failures")),
                         "> 40 ms": metric_value(ct, run_id, "solve.over_control_horizon"),
                         "samples": int(metric_value(ct, run_id, "solve.samples"))})
        table = pd.DataFrame(rows).to_markdown(index=False, floatfmt=".3g")
        ratio_rows = [{"movement": CASE_LABELS[c],
                       **{f"dec/full N{i + 1}": metric_value(ct, "table3", f"ratio.{c}.k{k}")
                                                       for i, k in enumerate((10, 20))},
                       "growth N1→N2 dec": metric_value(ct, "table3", f"growth.decomposed.{c}"),
                       "growth N1→N2 full": metric_value(ct, "table3", f"growth.full.{c}")} for c in CASE_LABELS]
        sections.append(
            "## Table 3: OCP solve time per step\n\nEach NMPC runs its own closed loop (ideal kinematic plant) over "
            "the same seeded random point-to-point moves; the 12 loops advance one solve each in turn, so machine "
            "load falls on all alike. Every solve is one sample (wall time of the IPOPT call, warm-started); failed "
            "solves are counted, not dropped. More moves: `scenario.moves=10`.\n\n" + table
            + "\n\nRatios (paper: 0.13–0.20; growth dec +15/+22/+24 %, full +66/+37/+23 %):\n\n"
            + pd.DataFrame(ratio_rows).to_markdown(index=False, floatfmt=".3f"))
        merged = ct.assign(metric=ct["run_id"] + "/" + ct["metric"], run_id="all")
        sections.append(compute_time_section(
            "Compute time per OCP step (median and p95)", merged, "all",
            [(f"{_combo(r)[0]}, {CASE_LABELS[_combo(r)[1]]}, k = {_combo(r)[2]}", f"{r}/solve",
              "t̄ ± σ = {:g} ± {:g} ms".format(*paper_table3()[_combo(r)])) for r in sorted(combos)],
            machine_of(runs, "compute-time"), unit="ms",
            note="Python + CasADi + IPOPT (MUMPS), no code generation; the paper: MATLAB R2020a + CasADi + IPOPT "
                 "on an i7-8550U."))
    for name, title in (("tracking", "Tracking (Fig. 3)"), ("fixed-obstacles", "Fixed obstacles (Figs. 4-5)"),
                        ("moving-obstacles", "Moving obstacles (Figs. 6-7)")):
        frame = metrics.get(name)
        if frame is None or frame.empty:
            continue
        shown = frame[frame["run_id"] != "all"]
        present = [c for c in TRAJECTORY_COLUMNS if c[0] in set(shown["metric"])]
        table = shown.pivot(index="run_id", columns="metric", values="value")
        table = pd.DataFrame({label: table[metric] * factor for metric, label, factor in present})
        sections.append(f"## {title}\n\n" + table.reset_index().to_markdown(index=False, floatfmt=".4g"))
    return sections
