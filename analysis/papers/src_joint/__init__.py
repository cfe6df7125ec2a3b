"""Analysis of `src-joint`: the joint model against MuJoCo and the exact rolling plant (Figs. 8-10), poses A,
B and reachable FK targets with the hardware stand-in (Figs. 13-14), target C between two bars (Figs. 16-17),
and the per-step compute times of the IK and the QP."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from analysis.core.compute_time import compute_time_section, machine_of, timing_metrics
from analysis.core.errors import error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable, metric_value
from pipeline.core.runlog import Run

# "converges to zero" / "reached accurately" (Figs. 13a, 14a, 16), made a rule: final position error below
# 0.1 mm and final orientation error below 0.05°
REACHED_POSITION = 1e-4
REACHED_ANGLE = np.radians(0.05)
# "value consistency" (Fig. 8) and "coincidence" (Fig. 10), made a rule: the largest model-minus-measured
# difference below 1 % of the largest measured value
CONSISTENT = 0.01
EULER = ["X", "Y", "Z"]
SIX = ["wx", "wy", "wz", "vx", "vy", "vz"]
# eqs. (66), (67): the paper's IK solutions q^r_i, scalar first
PRINTED_IK = {"A": [[0.7992, 0.1912, -0.5698, 0.0016], [-0.5579, -0.1939, -0.7714, -0.2366],
                    [0.1270, -0.4998, -0.3887, 0.7636]],
              "B": [[-0.4558, 0.5135, -0.7261, -0.0367], [-0.0130, -0.6933, 0.0267, -0.7200],
                    [0.0880, 0.2577, 0.8231, -0.4983]]}


def _columns(frame: pd.DataFrame, prefix: str, names) -> np.ndarray:
    return frame[[f"{prefix}.{k}" for k in names]].to_numpy()



# -- E1: joint-model ----------------------------------------------------------------------------------------


def _joint_metrics(run: Run) -> dict[str, tuple[float, str]]:
    err = run["/tracking_error"]
    t = err.index.to_numpy()
    euler = _columns(err, "error", EULER)
    values: dict[str, tuple[float, str]] = {}
    for k, axis in enumerate(EULER):
        values |= error_stats(t, euler[:, k], f"rotation_error.{axis}", "rad")
    values["rotation_error.peak"] = (np.abs(euler).max(), "rad")
    values["rotation_error.angle_max"] = (err["norm"].max(), "rad")

    w_meas = _columns(run["/joint_state"], "velocity", "xyz")
    dw = _columns(run["/tracking_error/joint_velocity"], "error", "xyz")
    for k, axis in enumerate("xyz"):
        values |= error_stats(t, dw[:, k], f"joint_velocity_error.{axis}", "rad/s")
    values["joint_velocity_error.relative"] = (np.abs(dw).max() / np.abs(w_meas).max(), "ratio")

    nu = _columns(run["/spatial_velocity"], "value", SIX)
    dnu = _columns(run["/tracking_error/spatial_velocity"], "error", SIX)
    for k, axis in enumerate(SIX):
        unit = "rad/s" if axis[0] == "w" else "m/s"
        values[f"spatial_velocity_error.{axis}.max"] = (np.abs(dnu[:, k]).max(), unit)
        values[f"spatial_velocity_error.{axis}.mean"] = (np.abs(dnu[:, k]).mean(), unit)
    relative = max(np.abs(dnu[:, :3]).max() / np.abs(nu[:, :3]).max(),       # angular
                   np.abs(dnu[:, 3:]).max() / np.abs(nu[:, 3:]).max())       # linear
    values["spatial_velocity_error.relative"] = (relative, "ratio")
    values["claim.joint_velocity_consistent"] = (float(values["joint_velocity_error.relative"][0] < CONSISTENT), "bool")
    values["claim.spatial_velocity_coincide"] = (float(relative < CONSISTENT), "bool")

    # what the plant did: total relative rotation and the contact point's travel on B_{i-1}
    dt = np.diff(t)
    speed = np.linalg.norm(w_meas, axis=1)
    values["plant.rotation_travelled"] = (float(np.sum(0.5 * (speed[1:] + speed[:-1]) * dt)), "rad")
    rate = _columns(run["/tangent_rate"], "value", "xyz")
    command = _columns(run["/reference"], "velocity", "xy")
    settled = t >= 1.0
    values["plant.tangent_rate_error_mean"] = (np.linalg.norm(rate[settled, :2] - command[settled], axis=1).mean(),
                                               "rad/s")
    values["plant.spin_rate_max"] = (np.abs(rate[:, 2]).max(), "rad/s")
    # slip: the contact point's paths on the two spheres differ
    paths = run["/contact_path"]
    on_lower, on_upper = paths["value.lower"].iloc[-1], paths["value.upper"].iloc[-1]
    values["contact.path_lower"] = (on_lower, "m")
    values["contact.path_mismatch"] = (abs(on_lower - on_upper) / on_lower, "ratio")
    if "/contact" in run.topic_names:
        values["contact.penetration_max"] = (-run["/contact"]["value.penetration"].min(), "m")
    return values


def analyze_joint_model(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_id = {}
    for run in runs:
        m.add_run(run, _joint_metrics(run))
        by_id[run.run_id] = run
    for plant in ("mujoco", "exact"):
        if f"{plant}-corrected" in by_id:
            _joint_figures(plant, {k.removeprefix(f"{plant}-"): r for k, r in by_id.items() if k.startswith(plant)},
                           figures, velocities=plant == "mujoco")
    return m.frame()


def _joint_figures(plant: str, runs: dict[str, Run], figures: Figures, velocities: bool) -> None:
    """Fig. 9 (rotation error), and with `velocities` Figs. 8 and 10."""
    label = {"mujoco": "MuJoCo", "exact": "exact rolling"}[plant]
    base = runs["corrected"]
    fig, ax = plt.subplots(figsize=(6, 3.2))
    err = base["/tracking_error"]
    for axis in EULER:
        ax.plot(err.index, np.degrees(err[f"error.{axis}"]), label=axis)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("rotation error [deg]")
    ax.set_title(f"R(q_i) (corrected model) vs {label}: XYZ Euler angles of R_modelᵀ R", fontsize=8)
    ax.legend(fontsize=7)
    figures.save(fig, f"fig9-rotation-error-{plant}")
    if not velocities:
        return
    # Fig. 8: joint velocity, model (1) vs measured
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2), sharex=True)
    measured = base["/joint_state"]
    for ax, axis in zip(axes, "xy", strict=True):
        ax.plot(measured.index, measured[f"velocity.{axis}"], "k", lw=2.5, alpha=0.4, label=f"measured ({label})")
        for variant, run in runs.items():
            if variant != "printed-sign":
                model = run["/joint_state/model"]
                ax.plot(model.index, model[f"velocity.{axis}"], "--", lw=1.2, label=f"eq. (1), {variant}")
        ax.set_title(f"joint velocity ω_{axis} in P_i")
        ax.set_xlabel("t [s]")
    axes[0].set_ylabel("[rad/s]")
    axes[0].legend(fontsize=7)
    figures.save(fig, f"fig8-joint-velocity-{plant}")
    # Fig. 10: spatial velocity, Φ_i w vs measured
    fig, axes = plt.subplots(2, 3, figsize=(10, 5), sharex=True)
    nu = base["/spatial_velocity"]
    for ax, axis in zip(axes.ravel(), SIX, strict=True):
        ax.plot(nu.index, nu[f"value.{axis}"], "k", lw=2.5, alpha=0.4, label=f"measured ({label})")
        for variant in ("corrected", "printed-sign"):
            if variant in runs:
                model = runs[variant]["/spatial_velocity/model"]
                ax.plot(model.index, model[f"value.{axis}"], "--", lw=1.2, label=f"Φ_i w, {variant}")
        ax.set_title(f"{axis} [{'rad/s' if axis[0] == 'w' else 'm/s'}]")
    axes[0, 0].legend(fontsize=7)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    figures.save(fig, f"fig10-spatial-velocity-{plant}")


# -- E2: reach-poses ----------------------------------------------------------------------------------------


def _final_errors(run: Run) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(e_p (3,) m, e_o XYZ (3,) rad, |e_p|, rotation angle) at the end of a run."""
    p, o = run["/tracking_error"], run["/tracking_error/orientation"]
    return (_columns(p, "error", "xyz")[-1], _columns(o, "error", EULER)[-1], float(p["norm"].iloc[-1]),
            float(o["norm"].iloc[-1]))


