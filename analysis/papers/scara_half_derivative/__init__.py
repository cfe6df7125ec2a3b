"""Analysis of `scara-half-derivative`: the set-point (Figs. 4-5), Table 2 and Figs. 8-10, the ICE/ISE maps
and the equal-ICE locus (Fig. 6, eq. 20), the path along eq. (20) (Fig. 7), controller compute time.

Metric definitions (spec §7): e = x_d − x on the fine-step samples; e_max = max |e|, e_mean = mean |e|
(MAE over [0, T_sim]); ISE = ∫ (e_x² + e_y² + e_z²) dt (eq. 19, trapezoid); ICE = Σ_i ∫ τ_i² dt (eq. 18) with τ the
actuator torques (τ_g included) held over each period, so the sum over periods is exact; percentages are
relative to KD (d_xyz = 5000) at the same stiffness.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import yaml
from matplotlib import ticker

from analysis.core.compute_time import compute_time_section, machine_of, timing_metrics
from analysis.core.errors import error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable, metric_value
from pipeline.core.runlog import Run
from pipeline.papers.scara_half_derivative.arm import Arm

AXES = ("x", "y", "z")
JOINT_TORQUES = [f"value.theta{i}" for i in range(1, 5)]
NOISE = 1e-9                 # SI: a reference value this small is round-off (τ4 ≡ 0 in the model)
KD_DAMPING = 5000.0          # N s/m: the reference KD of every comparison (Sec. 5)
LEVEL_TOLERANCE = 1e-9       # relative: grid values this close count as equal
TABLE2 = ["e.x.max", "e.y.max", "e.z.max", "e.x.mean", "e.y.mean", "e.z.mean", "tau1.max", "tau2.max",
          "tau3.max", "tau4.max", "ise"]
CONTROLLER_COLORS = {"kd": "C0", "kdhd": "C3", "khd": "C2"}
FULL_PLOT_STRIDE = 5       # samples drawn in the whole-run panels (the zoom draws every sample)
ZOOM = (0.08, 0.25)        # s before and after the peak in the zoom panels
SWING = 5e-6                 # m: an error reversal this large counts as one swing of an oscillation


def _model(run: Run) -> dict:
    return yaml.safe_load(run.attachments["model.yaml"])


def _tuning(run: Run) -> dict[str, float]:
    g = _model(run)["gains"]
    return {"k_xyz": g["k_xyz"], "d_xyz": g["d_xyz"], "hd_xyz": g["hd_xyz"]}


def _stiffness_id(k: float) -> str:
    return f"k{k:g}"


def tuning_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """Table 2's indexes, ICE and the Exudyn loop gap of one closed-loop run."""
    err = run["/tracking_error"]
    t = err.index.to_numpy()
    values: dict[str, tuple[float, str]] = {}
    ise = 0.0
    for axis in AXES:
        stats = error_stats(t, err[f"error.{axis}"].to_numpy(), f"e.{axis}", "m")
        values |= {k: stats[k] for k in (f"e.{axis}.max", f"e.{axis}.mean")}
        ise += stats[f"e.{axis}.ise"][0]
    values["ise"] = (ise, "m^2*s")   # eq. (19)
    command = run["/command"]
    tau = command[JOINT_TORQUES].to_numpy()
    period = float(np.diff(command.index.to_numpy()).mean())
    values["ice"] = (float((tau ** 2).sum() * period), "N^2*m^2*s")   # eq. (18), torques held over each period
    for i in range(4):
        values[f"tau{i + 1}.max"] = (float(np.abs(tau[:, i]).max()), "Nm")
    if "/loop_closure" in run.topic_names:
        values["loop_gap.max"] = (float(run["/loop_closure"]["value.gap"].abs().max()), "m")
    return values


