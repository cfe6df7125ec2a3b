"""`scara-half-derivative`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib import ticker

from analysis.core.figures import PAPER_STYLE, Figures, plt
from analysis.core.targets import paper_value
from analysis.papers.scara_half_derivative.metrics import (
    AXES,
    CONTROLLER_COLORS,
    FULL_PLOT_STRIDE,
    KD_DAMPING,
    SCALE,
    SLUG,
    ZOOM,
    _stiffness_id,
    equal_ice_locus,
    paper_table2,
)
from pipeline.core.runlog import Run


def _setpoint_figures(ref: pd.DataFrame, joints: pd.DataFrame, figures: Figures) -> None:
    t = ref.index.to_numpy()
    fig, axes = plt.subplots(3, 1, figsize=(8, 6.5), sharex=True)
    for ax, (field, label) in zip(axes, (("position", "position [m]"), ("velocity", "velocity [m/s]"),
                                          ("acceleration", "acceleration [m/s²]")), strict=True):
        for axis in AXES:
            ax.plot(t, ref[f"{field}.{axis}"], lw=1, label=axis)
        ax.set_ylabel(label)
    axes[0].legend(ncol=3)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle("Fig. 4: set-point of the end-effector (d = 0.15 m, t_mov = 0.3 s, t_stop = 1 s, α = 0.2)")
    figures.save(fig, "fig4-setpoint")
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for i in range(1, 5):
        ax.plot(joints.index, np.rad2deg(joints[f"position.theta{i}"]), lw=1.2, label=f"θ{i}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("joint position [°]")
    ax.legend(ncol=4)
    ax.set_title("Fig. 5: internal coordinates of the set-point motion (inverse kinematics)")
    figures.save(fig, "fig5-joints")


def _error_figures(k: float, controllers: dict[str, tuple[Run, dict]], figures: Figures, name: str) -> None:
    """Figs. 8-10: e_x, e_y, e_z of the three controllers, the whole run and a zoom on the largest peak."""
    for fig_number, axis in zip((8, 9, 10), AXES, strict=True):
        fig, (full, zoom) = plt.subplots(1, 2, figsize=(10, 3.4), gridspec_kw={"width_ratios": [2.2, 1]})
        errors = {name: controllers[name][0]["/tracking_error"][f"error.{axis}"] * 1e3
                  for name in ("kd", "kdhd", "khd") if name in controllers}
        if not errors:
            plt.close(fig)
            continue
        peak = float(next(iter(errors.values())).abs().idxmax())   # KD's largest error, or the first run's
        for name, err in errors.items():
            full.plot(err.index[::FULL_PLOT_STRIDE], err.to_numpy()[::FULL_PLOT_STRIDE], lw=0.9,
                      color=CONTROLLER_COLORS[name], label=name.upper())
            window = err.loc[peak - ZOOM[0]:peak + ZOOM[1]]
            zoom.plot(window.index, window, lw=1.1, color=CONTROLLER_COLORS[name])
            printed = paper_value(SLUG, f"T2.e{axis}_max.{name}.k8e5")   # Table 2's max |e|, at ± on the plot
            for ax in (full, zoom):
                for sign in (1, -1):
                    ax.axhline(sign * printed, color=CONTROLLER_COLORS[name], ls="--", lw=0.8, alpha=0.8)
        full.plot([], [], "k--", lw=0.8, label="paper: max |e| (Table 2)")
        full.set_xlabel("time [s]")
        zoom.set_xlabel("time [s] (peak zone)")
        full.set_ylabel(f"e_{axis} [mm]")
        full.legend(ncol=3, loc="center", bbox_to_anchor=(0.5, 0.75))   # between the traces and the paper lines
        fig.suptitle(f"Fig. {fig_number}: error e_{axis}, K = {k:g} N/m")
        figures.save(fig, f"fig{fig_number}-e{axis}-{name}")


def _map_figure(k: float, grid: pd.DataFrame, level: float, points: list, figures: Figures, name: str) -> None:
    """Fig. 6 as surfaces (red, with the KD level as a green plane) and as contour maps with the equal-ICE
    points, our fitted line and eq. (20)."""
    ice = grid.pivot(index="hd_xyz", columns="d_xyz", values="ice")
    ise = grid.pivot(index="hd_xyz", columns="d_xyz", values="ise")
    if min(ice.shape) < 2:   # a single line of the grid: curves instead of surfaces
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.4))
        for ax, table, label in zip(axes, (ice, ise), ("ICE [N²m²s]", "ISE [m²s]"), strict=True):
            for hd, row in table.iterrows():
                ax.plot(row.index, row.to_numpy(), "o-", label=f"hd_xyz = {hd:g}")
            ax.set_xlabel("d_xyz [Ns/m]")
            ax.set_ylabel(label)
        axes[0].legend()
        fig.suptitle(f"Fig. 6 (one grid line on disk), K = {k:g} N/m")
        figures.save(fig, f"fig6-maps-{name}")
        return
    D, HD = np.meshgrid(ice.columns.to_numpy(), ice.index.to_numpy())
    fig = plt.figure(figsize=(11, 8))
    kd_ise = grid[(grid["hd_xyz"] == 0) & np.isclose(grid["d_xyz"], KD_DAMPING)]["ise"]
    for col, (table, label, plane) in enumerate(
            ((ice, "ICE [N²m²s]", level), (ise, "ISE [m²s]", kd_ise.iloc[0] if len(kd_ise) else np.nan))):
        ax = fig.add_subplot(2, 2, col + 1, projection="3d")
        ax.plot_surface(D, HD, table.to_numpy(), color="tab:red", alpha=0.75, edgecolor="k", lw=0.3)
        if np.isfinite(plane):
            ax.plot_surface(D, HD, np.full(D.shape, plane), color="tab:green", alpha=0.25)
        ax.set_xlabel("d_xyz [Ns/m]")
        ax.set_ylabel("hd_xyz [Ns^½/m]")
        ax.set_zlabel(label)
        flat = fig.add_subplot(2, 2, col + 3)
        values = table.to_numpy()
        wide = np.nanmax(values) > 10 * np.nanmin(values)   # near-unstable corners: a log scale keeps the rest
        filled = flat.contourf(D, HD, values, levels=12, cmap="viridis",
                               locator=ticker.LogLocator(subs="all") if wide else None)
        fig.colorbar(filled, ax=flat, label=label)
        if np.isfinite(plane):
            flat.contour(D, HD, table.to_numpy(), levels=[plane], colors="w", linewidths=1.5)
        d_line = np.linspace(D.min(), D.max(), 50)
        flat.plot(d_line, 47200 - 9.44 * d_line, "y:", lw=2, label="eq. (20)")
        if len(points) >= 2:
            d, hd = np.array(points).T
            slope, intercept = np.polyfit(d, hd, 1)
            flat.plot(d, hd, "wo", ms=4)
            flat.plot(d_line, intercept + slope * d_line, "w--", lw=1, label="fitted equal-ICE line")
        flat.set_ylim(HD.min(), HD.max())
        flat.set_xlabel("d_xyz [Ns/m]")
        flat.set_ylabel("hd_xyz [Ns^½/m]")
        flat.legend(loc="upper right", fontsize=7)
    fig.suptitle(f"Fig. 6: ICE (left) and ISE (right) over the grid on disk, K = {k:g} N/m "
                 "(green: KD at d = 5000; white: its level)")
    figures.save(fig, f"fig6-maps-{name}")


def _path_figure(k: float, path: pd.DataFrame, ratio: pd.DataFrame, figures: Figures, name: str) -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    d = path["d_xyz"].to_numpy()
    left.plot(d, path["ise"], "o-", color="C0", label="ISE")
    left.set_xlabel("d_xyz [Ns/m]")
    left.set_ylabel("ISE [m²s]", color="C0")
    left.invert_xaxis()
    twin = left.twinx()
    twin.plot(d, path["hd_xyz"], "s-", color="C1", label="hd_xyz")
    twin.set_ylabel("hd_xyz [Ns^½/m]", color="C1")
    twin.spines["right"].set_visible(True)
    for i in range(1, 4):
        right.plot(d, 100 * ratio[f"tau{i}.max"], "o-", label=f"τ{i}")
    right.plot(d, 100 * ratio["ice"], "k--", lw=1, label="ICE")
    right.set_xlabel("d_xyz [Ns/m]")
    right.set_ylabel("% of KD (d = 5000)")
    right.invert_xaxis()
    right.legend(ncol=2)
    fig.suptitle(f"Fig. 7: along eq. (20), KD (d = 5000) to KHD (d = 0), K = {k:g} N/m")
    figures.save(fig, f"fig7-path-{name}")


BAND_ROWS = ("e.x.max", "e.y.max", "e.z.max", "e.x.mean", "e.y.mean", "e.z.mean", "ise", "tau1.max", "tau2.max",
             "tau3.max")
IMPLEMENTATION_STYLE = {"sampled": ("C0", "o"), "sampled-difference": ("C3", "s"), "continuous": ("C2", "^")}


def _ratio_to_paper(frame: pd.DataFrame) -> pd.DataFrame:
    """Rows (run_id, controller, k_xyz, implementation, inertia, metric, ratio = ours / Table 2's value) for
    the Table 2 indexes of KD, KDHD and KHD (τ2 of KDHD and KHD left out: the paper's values contradict its
    percentages)."""
    paper = paper_table2()
    rows = []
    for r in frame[frame["metric"].isin(BAND_ROWS)].to_dict("records"):
        controller, k = r["run_id"].split("__")[0].rsplit("-k", 1)
        if controller not in ("kd", "kdhd", "khd") or (r["metric"] == "tau2.max" and controller != "kd"):
            continue
        printed = paper[r["metric"]][("kd", "kdhd", "khd").index(controller)]
        rows.append({"run_id": r["run_id"], "controller": controller, "k_xyz": float(k), "metric": r["metric"],
                     "implementation": _param(r, "system.control.implementation", "sampled"),
                     "inertia": float(_param(r, "system.inertia_scale", 1)),
                     "ratio": r["value"] * SCALE.get(r["metric"].split(".")[0], 1.0) / printed})
    return pd.DataFrame(rows)


def _param(row: dict, key: str, default):
    """A swept parameter of a metrics row (its column), or the default where it was not swept."""
    value = row.get(key)
    return default if value is None or (isinstance(value, float) and np.isnan(value)) else value


def _table2_bands_figure(frame: pd.DataFrame, figures: Figures) -> None:
    """Each Table 2 index as ours / paper over the sweep: a bar from the least to the largest value, a marker
    per implementation; 1 is the paper's value."""
    ratios = _ratio_to_paper(frame)
    if ratios.empty:
        return
    for k, part in ratios.groupby("k_xyz"):
        fig, axes = plt.subplots(1, 3, figsize=(11, 4), sharey=True)
        for ax, controller in zip(axes, ("kd", "kdhd", "khd"), strict=True):
            ctl = part[part["controller"] == controller]
            for y, metric in enumerate(BAND_ROWS):
                values = ctl[ctl["metric"] == metric]
                if values.empty:
                    continue
                ax.plot([values["ratio"].min(), values["ratio"].max()], [y, y], color="0.6", lw=5, alpha=0.6,
                        solid_capstyle="butt")
                for implementation, (color, marker) in IMPLEMENTATION_STYLE.items():
                    these = values[values["implementation"] == implementation]
                    ax.plot(these["ratio"], [y] * len(these), marker, color=color, ms=4, ls="none",
                            label=implementation if y == 0 else None)
            ax.axvline(1.0, **PAPER_STYLE, label="paper (Table 2)")
            ax.set_xscale("log")
            ax.set_title(controller.upper() + ("" if len(ctl) else " (every run failed: unstable)"))
            ax.set_xlabel("ours / paper")
        axes[0].set_yticks(range(len(BAND_ROWS)), BAND_ROWS)
        axes[0].invert_yaxis()
        axes[-1].legend(fontsize=7, loc="lower right")
        fig.suptitle(f"Table 2 over the sweep (implementation × inertia scale), K = {k:g} N/m: grey = band")
        figures.save(fig, f"table2-bands-{_stiffness_id(k)}")


def _maps_bands_figure(grid: pd.DataFrame, figures: Figures) -> None:
    """Per stiffness: ICE along KD's row (hd = 0) against d for every sweep point, and the equal-ICE line
    through KD of each (eq. 20 for comparison)."""
    if grid.empty:
        return
    for k, part in grid.groupby("k_xyz"):
        fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
        for _, points in part.groupby("group"):
            first = points.iloc[0].to_dict()
            implementation = _param(first, "system.control.implementation", "sampled")
            inertia = f"{float(_param(first, 'system.inertia_scale', 1)):g}"
            color, marker = IMPLEMENTATION_STYLE[implementation]
            style = {"0.5": ":", "1": "-", "3": "--"}.get(inertia, "-.")
            row = points[points["hd_xyz"] == 0].sort_values("d_xyz")
            left.plot(row["d_xyz"], row["ice"] / 1e3, style, marker=marker, color=color, ms=3, lw=1,
                      label=f"{implementation}, inertia ×{inertia}")
            _, locus = equal_ice_locus(points)
            if len(locus) >= 2:
                d, hd = np.array(locus).T
                right.plot(d, hd, style, marker=marker, color=color, ms=3, lw=1)
        d_line = np.linspace(0, 6000, 50)
        right.plot(d_line, 47200 - 9.44 * d_line, **PAPER_STYLE, label="paper, eq. (20)")
        right.set_xlim(0, 6200)
        right.set_ylim(0, 50000)
        right.set_xlabel("d_xyz [Ns/m]")
        right.set_ylabel("hd_xyz [Ns^½/m]")
        right.set_title("equal-ICE line through KD (d = 5000)")
        right.legend(fontsize=7)
        left.set_xlabel("d_xyz [Ns/m]")
        left.set_ylabel("ICE of KD (hd = 0) [10³ N²m²s]")
        left.set_title("ICE along KD's row")
        left.axvline(KD_DAMPING, color="0.5", lw=0.8)
        top = np.nanpercentile(part[part["hd_xyz"] == 0]["ice"], 90) / 1e3
        left.set_ylim(None, top * 1.05)
        left.legend(fontsize=6, ncol=1)
        fig.suptitle(f"Fig. 6 under the omitted parameters, K = {k:g} N/m")
        figures.save(fig, f"maps-bands-{_stiffness_id(k)}")


def _stiffness_figure(frame: pd.DataFrame, figures: Figures) -> None:
    """KD's Table 2 indexes as ours / paper against the stiffness, per implementation: what scales the
    magnitudes."""
    ratios = _ratio_to_paper(frame)
    ratios = ratios[ratios["controller"] == "kd"]
    if ratios.empty:
        return
    implementations = [i for i in IMPLEMENTATION_STYLE if i in set(ratios["implementation"])]
    fig, axes = plt.subplots(1, len(implementations), figsize=(5.2 * len(implementations), 3.8), sharey=True,
                             squeeze=False)
    for ax, implementation in zip(axes[0], implementations, strict=True):
        part = ratios[ratios["implementation"] == implementation]
        for metric, series in part.groupby("metric"):
            series = series.sort_values("k_xyz")
            kind = "-" if metric.startswith("e.") and metric.endswith("max") else (
                "--" if metric.endswith("mean") else ":" if metric.startswith("tau") else "-.")
            ax.plot(series["k_xyz"], series["ratio"], kind, marker="o", ms=3, lw=1, label=metric)
        ax.axhline(1.0, **PAPER_STYLE, label="paper (Table 2, KD)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("k_xyz [N/m]")
        ax.set_title(implementation)
    axes[0][0].set_ylabel("ours / paper (KD)")
    axes[0][-1].legend(fontsize=6, ncol=2)
    fig.suptitle("KD's Table 2 indexes against the stiffness (printed: 8e5 N/m)")
    figures.save(fig, "stiffness")