def _time_below(run: Run, threshold: float) -> float:
    """First time after which the position error stays below `threshold` (NaN if it never does)."""
    norm = run["/tracking_error"]["norm"]
    above = np.flatnonzero(norm.to_numpy() >= threshold)
    if not len(above):
        return float(norm.index[0])
    return float(norm.index[above[-1] + 1]) if above[-1] + 1 < len(norm) else float("nan")


def _reach_metrics(run: Run) -> dict[str, tuple[float, str]]:
    e_p, e_o, p_norm, angle = _final_errors(run)
    ik = run["/ik"]
    values = {f"final.position_error.{a}": (e_p[k], "m") for k, a in enumerate("xyz")}
    values |= {f"final.orientation_error.{a}": (e_o[k], "rad") for k, a in enumerate(EULER)}
    values |= {"final.position_error": (p_norm, "m"), "final.orientation_error": (angle, "rad"),
               "time_to_1mm": (_time_below(run, 1e-3), "s"),
               "claim.reached": (float(p_norm < REACHED_POSITION and angle < REACHED_ANGLE), "bool"),
               "ik.position_error": (ik["value.position_error"].iloc[-1], "m"),
               # |δ| of eq. (47) is sin(θ/2) of the remaining rotation θ
               "ik.orientation_error": (2 * np.arcsin(min(1.0, ik["value.orientation_error"].iloc[-1])), "rad"),
               "ik.iterations": (len(ik), "count"), "ik.time": (ik.index[-1], "s")}
    solution = run["/ik/solution"]
    values["ik.converged"] = (solution["value.converged"].iloc[0], "bool")
    target = run.metadata["case"].split("-")[0]
    if target in PRINTED_IK:  # our q^r_i beside eqs. (66)/(67), as the representative (±q) nearer the printed one
        for i, printed in enumerate(PRINTED_IK[target], start=1):
            q = _columns(solution, f"value.j{i}", ["qw", "qx", "qy", "qz"])[0]
            q = q if q @ printed >= 0 else -q
            values |= {f"ik.q{i}.{c}": (q[k], "") for k, c in enumerate("wxyz")}
    values |= timing_metrics("ik_iteration", run["/compute_time"]["seconds.ik_iteration"].to_numpy())
    wheels = run["/command"].drop(columns="kind").to_numpy()
    values["wheel_speed_max"] = (np.abs(wheels).max(), "rad/s")
    return values


