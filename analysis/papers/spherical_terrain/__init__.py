"""Analysis of `spherical-terrain`: convergence time, steady-state and vertex errors, control effort and tilt
saturation of every tracking run (spec §7); the paper's Figs. 6-12 regenerated; the gain/start sweep
tabulated from whatever sweep runs are on disk; and the physics check (MuJoCo vs the no-slip model)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.errors import error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run
from pipeline.papers.spherical_terrain.kinematics import CosineTerrain
from pipeline.papers.spherical_terrain.paths import vertex_times
from pipeline.papers.spherical_terrain.tracking import CLASSES

LABEL = {"3r": "3R-SR", "2r": "2R-SR", "rt": "RT-SR", "rs": "RS-SR"}
COLOR = {"3r": "C0", "2r": "C1", "rt": "C2", "rs": "C3"}
EPSILONS = (0.05, 0.1, 0.2)      # m, convergence thresholds (spec §7)
WINDOWS = (40.0, 30.0)           # s, start of the steady-state window (spec §7)
VERTEX_HALF_WIDTH = 5.0          # s, error near a vertex: within ±5 s of the target passing it (spec §7)
CLAIM_TIME = 45.0                # s, "converges in approximately 30 s": t_c(0.1 m) ≤ 1.5 × 30 s


def convergence_time(t: np.ndarray, e: np.ndarray, eps: float) -> float:
    """t_c(ε) = inf{t : e(τ) ≤ ε for all τ ≥ t}; NaN if the last sample is above ε."""
    above = np.flatnonzero(e > eps)
    if not len(above):
        return float(t[0])
    return float(t[above[-1] + 1]) if above[-1] + 1 < len(t) else float("nan")


def _case(run: Run) -> tuple[str, str]:
    robot, path = run.metadata["case"].split("-", 1)
    return robot, path


def _terrain(run: Run) -> CosineTerrain:
    t = run.config["system"]["terrain"]
    return CosineTerrain(t["amplitude"], t["frequency"])


def tracking_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """Spec §7 for one tracking run."""
    robot, path = _case(run)
    err = run["/tracking_error"]
    t, e = err.index.to_numpy(), err["norm"].to_numpy()
    values: dict[str, tuple[float, str]] = {}
    for eps in EPSILONS:
        values[f"tc_{eps:g}"] = (convergence_time(t, e, eps), "s")
    entered = np.flatnonzero(e <= 0.1)
    values["first_entry_0.1"] = (float(t[entered[0]]) if len(entered) else float("nan"), "s")
    for start in WINDOWS:  # a run shorter than the window has no steady-state statistics
        window = t >= start
        if window.any():
            values |= error_stats(t[window], e[window], f"error_after_{start:g}s", "m")
    window = t >= WINDOWS[0]
    if window.any():
        zeta = np.abs(run["/pursuit"]["value.zeta"].to_numpy()[window])
        values["zeta.mean_abs"], values["zeta.max_abs"] = (float(zeta.mean()), "rad"), (float(zeta.max()), "rad")
    if path == "diamond":
        d = run.config["system"]["paths"]["diamond"]
        passes = vertex_times(t[-1], d["diagonal"], d["speed"])
        passes = passes[passes >= WINDOWS[0]]
        near = np.zeros_like(t, dtype=bool)
        for tv in passes:
            near |= np.abs(t - tv) <= VERTEX_HALF_WIDTH
        if near.any():
            values["vertex.max"] = (float(e[near].max()), "m")
            values["vertex.mean"] = (float(e[near].mean()), "m")
    command = run["/command"]
    for column in command.columns:
        if column.startswith("value."):
            u = command[column].to_numpy()
            name = column.removeprefix("value.")
            values[f"effort.{name}.rms"] = (float(np.sqrt(np.mean(u * u))), "rad/s")
            values[f"effort.{name}.max"] = (float(np.abs(u).max()), "rad/s")
    if robot == "rs":
        phi = run["/joint_state"]["position.phi"].to_numpy()
        values["tilt.max_abs"] = (float(np.abs(phi).max()), "rad")
        values["tilt.saturated_fraction"] = (float(run["/pursuit"]["value.tilt_saturated"].mean()), "fraction")
    values["claim.converges"] = (float(values["tc_0.1"][0] <= CLAIM_TIME), "bool")
    return values


def _reference_metrics(runs: dict[str, Run]) -> dict[str, tuple[float, str]]:
    """The reference paths as generated, measured from the logs (radius, rate, diagonals)."""
    values = {}
    circle = next((r for k, r in runs.items() if k.endswith("-circle")), None)
    if circle is not None:
        ref = circle["/reference"]
        x, y = ref["position.x"].to_numpy(), ref["position.y"].to_numpy()
        angle = np.unwrap(np.arctan2(y, x))
        values["circle.radius"] = (float(np.hypot(x, y).mean()), "m")
        values["circle.rate"] = (float(np.polyfit(ref.index.to_numpy(), angle, 1)[0]), "rad/s")
    diamond = next((r for k, r in runs.items() if k.endswith("-diamond")), None)
    if diamond is not None:
        ref = diamond["/reference"]
        values["diamond.diagonal_x"] = (float(np.ptp(ref["position.x"])), "m")
        values["diamond.diagonal_y"] = (float(np.ptp(ref["position.y"])), "m")
    return values


def _agility(table: pd.DataFrame) -> dict[str, tuple[float, str]]:
    """Sec. 6: '3R and 2R-SRs outperform RT and RS-SRs in tracking the nonsmooth trajectory', as ratios
    worst(3R, 2R) / best(RT, RS) on the diamond (< 1 when the claim holds)."""
    values = {}
    for metric, name in (("vertex.max", "claim.vertex_error_ratio"), ("error_after_40s.rms", "claim.rms_error_ratio")):
        got = {r: table.get((f"{r}-diamond", metric)) for r in CLASSES}
        if all(v is not None for v in got.values()):
            values[name] = (max(got["3r"], got["2r"]) / min(got["rt"], got["rs"]), "ratio")
    return values


# -- figures -----------------------------------------------------------------------------------------


def _surface(ax, terrain: CosineTerrain, extent: float = 2.6) -> None:
    grid = np.linspace(-extent, extent, 41)
    x, y = np.meshgrid(grid, grid)
    ax.plot_wireframe(x, y, terrain.height(x, y), rstride=2, cstride=2, color="0.75", lw=0.4)


def _paths_3d(runs: dict[str, Run], path: str, title: str, figures: Figures, name: str) -> None:
    fig = plt.figure(figsize=(7, 5.5))
    ax = fig.add_subplot(projection="3d")
    some = next(iter(runs.values()))
    _surface(ax, _terrain(some))
    drew_reference = False
    for robot in CLASSES:
        run = runs.get(f"{robot}-{path}")
        if run is None:
            continue
        tf = run["/tf"]
        p = tf[[f"transforms.contact.translation.{a}" for a in "xyz"]].to_numpy()
        ax.plot(*p.T, color=COLOR[robot], lw=1.2, label=LABEL[robot])
        if not drew_reference:
            ref = run["/reference"][[f"position.{a}" for a in "xyz"]].to_numpy()
            ax.plot(*ref.T, "k--", lw=1.0, label="desired")
            drew_reference = True
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.set_zlabel("Z [m]")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=7)
    figures.save(fig, name)


def _xyz_vs_time(runs: dict[str, Run], path: str, title: str, figures: Figures, name: str) -> None:
    fig, axes = plt.subplots(3, 1, figsize=(8, 6.5), sharex=True)
    for k, axis in enumerate("xyz"):
        drew = False
        for robot in CLASSES:
            run = runs.get(f"{robot}-{path}")
            if run is None:
                continue
            err, ref = run["/tracking_error"], run["/reference"]
            actual = ref[f"position.{axis}"] - err[f"error.{axis}"]
            axes[k].plot(actual.index, actual, color=COLOR[robot], lw=1.0, label=LABEL[robot])
            if not drew:
                axes[k].plot(ref.index, ref[f"position.{axis}"], "k--", lw=1.0, label="desired")
                drew = True
        axes[k].set_ylabel(f"{axis.upper()} [m]")
    axes[0].legend(ncol=5, fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    figures.save(fig, name)


def _controls(runs: dict[str, Run], robot: str, title: str, figures: Figures, name: str) -> None:
    series = [(p, runs[f"{robot}-{p}"]["/command"]) for p in ("circle", "diamond") if f"{robot}-{p}" in runs]
    if not series:
        return
    columns = [c for c in series[0][1].columns if c.startswith("value.")]
    fig, axes = plt.subplots(len(columns), 1, figsize=(8, 2.2 * len(columns)), sharex=True)
    for ax, column in zip(np.atleast_1d(axes), columns, strict=True):
        for path, command in series:
            ax.plot(command.index, command[column], lw=0.8, label=path)
        ax.set_ylabel(column.removeprefix("value.").replace("_dot", " rate") + " [rad/s]")
    np.atleast_1d(axes)[0].legend()
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    figures.save(fig, name)


def _tilt(runs: dict[str, Run], figures: Figures, name: str) -> None:
    fig, ax = plt.subplots(figsize=(8, 2.8))
    limit = None
    for path in ("circle", "diamond"):
        run = runs.get(f"rs-{path}")
        if run is None:
            continue
        phi = run["/joint_state"]["position.phi"]
        ax.plot(phi.index, phi, lw=0.9, label=path)
        limit = run.config["system"]["tilt_limit"]
    if limit is not None:
        for sign in (-1, 1):
            ax.axhline(sign * limit, color="k", ls=":", lw=1)
    ax.set_ylabel("RS-SR tilt φ [rad]")
    ax.set_xlabel("time [s]")
    ax.set_title("Fig. 12(b) regenerated: tilting angle, limit ±π/3 dotted")
    ax.legend()
    figures.save(fig, name)


def _errors(runs: dict[str, Run], title: str, figures: Figures, name: str) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.4), sharey=True)
    for ax, path in zip(axes, ("circle", "diamond"), strict=True):
        for robot in CLASSES:
            run = runs.get(f"{robot}-{path}")
            if run is None:
                continue
            e = run["/tracking_error"]["norm"]
            ax.semilogy(e.index, np.maximum(e, 1e-5), color=COLOR[robot], lw=0.9, label=LABEL[robot])
        ax.axhline(0.1, color="k", ls=":", lw=1)
        ax.axvline(30.0, color="0.5", ls="--", lw=1)
        ax.set_title(path)
        ax.set_xlabel("time [s]")
    axes[0].set_ylabel("‖e_t‖ [m]  (dotted: 0.1 m, dashed: 30 s)")
    axes[0].legend(fontsize=7)
    fig.suptitle(title)
    figures.save(fig, name)


# -- experiments -------------------------------------------------------------------------------------


def _per_run(runs: list[Run]) -> tuple[MetricTable, dict[str, Run], dict]:
    """Metrics of every run; the run of each case drawn in the figures and compared across classes (the one
    without overrides if there is one); and those runs' metrics as {(case, metric): value}."""
    m = MetricTable()
    by_case: dict[str, Run] = {}
    values_of = {}
    for run in runs:
        values_of[run.run_id] = tracking_metrics(run)
        m.add_run(run, values_of[run.run_id])
        case = run.metadata["case"]
        if case not in by_case or (by_case[case].params and not run.params):
            by_case[case] = run
    table = {(case, k): v for case, run in by_case.items() for k, (v, _) in values_of[run.run_id].items()}
    return m, by_case, table


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
    _errors(by_case, "Tracking error, corrected equations (spec §7)", figures, "tracking-error")
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