def _percentages(m: MetricTable, reference: dict, variant: dict, run_id: str, params: dict, names) -> None:
    for name in names:
        base = reference[name][0]
        if abs(base) > NOISE:   # τ4 is zero up to round-off: no percentage of noise
            m.add(run_id, f"pct.{name}", variant[name][0] / base - 1.0, "fraction", params)


# -- Figs. 4-5 -------------------------------------------------------------------------------------------


def analyze_setpoint(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        ref = run["/reference"]
        t = ref.index.to_numpy()
        v = ref[[f"velocity.{a}" for a in AXES]].to_numpy()
        a = ref[[f"acceleration.{a}" for a in AXES]].to_numpy()
        dt = float(t[1] - t[0])
        joints = run["/reference/joints"]
        q = joints[[f"position.theta{i}" for i in range(1, 5)]].to_numpy()
        arm = Arm.from_config(_config_node(run))
        values = {
            "v_max": (float(np.abs(v).max()), "m/s"), "a_max": (float(np.abs(a).max()), "m/s^2"),
            "accel_time": (float(t[np.argmax((t > 0) & (a[:, 0] <= 0))]), "s"),   # the first move is along +x
            "duration": (float(t[np.flatnonzero(np.abs(v).max(axis=1) > 0)[-1]] + dt
                               + run.config["system"]["motion"]["t_stop"]), "s"),
            "theta3p": (arm.theta3p, "rad"), "theta2.min": (float(q[:, 1].min()), "rad"),
            "theta3.max": (float(np.abs(q[:, 2]).max()), "rad"),
            "fk_ik_error.max": (float(run["/setpoint/check"]["value.fk_ik_error"].max()), "m"),
        }
        values |= {f"home.{c}": (float(ref[f"position.{c}"].iloc[0]), "m" if c != "theta" else "rad")
                   for c in (*AXES, "theta")}
        m.add_run(run, values)
        _setpoint_figures(ref, joints, figures)
    return m.frame()


def _config_node(run: Run):
    from omegaconf import OmegaConf

    return OmegaConf.create(run.config["system"])


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


# -- Table 2, Figs. 8-10 ---------------------------------------------------------------------------------


def _reversals(e: np.ndarray, amplitude: float) -> int:
    """How often the signal turns back by at least `amplitude` (a swing counter with hysteresis, blind to
    numerical ripple)."""
    count, extreme, direction = 0, e[0], 0
    for value in e.tolist():
        if direction >= 0 and value < extreme - amplitude:
            count += direction == 1
            direction, extreme = -1, value
        elif direction <= 0 and value > extreme + amplitude:
            count += direction == -1
            direction, extreme = 1, value
        elif (direction == 1 and value > extreme) or (direction == -1 and value < extreme):
            extreme = value
    return count


def _ringing(run: Run) -> int:
    """Swings of e_x, e_y, e_z larger than SWING over the run: the oscillation that Figs. 8-10 show."""
    err = run["/tracking_error"]
    return sum(_reversals(err[f"error.{axis}"].to_numpy(), SWING) for axis in AXES)


def analyze_table2(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_stiffness: dict[float, dict[str, tuple[Run, dict]]] = {}
    timings: dict[str, list[np.ndarray]] = {}
    for run in runs:
        name = run.metadata["case"].rsplit("-k", 1)[0]
        values = tuning_metrics(run) | {"ringing": (_ringing(run), "count")}
        m.add_run(run, values)
        by_stiffness.setdefault(_tuning(run)["k_xyz"], {})[name] = (run, values)
        law = _model(run)["law"]
        timings.setdefault(law, []).append(run["/compute_time"][f"seconds.{law}"].dropna().to_numpy())
    for law, samples in timings.items():   # every control step of every run of the law
        for metric, (value, unit) in timing_metrics(f"controller.{law}", np.concatenate(samples)).items():
            m.add("all", metric, value, unit)
    for k, controllers in by_stiffness.items():
        if "kd" in controllers:
            reference = controllers["kd"][1]
            for name, (run, values) in controllers.items():
                if name != "kd":
                    _percentages(m, reference, values, run.run_id, run.params, [*TABLE2, "ice"])
        ringing = {name: v["ringing"][0] for name, (_, v) in controllers.items()}
        if {"kd", "kdhd", "khd"} <= set(ringing):
            more = ringing["khd"] > max(ringing["kd"], ringing["kdhd"])
            m.add(_stiffness_id(k), "claim.khd_more_oscillatory", float(more), "bool")
        _error_figures(k, controllers, figures)
    return m.frame()


def _error_figures(k: float, controllers: dict[str, tuple[Run, dict]], figures: Figures) -> None:
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
        full.set_xlabel("time [s]")
        zoom.set_xlabel("time [s] (peak zone)")
        full.set_ylabel(f"e_{axis} [mm]")
        full.legend(ncol=3)
        fig.suptitle(f"Fig. {fig_number}: error e_{axis}, K = {k:g} N/m")
        figures.save(fig, f"fig{fig_number}-e{axis}-{_stiffness_id(k)}")


# -- Fig. 6: maps and the equal-ICE locus -----------------------------------------------------------------


def grid_frame(runs: list[Run]) -> pd.DataFrame:
    """One row per grid point on disk (k_xyz, d_xyz, hd_xyz, run_id, ISE, ICE, peak torques); a point run
    twice (the sweep and the default run) is kept once."""
    rows = [{**_tuning(run), "run_id": run.run_id, **{k: v for k, (v, _) in tuning_metrics(run).items()}}
            for run in runs]
    if not rows:
        return pd.DataFrame(columns=["k_xyz", "d_xyz", "hd_xyz", "run_id", "ise", "ice"])
    frame = pd.DataFrame(rows).sort_values(["k_xyz", "d_xyz", "hd_xyz", "run_id"])
    return frame.drop_duplicates(["k_xyz", "d_xyz", "hd_xyz"]).reset_index(drop=True)


def equal_ice_locus(grid: pd.DataFrame) -> tuple[float, list[tuple[float, float]]]:
    """(ICE of KD at d = 5000, points (d, hd) where ICE equals it): for each hd of the grid, the d at which
    ICE crosses the level, by linear interpolation along d (the KD point itself included)."""
    kd = grid[(grid["hd_xyz"] == 0) & np.isclose(grid["d_xyz"], KD_DAMPING, rtol=LEVEL_TOLERANCE)]
    if kd.empty:
        return float("nan"), []
    level = float(kd["ice"].iloc[0])
    points = []
    for hd, column in grid.groupby("hd_xyz"):
        column = column.sort_values("d_xyz")
        d, ice = column["d_xyz"].to_numpy(), column["ice"].to_numpy() - level
        for i in range(len(d) - 1):
            if ice[i] == 0:
                points.append((float(d[i]), float(hd)))
            elif ice[i] * ice[i + 1] < 0:
                points.append((float(d[i] - ice[i] * (d[i + 1] - d[i]) / (ice[i + 1] - ice[i])), float(hd)))
        if len(d) and ice[-1] == 0:
            points.append((float(d[-1]), float(hd)))
    return level, sorted(set(points))


def _monotonic(grid: pd.DataFrame, metric: str, sign: int) -> bool:
    """`metric` changes with the sign `sign` along every grid line of d and of hd."""
    table = grid.pivot(index="d_xyz", columns="hd_xyz", values=metric)
    steps = [np.diff(table.to_numpy(), axis=0), np.diff(table.to_numpy(), axis=1)]
    finite = [s[np.isfinite(s)] for s in steps]
    return bool(all((sign * s > 0).all() for s in finite) and any(s.size for s in finite))


def analyze_maps(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    grid = grid_frame(runs)
    for row in grid.to_dict("records"):
        params = {key: row[key] for key in ("k_xyz", "d_xyz", "hd_xyz")}
        m.add(row["run_id"], "ise", row["ise"], "m^2*s", params)
        m.add(row["run_id"], "ice", row["ice"], "N^2*m^2*s", params)
    for k, part in grid.groupby("k_xyz"):
        sid = _stiffness_id(k)
        level, points = equal_ice_locus(part)
        m.add(sid, "ice.kd", level, "N^2*m^2*s", {"k_xyz": k})
        m.add(sid, "locus.points", len(points), "count", {"k_xyz": k})
        if len(points) >= 2:
            d, hd = np.array(points).T
            slope, intercept = np.polyfit(d, hd, 1)
            m.add(sid, "locus.slope", slope, "s^-0.5", {"k_xyz": k})
            m.add(sid, "locus.intercept", intercept, "Ns^0.5/m", {"k_xyz": k})
        m.add(sid, "claim.ice_increases", float(_monotonic(part, "ice", +1)), "bool", {"k_xyz": k})
        m.add(sid, "claim.ise_decreases", float(_monotonic(part, "ise", -1)), "bool", {"k_xyz": k})
        _map_figure(k, part, level, points, figures)
    return m.frame()


def _map_figure(k: float, grid: pd.DataFrame, level: float, points: list, figures: Figures) -> None:
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
        figures.save(fig, f"fig6-maps-{_stiffness_id(k)}")
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
    figures.save(fig, f"fig6-maps-{_stiffness_id(k)}")


# -- Fig. 7: along eq. (20) -------------------------------------------------------------------------------


def analyze_locus(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    grid = grid_frame(runs)
    for row in grid.to_dict("records"):
        params = {key: row[key] for key in ("k_xyz", "d_xyz", "hd_xyz")}
        for name, unit in (("ise", "m^2*s"), ("ice", "N^2*m^2*s"), *((f"tau{i}.max", "Nm") for i in range(1, 5))):
            m.add(row["run_id"], name, row[name], unit, params)
    for k, path in grid.groupby("k_xyz"):
        sid = _stiffness_id(k)
        path = path.sort_values("d_xyz", ascending=False)
        kd = path[np.isclose(path["d_xyz"], KD_DAMPING)]
        if kd.empty:
            continue
        ref = kd.iloc[0]
        torques = [f"tau{i}.max" for i in range(1, 4)]
        ratio = path[["ise", "ice", *torques]] / ref[["ise", "ice", *torques]].astype(float)
        m.add(sid, "claim.ise_decreases_along_path", float((np.diff(path["ise"].to_numpy()) < 0).all()), "bool")
        m.add(sid, "ice.max_deviation", float((ratio["ice"] - 1).abs().max()), "fraction")
        middle = path[np.isclose(path["d_xyz"], KD_DAMPING / 2)]
        if not middle.empty:
            change = (ratio.loc[middle.index[0], torques] - 1).abs().max()
            m.add(sid, "middle.max_torque_change", float(change), "fraction")
        _path_figure(k, path, ratio, figures)
    return m.frame()


def _path_figure(k: float, path: pd.DataFrame, ratio: pd.DataFrame, figures: Figures) -> None:
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
    figures.save(fig, f"fig7-path-{_stiffness_id(k)}")


ANALYSES = {"setpoint": analyze_setpoint, "table2": analyze_table2, "maps": analyze_maps, "locus": analyze_locus}


# -- extra report tables ----------------------------------------------------------------------------------

PAPER_TABLE2 = {  # Table 2 as printed: KD, KDHD, KHD (mm, Nm, m²s)
    "e.x.max": (4.979, 4.970, 4.882), "e.y.max": (3.833, 3.817, 3.739), "e.z.max": (2.676, 2.652, 2.642),
    "e.x.mean": (0.359, 0.338, 0.320), "e.y.mean": (0.352, 0.334, 0.318), "e.z.mean": (0.187, 0.176, 0.167),
    "tau1.max": (172.8, 171.6, 191.6), "tau2.max": (90.2, 94.2, 157.2), "tau3.max": (157.2, 164.1, 167.9),
    "tau4.max": (1.67, 1.57, 1.67), "ise": (2.41e-5, 2.20e-5, 2.02e-5),
}
SCALE = {"e": 1e3}   # m -> mm for the error rows



def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = []
    table2 = metrics.get("table2")
    if table2 is not None and not table2.empty:
        for k in sorted({rid.rsplit("-k", 1)[1] for rid in table2["run_id"] if "-k" in rid}, key=float):
            rows = []
            for metric, paper in PAPER_TABLE2.items():
                scale = SCALE.get(metric.split(".")[0], 1.0)
                row = {"index": metric}
                for name, printed in zip(("kd", "kdhd", "khd"), paper, strict=True):
                    value = metric_value(table2, f"{name}-k{k}", metric) * scale
                    pct = metric_value(table2, f"{name}-k{k}", f"pct.{metric}")
                    row[f"{name.upper()}"] = f"{value:.4g}" + (f" ({100 * pct:+.1f}%)" if np.isfinite(pct) else "")
                    row[f"paper {name.upper()}"] = printed
                rows.append(row)
            sections.append(f"## Table 2 as reproduced, K = {float(k):g} N/m (Exudyn closed chain)\n\nErrors in mm, "
                            "torques in Nm, ISE in m²s; percentages vs KD. A KHD column of NaN means the run "
                            "failed (unstable, see Runs).\n\n" + pd.DataFrame(rows).to_markdown(index=False))
        sections.append(compute_time_section(
            "Compute time per control step (not reported by the paper)", table2, "all",
            [("KD, eq. (11)", "controller.kd", "not reported"),
             ("KDHD/KHD, eq. (17)", "controller.kdhd", "not reported")],
            machine_of(runs, "table2"),
            note="One call = FK, Jacobian and the control law (plus the 11-tap half-derivative filter for KDHD) in "
                 "Python/NumPy, timed inside the closed loop over every step of every table2 run."))
    maps = metrics.get("maps")
    if maps is not None and not maps.empty:
        rows = []
        for sid in sorted({r for r in maps["run_id"] if r.startswith("k") and "-" not in r}):
            rows.append({"stiffness": sid, "ICE of KD [N²m²s]": metric_value(maps, sid, "ice.kd"),
                         "points": metric_value(maps, sid, "locus.points"),
                         "slope [s^-½]": metric_value(maps, sid, "locus.slope"),
                         "intercept [Ns^½/m]": metric_value(maps, sid, "locus.intercept"),
                         "paper (eq. 20)": "−9.44, 47,200"})
        lonely = [r["stiffness"] for r in rows if r["points"] < 2]
        sections.append("## Equal-ICE locus fitted from the maps (Fig. 6, eq. 20)\n\nFor each hd_xyz of the grid, "
                        "the d_xyz at which ICE equals KD's (linear interpolation along d), then a least-squares "
                        "line through these points.\n\n" + pd.DataFrame(rows).to_markdown(index=False, floatfmt=".5g")
                        + ("\n\nWith a single point (" + ", ".join(lonely) + ") the only grid point at KD's ICE is KD "
                           "itself: ICE grows in every direction around it on the grid, so this model has no "
                           "equal-ICE line through KD to fit." if lonely else ""))
    locus = metrics.get("locus")
    if locus is not None and not locus.empty:
        points = locus[locus["metric"].isin(["ise", "ice", "tau1.max", "tau2.max", "tau3.max"])]
        table = points.pivot_table(index=["k_xyz", "d_xyz", "hd_xyz"], columns="metric", values="value")
        sections.append("## Along eq. (20) (Fig. 7)\n\n" + table.reset_index().sort_values(
            ["k_xyz", "d_xyz"], ascending=[True, False]).to_markdown(index=False, floatfmt=".5g"))
    return sections