def analyze_reach_poses(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_case = {r.metadata["case"]: r for r in runs}
    for run in runs:
        values = _reach_metrics(run)
        target, _, plant = run.metadata["case"].partition("-")
        nominal = by_case.get(f"{target}-nominal")
        if plant != "nominal" and nominal is not None:
            # what the plant's defects alone did: the final pose against FreeBOT-SIM's final pose
            e_p, e_o = _final_errors(run)[:2]
            e_p_nominal, e_o_nominal = _final_errors(nominal)[:2]
            dp = e_p_nominal - e_p                                   # r − r_nominal, as both aim at r^d
            values |= {f"deviation.position.{a}": (dp[k], "m") for k, a in enumerate("xyz")}
            values["deviation.position"] = (float(np.linalg.norm(dp)), "m")
            turn = Rotation.from_euler("XYZ", e_o).inv() * Rotation.from_euler("XYZ", e_o_nominal)  # R Rᵀ_nominal
            values["deviation.orientation"] = (float(turn.magnitude()), "rad")
        m.add_run(run, values)
    reachable = [r for case, r in by_case.items() if case.startswith("random") and case.endswith("-nominal")]
    if reachable:
        finals = np.array([_final_errors(r)[2:] for r in reachable])
        m.add("random", "final.position_error_max", finals[:, 0].max(), "m")
        m.add("random", "final.orientation_error_max", finals[:, 1].max(), "rad")
        reached = (finals[:, 0] < REACHED_POSITION) & (finals[:, 1] < REACHED_ANGLE)
        m.add("random", "claim.reached", float(reached.all()), "bool")
    for target in ("A", "B"):
        if f"{target}-nominal" in by_case:
            _pose_figure(target, {c.partition("-")[2]: r for c, r in by_case.items() if c.startswith(f"{target}-")},
                         figures)
    if reachable:
        _random_figure(reachable, figures)
    return m.frame()


def _pose_figure(target: str, runs: dict[str, Run], figures: Figures) -> None:
    """Figs. 13/14: end-effector position and orientation errors vs time."""
    fig, axes = plt.subplots(2, 2, figsize=(10, 5.5), sharex=True)
    for col, plant in enumerate(("nominal", "eva-1mm-slip-2pct")):
        if plant not in runs:
            continue
        p, o = runs[plant]["/tracking_error"], runs[plant]["/tracking_error/orientation"]
        for axis in "xyz":
            axes[0, col].plot(p.index, p[f"error.{axis}"] * 1e3, label=axis)
        for axis in EULER:
            axes[1, col].plot(o.index, np.degrees(o[f"error.{axis}"]), label=axis)
        axes[0, col].set_title(f"target {target}, plant {plant}" + (" (FreeBOT-SIM)" if plant == "nominal"
                                                                    else " (hardware stand-in)"))
        axes[1, col].set_xlabel("t [s]")
    axes[0, 0].set_ylabel("position error r^d − r [mm]")
    axes[1, 0].set_ylabel("orientation error, XYZ of R_d Rᵀ [deg]")
    axes[0, 0].legend(fontsize=7)
    axes[1, 0].legend(fontsize=7)
    figures.save(fig, f"fig{13 if target == 'A' else 14}-target-{target}")


def _random_figure(runs: list[Run], figures: Figures) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.2), sharex=True)
    for run in runs:
        label = run.metadata["case"].removesuffix("-nominal")
        p, o = run["/tracking_error"], run["/tracking_error/orientation"]
        axes[0].semilogy(p.index, np.maximum(p["norm"] * 1e3, 1e-6), label=label)
        axes[1].semilogy(o.index, np.maximum(np.degrees(o["norm"]), 1e-6), label=label)
    axes[0].set_ylabel("|r^d − r| [mm]")
    axes[1].set_ylabel("orientation error [deg]")
    for ax in axes:
        ax.set_xlabel("t [s]")
    axes[0].legend(fontsize=7)
    fig.suptitle("targets made by FK of random configurations: convergence of the whole loop (IK, planning, trolleys)")
    figures.save(fig, "reachable-targets")