MOVING = 0.02   # m/s: samples where the paper's model moves the contact point slower than this are left out


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


# -- extra report tables -----------------------------------------------------------------------------

RUN_COLUMNS = {"tc_0.1": "t_c(0.1 m) [s]", "tc_0.05": "t_c(0.05 m) [s]", "first_entry_0.1": "first ≤ 0.1 m [s]",
               "error_after_40s.mean": "mean e (t≥40) [m]", "error_after_40s.rms": "RMS e (t≥40) [m]",
               "error_after_40s.max": "max e (t≥40) [m]", "vertex.max": "max e near vertices [m]",
               "tilt.max_abs": "max |φ| [rad]", "tilt.saturated_fraction": "tilt saturated [fraction]"}


def _run_table(frame: pd.DataFrame) -> pd.DataFrame:
    default = frame[~frame["run_id"].str.contains("__") & (frame["run_id"] != "all")]
    table = default[default["metric"].isin(RUN_COLUMNS)].pivot(index="run_id", columns="metric", values="value")
    effort = default[default["metric"].str.match(r"effort\..*\.rms")]
    effort = effort.assign(rate=effort["metric"].str.split(".").str[1]).groupby("run_id").apply(
        lambda g: ", ".join(f"{r} {v:.3g}" for r, v in zip(g["rate"], g["value"], strict=True)),
        include_groups=False)
    table = table.reindex(columns=[c for c in RUN_COLUMNS if c in table.columns]).rename(columns=RUN_COLUMNS)
    table["RMS rates [rad/s]"] = effort
    return table.reset_index()


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = []
    for name, title, text in (
            ("paths", "Tracking runs, corrected equations", "Default gains (all 1, k_e = 1 m), start at the "
             "origin with ψ0 = 0, forward Euler at 200 Hz. Steady-state errors of a few mm are the chattering "
             "of the pursuit law around the target at this step (they halve with the step)."),
            ("printed", "Tracking runs, eqs. (25), (58), (60) as printed", "The same gains and start. With eq. "
             "(25) as printed the heading laws of 3R and RT turn them away from the target, and with eq. (58) as "
             "printed the RS-SR's tilt rolls it away sideways; 2R-SR (ψ ≡ 0) is unaffected. Eq. (60) as printed "
             "is a segment of the line y = x, traversed back and forth, so 'circle' here is that segment.")):
        frame = metrics.get(name)
        if frame is not None and not frame.empty:
            sections.append(f"## {title}\n\n{text}\n\n" + _run_table(frame).to_markdown(index=False, floatfmt=".4g"))
    sweep = metrics.get("sweep")
    if sweep is not None and not sweep.empty:
        params = [c for c in sweep.columns if c not in ("run_id", "metric", "value", "unit")]
        rows = sweep[sweep["metric"].isin(["tc_0.1", "error_after_40s.mean", "vertex.max"])].copy()
        rows["case"] = rows["run_id"].str.split("__").str[0]
        table = rows.pivot_table(index=["case", *params], columns="metric", values="value", aggfunc="first",
                                 dropna=False).reset_index()
        converged = sweep[sweep["metric"] == "claim.converges"]
        share = f"{int(converged['value'].sum())}/{len(converged)}"
        sections.append(f"## Gain and start sweep\n\nEvery sweep run on disk ({len(converged)} runs; swept: "
                        f"{', '.join(params) or 'nothing'}). Runs with t_c(0.1 m) ≤ {CLAIM_TIME:g} s: {share}. "
                        "An empty t_c means the error is above 0.1 m at the end.\n\n"
                        + table.to_markdown(index=False, floatfmt=".4g"))
    physics = metrics.get("physics-check")
    if physics is not None and not physics.empty:
        keep = {"paper_model_error.median": "vs paper model (median)", "rigid_model_error.median":
                "vs rigid rolling (median)", "paper_model_error.weighted": "vs paper model (weighted)",
                "rigid_model_error.weighted": "vs rigid rolling (weighted)", "speed_ratio.p05": "speed ratio p5",
                "speed_ratio.p95": "speed ratio p95",
                "slip.median": "slip median [m/s]", "drive.omega_error_median": "|ω − ω_cmd| median [rad/s]",
                "tc_0.1": "t_c(0.1 m) [s]", "kinematic.tc_0.1": "t_c kinematic [s]",
                "error_after_40s.mean": "mean e (t≥40) [m]", "kinematic.error_after_40s.mean": "kinematic [m]",
                "error_after_40s.max": "max e (t≥40) [m]"}
        table = physics[physics["metric"].isin(keep)].pivot(index="run_id", columns="metric", values="value")
        table = table.reindex(columns=[k for k in keep if k in table.columns]).rename(columns=keep)
        sections.append(
            "## Physics check (not in the paper)\n\nEach robot is a 2 kg ball on a MuJoCo height field of eq. "
            "(59), driven by torque-limited velocity actuators to the ω the paper's controller asks for, in closed "
            "loop at 100 Hz; the kinematic model runs beside it with the same controller and step. Model errors "
            "compare the ball's contact-point velocity v with two models fed the ball's measured ω, relative to "
            "‖v_paper‖: the median over samples while moving, and Σ‖v − v_model‖ / Σ‖v_paper‖ (weighted, which "
            "the drive's transients dominate). 'paper model' is eq. (31) (ω × R n̂), 'rigid rolling' adds the "
            "curvature term the paper drops "
            "(the difference of the two columns is the curvature effect; what remains against rigid rolling is "
            "slip, soft contact and the field's facets). Speed ratio: MuJoCo contact speed over the paper "
            "model's, 5th/95th percentile while moving (the curvature bound is 1/(1 ± Rκ) = 0.86…1.19).\n\n"
            + table.reset_index().to_markdown(index=False, floatfmt=".4g"))
    return sections