# -- E3: avoid-obstacles ------------------------------------------------------------------------------------


def _bars(frame: pd.DataFrame) -> list[str]:
    return sorted({c.rsplit(".", 1)[1] for c in frame.columns})


def analyze_avoid_obstacles(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        clearance, check = run["/clearance"], run["/clearance/mujoco"]
        _, _, p_norm, angle = _final_errors(run)
        values = {"final.position_error": (p_norm, "m"), "final.orientation_error": (angle, "rad"),
                  "time_to_1mm": (_time_below(run, 1e-3), "s"),
                  "claim.reached": (float(p_norm < REACHED_POSITION and angle < REACHED_ANGLE), "bool"),
                  "clearance.min": (clearance.to_numpy().min(), "m"),
                  "clearance.mujoco_min": (check.to_numpy().min(), "m"),
                  "clearance.mujoco_difference_max": (np.abs(clearance.to_numpy() - check.to_numpy()).max(), "m"),
                  "qp.slack_max": (run["/qp"]["value.slack"].max(), "m/s")}
        for bar in _bars(clearance):
            values[f"clearance.{bar}.min"] = (clearance.filter(like=bar).to_numpy().min(), "m")
        ct = run["/compute_time"]
        for name in ("qp", "model"):
            values |= timing_metrics(name, ct[f"seconds.{name}"].to_numpy())
        values["wheel_speed_max"] = (np.abs(run["/command"].drop(columns="kind").to_numpy()).max(), "rad/s")
        m.add_run(run, values)
    by_id = {r.run_id: r for r in runs}
    if "avoid" in by_id:
        _obstacle_figures(by_id, figures)
    return m.frame()


def _obstacle_figures(runs: dict[str, Run], figures: Figures) -> None:
    run = runs["avoid"]
    # Fig. 16: pose errors
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.2), sharex=True)
    p, o = run["/tracking_error"], run["/tracking_error/orientation"]
    for axis in "xyz":
        axes[0].plot(p.index, p[f"error.{axis}"] * 1e3, label=axis)
    for axis in EULER:
        axes[1].plot(o.index, np.degrees(o[f"error.{axis}"]), label=axis)
    axes[0].set_ylabel("position error [mm]")
    axes[1].set_ylabel("orientation error, XYZ [deg]")
    for ax in axes:
        ax.set_xlabel("t [s]")
        ax.legend(fontsize=7)
    fig.suptitle("target C with velocity-damper avoidance")
    figures.save(fig, "fig16-target-C-errors")
    # Fig. 17: closest distance to each bar
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for case, style in (("avoid", "-"), ("unconstrained", ":")):
        if case not in runs:
            continue
        clearance, check = runs[case]["/clearance"], runs[case]["/clearance/mujoco"]
        for k, bar in enumerate(_bars(clearance)):
            ax.plot(clearance.index, clearance.filter(like=bar).min(axis=1) * 1e3, style, color=f"C{k}",
                    label=f"{bar}, {case}")
            if case == "avoid":
                every = check.iloc[::50]
                ax.plot(every.index, every.filter(like=bar).min(axis=1) * 1e3, "o", ms=3, mfc="none", color=f"C{k}",
                        label=f"{bar}, MuJoCo mj_geomDistance")
    ax.axhline(10.0, color="r", ls="--", lw=1, label="safety distance 0.01 m")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("closest distance [mm]")
    ax.legend(fontsize=7, ncol=2)
    figures.save(fig, "fig17-clearance")


ANALYSES = {"joint-model": analyze_joint_model, "reach-poses": analyze_reach_poses,
            "avoid-obstacles": analyze_avoid_obstacles}


# -- extra report tables ----------------------------------------------------------------------------------------


def _joint_section(frame: pd.DataFrame) -> str:
    rows = []
    for run_id in sorted(set(frame["run_id"])):
        rows.append({"plant-model": run_id,
                     "peak rot. err [deg]": np.degrees(metric_value(frame, run_id, "rotation_error.peak")),
                     **{f"mean |{a}| [deg]": np.degrees(metric_value(frame, run_id, f"rotation_error.{a}.mean"))
                        for a in EULER},
                     "joint vel. err (rel.)": metric_value(frame, run_id, "joint_velocity_error.relative"),
                     "spatial vel. err (rel.)": metric_value(frame, run_id, "spatial_velocity_error.relative"),
                     "rotation travelled [deg]": np.degrees(metric_value(frame, run_id, "plant.rotation_travelled"))})
    contact = ("mujoco-corrected", ["contact.penetration_max", "contact.path_lower", "contact.path_mismatch",
                                    "plant.tangent_rate_error_mean", "plant.spin_rate_max"])
    details = ", ".join(f"{k} = {metric_value(frame, contact[0], k):.3g}" for k in contact[1])
    return ("## Joint model against the plants (Figs. 8-10)\n\nThe paper's model is fed the Ω^B each plant "
            "realised; 'printed-radius' runs eqs. (1), (5), (13)-(16) as printed, 'printed-sign' Table I's sign of "
            "Φ_v. "
            "Mean |error| per XYZ Euler angle over 0-30 s (paper: [4.92, 0.01, 9.83]·10⁻⁴, unit not stated).\n\n"
            + pd.DataFrame(rows).to_markdown(index=False, floatfmt=".3g")
            + f"\n\nMuJoCo contact (SI): {details}. What remains of the model–physics difference comes from the soft "
            "contact (penetration): it falls with the square of the contact time constant `physics.solref[0]` "
            "(tests/test_src_joint_control.py), which MuJoCo bounds below by 2 `physics.dt`.")


def _reach_section(frame: pd.DataFrame) -> str:
    rows = []
    for run_id in sorted(set(frame["run_id"]) - {"random"}):
        rows.append({"run": run_id, "IK converged": bool(metric_value(frame, run_id, "ik.converged")),
                     "IK |e_p| [mm]": metric_value(frame, run_id, "ik.position_error") * 1e3,
                     "IK e_o [deg]": np.degrees(metric_value(frame, run_id, "ik.orientation_error")),
                     **{f"final e_{a} [mm]": metric_value(frame, run_id, f"final.position_error.{a}") * 1e3
                        for a in "xyz"},
                     **{f"final {a} [deg]": np.degrees(metric_value(frame, run_id, f"final.orientation_error.{a}"))
                        for a in EULER},
                     "|Δp vs nominal| [mm]": metric_value(frame, run_id, "deviation.position") * 1e3,
                     "Δθ vs nominal [deg]": np.degrees(metric_value(frame, run_id, "deviation.orientation"))})
    return ("## Reaching poses (Figs. 13-14) and the hardware stand-in\n\nIK from the Table II start, then the "
            "trolleys. Plants: `nominal` steers by the measured contact point ((53)-(55) online, FreeBOT-SIM); the "
            "others by wheel encoders only, with the EVA foam compressed by 1 mm and/or 2 % of the forward travel "
            "lost — the labelled stand-in for the paper's hardware errors (A: [4.17, −0.21, −4.19] mm, "
            "[1.07, −0.8, 1.45]°; B: [−3.51, 3.9, 1.47] mm, [0.13, 1.86, 0.52]°). 'Δ vs nominal' compares the "
            "final pose with FreeBOT-SIM's (the defects' own effect). A and B are not reachable with exact rolling "
            "kinematics: the IK stops at the residual shown.\n\n"
            + pd.DataFrame(rows).to_markdown(index=False, floatfmt=".3g"))


def _obstacle_section(frame: pd.DataFrame) -> str:
    rows = [{"case": run_id,
             **{f"min clearance {bar} [mm]": metric_value(frame, run_id, f"clearance.{bar}.min") * 1e3
                for bar in ("bar1", "bar2")},
             "MuJoCo min [mm]": metric_value(frame, run_id, "clearance.mujoco_min") * 1e3,
             "|analytic − MuJoCo| [m]": metric_value(frame, run_id, "clearance.mujoco_difference_max"),
             "final |e_p| [mm]": metric_value(frame, run_id, "final.position_error") * 1e3,
             "final e_o [deg]": np.degrees(metric_value(frame, run_id, "final.orientation_error")),
             "t(|e_p| < 1 mm) [s]": metric_value(frame, run_id, "time_to_1mm"),
             "max level-1 slack": metric_value(frame, run_id, "qp.slack_max")}
            for run_id in sorted(set(frame["run_id"]))]
    return ("## Target C between the bars (Figs. 16-17)\n\nBars parallel to x through the Table II points, radius "
            "5 mm (assumed); dampers act below 40 mm with gain 0.5 s⁻¹ and keep 10 mm (the paper's safety distance). "
            "`unconstrained` is the same loop without the dampers.\n\n"
            + pd.DataFrame(rows).to_markdown(index=False, floatfmt=".4g"))


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = []
    if metrics.get("joint-model") is not None and not metrics["joint-model"].empty:
        sections.append(_joint_section(metrics["joint-model"]))
    if metrics.get("reach-poses") is not None and not metrics["reach-poses"].empty:
        sections.append(_reach_section(metrics["reach-poses"]))
    obstacles = metrics.get("avoid-obstacles")
    if obstacles is not None and not obstacles.empty:
        sections.append(_obstacle_section(obstacles))
        rows = [("QP of the velocity dampers (qpOASES, per tick)", "qp", "not reported"),
                ("FK + Jacobians of every link (per tick)", "model", "not reported")]
        sections.append(compute_time_section("Compute time, avoid-obstacles", obstacles, "avoid", rows,
                                             machine_of(runs, "avoid-obstacles"),
                                             note="Python + NumPy + CasADi; the paper reports no times."))
    reach = metrics.get("reach-poses")
    if reach is not None and not reach.empty:
        sections.append(compute_time_section("Compute time, IK", reach, "A-nominal",
                                             [("IK iteration: FK + Jacobian + SVD-DLS", "ik_iteration",
                                               "not reported")],
                                             machine_of(runs, "reach-poses")))
    return sections
