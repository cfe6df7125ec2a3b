"""Analysis of `partial-lagrangian`: the motions of Figs. 1-5a (damped oscillation, PD and PID settling,
static offsets against the closed-form equilibrium, Listing A1 against the Lagrange equations), the compute
time of Fig. 5b with log-log slopes, and the checks of the AD dynamics against MuJoCo."""

from __future__ import annotations

import numpy as np
import pandas as pd
from mpl_toolkits.mplot3d.art3d import Line3DCollection
from scipy.optimize import fsolve

from analysis.core.compute_time import compute_time_section, machine_of, timing_metrics
from analysis.core.errors import error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable, metric_value
from pipeline.core.runlog import Run
from pipeline.papers.partial_lagrangian.chain import from_config, gravity_torque

STEADY_WINDOW = 1.0      # s: steady state = mean over the last second (spec §7)
SETTLED_SPEED = 1e-2     # rad/s or m/s: settled if every controlled |q̇| stays below this over the last second
SETTLING_BAND = 0.02     # settling time: last entry into ±2 % of the step (spec §7)
SLOPE_FROM = 3           # log-log slopes fitted over n = 3..10 (spec §7)
SNAPSHOT_DT = 0.1        # s between chain drawings in the figures
METHODS = {"full": "AD, full Lagrangian", "partial": "AD, partial Lagrangians summed (1 thread)",
           "column": "AD, column n alone (ideal n threads)", "mujoco": "MuJoCo mj_step (our extension)"}
KINDS = {"eval": "dynamics evaluation q̈", "terms": "equation-of-motion terms (M, b)",
         "build": "graph generation + AD of the terms", "ops": "operations in the terms graph"}


def _positions(run: Run) -> tuple[np.ndarray, np.ndarray, list[str]]:
    js = run["/joint_state"]
    names = [c.removeprefix("position.") for c in js.columns if c.startswith("position.")]
    return js.index.to_numpy(), js[[f"position.{n}" for n in names]].to_numpy(), names


def _velocities(run: Run, names: list[str]) -> np.ndarray:
    return run["/joint_state"][[f"velocity.{n}" for n in names]].to_numpy()


def _tips(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """Tip positions in the paper's plane from /tf: (times, (N, n, 2) with x and the vertical y)."""
    tf = run["/tf"]
    tips = sorted({c.split(".")[1] for c in tf.columns if c.startswith("transforms.")}, key=lambda s: int(s[3:]))
    xy = np.stack([tf[[f"transforms.{k}.translation.x", f"transforms.{k}.translation.z"]].to_numpy() for k in tips],
                  axis=1)
    return tf.index.to_numpy(), xy


def _is_angle(name: str) -> bool:
    return name.startswith("theta")


# -- figures: q(t) and the chain drawn against time, as the paper draws it (Sect. 2.2) --------------------


def _chain_figure(run: Run, title: str, figures: Figures, twin: Run | None = None,
                  views: tuple[tuple[str, float, float], ...] = (("", 20.0, -60.0),)) -> None:
    """q(t) (angles in degrees; a slider's length in metres on the right axis), and the chain drawn every
    SNAPSHOT_DT against time, coloured by time, with the path of the last mass in red."""
    t, q, names = _positions(run)
    fig = plt.figure(figsize=(4.6 + 3.6 * len(views), 3.6))
    ax = fig.add_subplot(1, 1 + len(views), 1)
    axes = {True: ax, False: None}
    ref = run["/reference"] if "/reference" in run.topic_names else pd.DataFrame()
    twin_q = _positions(twin) if twin is not None else None
    for j, name in enumerate(names):
        angle = _is_angle(name)
        if axes[angle] is None:
            axes[angle] = ax.twinx()
            axes[angle].set_ylabel("length [m]")
        scale = 180 / np.pi if angle else 1.0
        line, = axes[angle].plot(t, q[:, j] * scale, lw=1.2, color=f"C{j}", label=name)
        if f"position.{name}" in ref:
            axes[angle].axhline(ref[f"position.{name}"].iloc[0] * scale, color=line.get_color(), ls=":", lw=1)
        if twin_q is not None:
            axes[angle].plot(twin_q[0], twin_q[1][:, j] * scale, "k--", lw=0.8, label="Listing A1")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("angle [°]")
    handles = [h for a in axes.values() if a is not None for h in a.get_legend_handles_labels()[0]]
    ax.legend(handles=handles, fontsize=7, loc="best")
    t_tf, xy = _tips(run)
    every = max(1, round(SNAPSHOT_DT / (t_tf[1] - t_tf[0]))) if len(t_tf) > 1 else 1
    t_snap, xy_snap = t_tf[::every], xy[::every]
    pts = np.concatenate([np.zeros((len(t_snap), 1, 2)), xy_snap], axis=1)   # (snapshots, base + n tips, 2)
    segments = np.stack([pts[..., 0], np.broadcast_to(t_snap[:, None], pts.shape[:2]), pts[..., 1]], axis=-1)
    reach = np.abs(pts).max() * 1.05
    for k, (view, elev, azim) in enumerate(views, start=2):
        ax3 = fig.add_subplot(1, 1 + len(views), k, projection="3d")
        ax3.add_collection3d(Line3DCollection(segments, colors=plt.cm.viridis(np.linspace(0, 1, len(t_snap))),
                                              lw=0.8))
        ax3.plot(xy[:, -1, 0], t_tf, xy[:, -1, 1], color="r", lw=0.6)
        ax3.set(xlim=(-reach, reach), ylim=(t_tf[0], t_tf[-1]), zlim=(-reach, reach), xlabel="x [m]",
                ylabel="t [s]", zlabel="y [m]")
        ax3.view_init(elev=elev, azim=azim)
        if view:
            ax3.set_title(view, fontsize=8)
    fig.suptitle(title, fontsize=9)
    figures.save(fig, run.run_id)


# -- Figs. 1, 2, 3, 5a -------------------------------------------------------------------------------------


def _damped_oscillation(t: np.ndarray, q1: np.ndarray, energy: np.ndarray) -> dict[str, tuple[float, str]]:
    """Qualitative rule: link 1 swings back and forth (≥ 3 reversals of its rate) and the chain ends with
    less energy than it started with."""
    qd = np.diff(q1)
    reversals = int((np.sign(qd[1:]) * np.sign(qd[:-1]) < 0).sum())
    return {"reversals": (reversals, "count"), "energy.change": (energy[-1] - energy[0], "J"),
            "damped_oscillation": (float(reversals >= 3 and energy[-1] < energy[0]), "bool")}


def _decay_rate(t: np.ndarray, q1: np.ndarray) -> float:
    """Envelope decay rate (1/s) of a one-link swing, from the later half of its swings: half the distance
    between successive turning points, against time (no rest angle needed)."""
    turns = np.flatnonzero(np.sign(np.diff(q1[1:])) != np.sign(np.diff(q1[:-1]))) + 1
    if len(turns) < 6:
        return float("nan")
    half_swing = np.abs(np.diff(q1[turns])) / 2
    mid = (t[turns[1:]] + t[turns[:-1]]) / 2
    later = slice(len(mid) // 2, None)   # the smaller swings: closest to the linear theory
    return float(-np.polyfit(mid[later], np.log(half_swing[later]), 1)[0])


def _linear_decay_rate(config: dict) -> float:
    """Small swings of one link about the hanging rest decay at c/(2 m l²), with the generalized damping
    c = d l² of the Cartesian damper or c = d of the joint damper (spec §8.4)."""
    system = config["system"]
    d, m, length = (system["links"][key][0] for key in ("damping", "mass", "length"))
    c = d * length ** 2 if system["damping_model"] == "cartesian" else d
    return c / (2 * m * length ** 2)


def _energy_balance(run: Run, scale: float) -> float:
    """max |H(t) − H(0) − ∫(τ·q̇ − 2R) dt| / energy scale: the logged motion obeys its own power balance."""
    e = run["/energy"]
    t = e.index.to_numpy()
    net = e["value.input_power"].to_numpy() - e["value.dissipation"].to_numpy()
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (net[1:] + net[:-1]) * np.diff(t))])
    return float(np.abs(e["value.total"].to_numpy() - e["value.total"].iloc[0] - integral).max() / scale)


def energy_scale(config: dict, n: int) -> float:
    """Σ m_i g r_i, r_i = distance of mass i from the base when straight: the energy drop from horizontal
    to hanging, the scale of every energy error."""
    links = config["system"]["links"]
    reach = np.cumsum(links["length"][:n])
    return float(np.sum(np.asarray(links["mass"][:n]) * config["system"]["gravity"] * reach))


def static_equilibrium(config: dict, n: int, reference: np.ndarray, kp: np.ndarray) -> np.ndarray:
    """The rest posture of the PD law without gravity compensation: Kp (r − q) = ∂P/∂q (spec §8.5), with
    the gravity torque from statics (not from either dynamics model); solved from q = r."""
    chain = from_config(config["system"], n)
    return fsolve(lambda q: kp * (reference - q) - gravity_torque(chain, q), reference, xtol=1e-12)


def _control_metrics(run: Run, names: list[str]) -> dict[str, tuple[float, str]]:
    """Per controlled coordinate: error statistics, rest value, settling time, overshoot; and whether every
    controlled coordinate has come to rest."""
    t, q, _ = _positions(run)
    qd = _velocities(run, names)
    late = t >= t[-1] - STEADY_WINDOW
    err = run["/tracking_error"]
    values, settled = {}, True
    for col in err.columns:
        if not col.startswith("error."):
            continue
        name = col.removeprefix("error.")
        j = names.index(name)
        unit = "rad" if _is_angle(name) else "m"
        speed = float(np.abs(qd[late, j]).max())
        settled &= speed < SETTLED_SPEED
        values[f"{name}.final_speed"] = (speed, f"{unit}/s")
        e = err[col].to_numpy()
        values |= error_stats(err.index.to_numpy(), e, f"{name}.error", unit)
        final = q[late, j].mean()
        step = e[0]
        outside = np.flatnonzero(np.abs(q[:, j] - final) > SETTLING_BAND * abs(step))
        overshoot = (max(0.0, np.max(np.sign(step) * (q[:, j] - final))) / abs(step)) if step else 0.0
        values |= {f"{name}.final": (final, unit), f"{name}.steady_error": (e[late].mean(), unit),
                   f"{name}.settling_time": (t[outside[-1] + 1] if len(outside) else 0.0, "s"),
                   f"{name}.overshoot": (overshoot * 100, "%")}
    values["settled"] = (float(settled), "bool")
    return values


def analyze_pendulum(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_case = {r.metadata["case"]: r for r in runs}
    for run in runs:
        case = run.metadata["case"]
        t, q, names = _positions(run)
        n = len(names)
        scale = energy_scale(run.config, n)
        values = {"energy_balance.max_error": (_energy_balance(run, scale), "fraction")}
        energy = run["/energy"]["value.total"].to_numpy()
        if case.startswith("free"):
            values |= _damped_oscillation(t, q[:, 0], energy)
            if n == 1:
                values["decay_rate"] = (_decay_rate(t, q[:, 0]), "1/s")
                values["decay_rate.linear_theory"] = (_linear_decay_rate(run.config), "1/s")
        if case.startswith("pd"):
            values |= _control_metrics(run, names)
            pd_cfg = run.config["scenario"]["pd"]
            reference, kp = np.radians(pd_cfg["reference_deg"]), np.asarray(pd_cfg["kp"], dtype=float)
            q_eq = static_equilibrium(run.config, n, reference, kp)
            for j, name in enumerate(names):
                values[f"{name}.equilibrium"] = (q_eq[j], "rad")
                values[f"{name}.final_minus_equilibrium"] = (values[f"{name}.final"][0] - q_eq[j], "rad")
        if case.endswith("-listing") and case.removesuffix("-listing") in by_case:
            _, q_std, _ = _positions(by_case[case.removesuffix("-listing")])
            values["listing_deviation.max"] = (float(np.abs(q - q_std).max()), "rad")
        m.add_run(run, values)
        if not case.endswith("-listing"):
            twin = by_case.get(f"{case}-listing")
            label = {"free": "damped oscillation", "pd": "PD control"}.get(case, case)
            _chain_figure(run, f"{n} link{'s' if n > 1 else ''}: {label} (AD, partial Lagrangian)", figures, twin)
    return m.frame()


# -- Fig. 4 -------------------------------------------------------------------------------------------------


def analyze_slider(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        _, _, names = _positions(run)
        scale = energy_scale(run.config, len(names))
        m.add_run(run, _control_metrics(run, names) | {"energy_balance.max_error": (_energy_balance(run, scale),
                                                                                     "fraction")})
        _chain_figure(run, "Link 2 changed to a slider, l2: 1 → 0.1 m under PID (Fig. 4)", figures,
                      views=(("(a) side view (y against t)", 0.0, 0.0), ("(b) front view (along t)", 0.0, -90.0)))
    return m.frame()


# -- Fig. 5b: compute time ----------------------------------------------------------------------------------


def paper_term_counts(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (28): ½(n² + n)(n² + 2n) terms without dividing; eq. (29): n(n² + 2n) with partial Lagrangians
    on n threads. The paper's own model of Fig. 5b."""
    n = np.asarray(n, dtype=float)
    return 0.5 * (n * n + n) * (n * n + 2 * n), n * (n * n + 2 * n)


def slope(n: np.ndarray, seconds: np.ndarray) -> float:
    """Exponent p of time ∝ n^p, least squares in log-log over n ≥ SLOPE_FROM."""
    keep = n >= SLOPE_FROM
    return float(np.polyfit(np.log(n[keep]), np.log(seconds[keep]), 1)[0])


def _timing_table(ct: pd.DataFrame) -> pd.DataFrame:
    """(kind, method, n) -> per-item seconds, from the /compute_time columns `seconds.<kind>.<method>.n<k>`."""
    rows = []
    for col in ct.columns:
        if not col.startswith("seconds."):
            continue
        name = col.removeprefix("seconds.")
        kind, method, n = name.split(".")
        per_item = ct[col].dropna().to_numpy() / ct[f"calls.{name}"].dropna().to_numpy()
        rows += [{"kind": kind, "method": method, "n": int(n[1:]), "seconds": s} for s in per_item]
    return pd.DataFrame(rows)


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Median and p95 per (kind, method, n); log-log slopes of the medians and of the graph sizes (the
    deterministic operation counts eqs. 28-29 model); the full − column-n slope gap (the claimed O(n⁴) →
    O(n³)); ratios at the largest n."""
    m = MetricTable()
    for run in runs:
        table = _timing_table(run["/compute_time"])
        values = {}
        curves: dict[tuple[str, str], pd.Series] = {}
        for (kind, method), group in table.groupby(["kind", "method"]):
            for n, g in group.groupby("n"):
                values |= timing_metrics(f"{kind}.{method}.n{n}", g["seconds"])
            curves[kind, method] = group.groupby("n")["seconds"].median()
        sizes = run["/graph_size"]
        for method in ("full", "partial", "column"):
            curves["ops", method] = sizes[f"value.terms.{method}"].set_axis(sizes.index.astype(int))
            values |= {f"ops.{method}.n{n}": (v, "count") for n, v in curves["ops", method].items()}
        for (kind, method), curve in curves.items():
            values[f"slope.{kind}.{method}"] = (slope(curve.index.to_numpy(), curve.to_numpy()), "")
        for kind in ("terms", "build", "ops"):
            full, column = curves[kind, "full"], curves[kind, "column"]
            top = full.index.max()
            values[f"slope_gap.{kind}"] = (values[f"slope.{kind}.full"][0] - values[f"slope.{kind}.column"][0], "")
            values[f"ratio.{kind}.full_over_column.n{top}"] = (full[top] / column[top], "ratio")
        for kind in ("eval", "terms", "build", "ops"):
            full, partial = curves[kind, "full"], curves[kind, "partial"]
            values[f"ratio.{kind}.partial_over_full.n{full.index.max()}"] = (partial.iloc[-1] / full.iloc[-1], "ratio")
        ops_ratio = sizes["value.inverse.partial"] / sizes["value.inverse.full"]
        values |= {f"ops.inverse.partial_over_full.n{n:.0f}": (r, "ratio") for n, r in ops_ratio.items()}
        m.add_run(run, values)
        _compute_time_figure(curves, figures, run.run_id)
    return m.frame()


def _compute_time_figure(curves: dict, figures: Figures, name: str) -> None:
    fig, axes = plt.subplots(1, len(KINDS), figsize=(16, 3.8))
    n = np.arange(1, 11)
    eq28, eq29 = paper_term_counts(n)
    for ax, (kind, title) in zip(axes, KINDS.items(), strict=True):
        scale = 1.0 if kind == "ops" else 1e6
        for k, (method, label) in enumerate(METHODS.items()):
            curve = curves.get((kind, method))
            if curve is not None:
                ax.loglog(curve.index, curve.to_numpy() * scale, "o-", color=f"C{k}", ms=3, label=label)
        if kind != "eval":
            anchor = curves[kind, "full"].iloc[-1] * scale
            ax.loglog(n, eq28 / eq28[-1] * anchor, "k--", lw=0.8, label="eq. (28), O(n⁴), scaled to full at n = 10")
            ax.loglog(n, eq29 / eq28[-1] * anchor, "k:", lw=0.8, label="eq. (29), O(n³), same scale")
        ax.set_xlabel("links n")
        ax.set_ylabel("operations" if kind == "ops" else "time per call [µs]")
        ax.set_title(title, fontsize=8)
        ax.legend(fontsize=6)
    fig.suptitle("Fig. 5b: cost against the number of links (medians over repeats, one thread)", fontsize=9)
    figures.save(fig, f"{name}-cost")


# -- checks -------------------------------------------------------------------------------------------------


def analyze_checks(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    worst: dict[str, float] = {}
    for run in runs:
        states = run["/check/random_states"]
        values = {f"{c.removeprefix('value.')}.max_rel": (states[c].max(), "fraction") for c in states.columns
                  if states[c].notna().any()}
        _, q, names = _positions(run)
        mj = run["/joint_state/mujoco"][[f"position.{n}" for n in names]].to_numpy()
        values["trajectory_vs_mujoco.max"] = (float(np.abs(q - mj).max()), "rad")
        scale = energy_scale(run.config, len(names))
        for topic in run.topic_names:
            if topic.startswith("/energy/"):
                total = run[topic]["value.total"].to_numpy()
                values[f"energy_drift.{topic.removeprefix('/energy/')}"] = (np.abs(total - total[0]).max() / scale,
                                                                            "fraction")
        m.add_run(run, values)
        for key, (value, _) in values.items():
            worst[key] = max(worst.get(key, 0.0), value)
    for key, value in worst.items():
        m.add("all", key, value, "fraction" if "trajectory" not in key else "rad")
    return m.frame()


ANALYSES = {"one-link": analyze_pendulum, "two-link": analyze_pendulum, "three-link": analyze_pendulum,
            "ten-link": analyze_pendulum, "slider": analyze_slider, "compute-time": analyze_compute_time,
            "checks": analyze_checks}


# -- extra report tables -----------------------------------------------------------------------------------



def _pd_section(metrics: dict[str, pd.DataFrame]) -> str | None:
    rows = []
    for experiment in ("one-link", "two-link", "three-link"):
        frame = metrics.get(experiment)
        if frame is None or "pd" not in set(frame["run_id"]):
            continue
        finals = frame[(frame["run_id"] == "pd") & frame["metric"].str.match(r"theta\d+\.final$")]
        for metric in finals["metric"]:
            joint = metric.split(".")[0]
            value = {key: metric_value(frame, "pd", f"{joint}.{key}") for key in
                     ("final", "steady_error", "equilibrium", "settling_time", "overshoot")}
            final, steady = np.degrees(value["final"]), np.degrees(value["steady_error"])
            rows.append({"experiment": experiment, "joint": joint, "reference [°]": final + steady,
                         "simulated rest [°]": final, "closed-form rest [°]": np.degrees(value["equilibrium"]),
                         "rest − reference [°]": -steady, "settling time [s]": value["settling_time"],
                         "overshoot [%]": value["overshoot"]})
    if not rows:
        return None
    return ("## PD control: where the chains come to rest\n\nThe paper's PD law τ = Kp (θref − θ) − Kd θ̇ (radians, "
            "no gravity compensation: nothing else is stated) holds the chain where the spring torque balances "
            "gravity, not at the reference. The closed-form rest solves Kp (θref − θ) = ∂P/∂θ by statics "
            "(spec §8.5).\n\n" + pd.DataFrame(rows).to_markdown(index=False, floatfmt=".3f"))


def _per_n_table(ct: pd.DataFrame, run_id: str, ns: list[int], columns: list[tuple[str, str]]) -> str:
    """Median (p95) in µs of each (kind, method) by n."""
    rows = []
    for n in ns:
        row = {"n": n}
        for kind, method in columns:
            med, p95 = (metric_value(ct, run_id, f"{kind}.{method}.n{n}.{stat}") * 1e6 for stat in ("median", "p95"))
            row[f"{kind} {method}"] = f"{med:.3g} ({p95:.3g})"
        rows.append(row)
    return pd.DataFrame(rows).to_markdown(index=False)


def _compute_time_sections(ct: pd.DataFrame, runs: pd.DataFrame) -> list[str]:
    run_id = "chains"
    ns = sorted({int(x.split(".n")[1].split(".")[0]) for x in ct["metric"] if x.startswith("eval.full.n")})
    top = max(ns)
    rows = [(f"{KINDS[kind]}: {METHODS[method]}, n = {top}", f"{kind}.{method}.n{top}",
             "Fig. 5b: plotted only (i5-10400, PyTorch)")
            for kind, methods in (("eval", ("full", "partial", "mujoco")), ("terms", ("full", "partial", "column")),
                                  ("build", ("full", "partial", "column"))) for method in methods]
    main = compute_time_section(
        "Compute time (Fig. 5b)", ct, run_id, rows, machine_of(runs, "compute-time"),
        note="Evaluations are per state, from short batches of random states in one CasADi call; MuJoCo's from "
             "`rollout` of one mj_step per state. The paper prints no times (Fig. 5b is an image); its own model of "
             "the figure is the term counts of eqs. (28)-(29), beside ours below.")
    eq28, eq29 = paper_term_counts(np.array(ns))
    ops = pd.DataFrame({"n": ns, **{f"ops {m}": [f"{metric_value(ct, run_id, f'ops.{m}.n{n}'):.0f}" for n in ns]
                                   for m in ("full", "partial", "column")},
                        "eq. 28": [f"{x:.0f}" for x in eq28], "eq. 29": [f"{x:.0f}" for x in eq29]})
    slopes = pd.DataFrame([{"quantity": label,
                             **{METHODS[m]: metric_value(ct, run_id, f"slope.{kind}.{m}") for m in METHODS}}
                           for kind, label in KINDS.items()])
    text = ("## Compute time by number of links\n\nMedian (p95) in µs per call, one thread. `eval`: q̈ by AD of "
            "the full Lagrangian, of the summed partial Lagrangians, and by MuJoCo. `terms`: the coefficients (M, b) "
            "of the equations of motion; `column` is column n of Table 1 alone, the work of the slowest thread if "
            "the n columns ran in parallel (an ideal bound: no thread overhead, no summation). `build`: generating and "
            "differentiating the graph of those terms, which the paper's define-by-run code repeats every step.\n\n"
            + _per_n_table(ct, run_id, ns, [("eval", "full"), ("eval", "partial"), ("eval", "mujoco"),
                                            ("terms", "full"), ("terms", "partial"), ("terms", "column")])
            + "\n\n" + _per_n_table(ct, run_id, ns, [("build", "full"), ("build", "partial"), ("build", "column")])
            + "\n\nOperations in the graphs of the terms (CasADi instructions) beside the paper's term counts "
            "without (eq. 28) and with (eq. 29) partial Lagrangians on n threads:\n\n" + ops.to_markdown(index=False)
            + f"\n\nLog-log slopes over n = {SLOPE_FROM}..{top} (the paper: 4 without dividing, 3 with partial "
            "Lagrangians on n threads):\n\n" + slopes.to_markdown(index=False, floatfmt=".2f"))
    return [main, text]


def _checks_section(checks: pd.DataFrame) -> str:
    columns = {"mass_matrix.max_rel": "M vs MuJoCo", "bias.max_rel": "b vs MuJoCo", "qdd_mujoco.max_rel": "q̈ vs MuJoCo",
               "qdd_full_partial.max_rel": "q̈ full vs partial", "closed_form.max_rel": "closed form (n = 2)",
               "trajectory_vs_mujoco.max": "trajectory vs MuJoCo [rad]",
               "energy_drift.semi-implicit-euler": "energy drift, semi-implicit Euler",
               "energy_drift.rk4": "energy drift, RK4"}
    table = checks[checks["metric"].isin(columns)].pivot(index="run_id", columns="metric", values="value")
    table = table.reindex(columns=[c for c in columns if c in table.columns]).rename(columns=columns)
    order = sorted(table.index, key=lambda r: (r == "all", r == "slider", int(r[1:]) if r[1:].isdigit() else 0))
    return ("## Checks of the AD dynamics (not in the paper)\n\nPer chain: largest relative error over random states "
            "of the mass matrix, the bias force (Coriolis, gravity, damping) and q̈ against MuJoCo's model of the same "
            "chain; full against partial Lagrangian; the closed-form double pendulum (eqs. 17-24 corrected); the "
            "largest joint-angle difference from MuJoCo over the free damped motion (same Euler step); the largest "
            "energy change of the undamped chain over the run, relative to Σ m g r (the energy from horizontal to "
            "hanging).\n\n" + table.loc[order].reset_index().to_markdown(index=False, floatfmt=".2g"))


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = []
    pd_text = _pd_section(metrics)
    if pd_text:
        sections.append(pd_text)
    one = metrics.get("one-link")
    if one is not None and "free-listing" in set(one["run_id"]):
        free, pd_ = (np.degrees(metric_value(one, f"{case}-listing", "listing_deviation.max"))
                     for case in ("free", "pd"))
        decay, theory = (metric_value(one, "free", key) for key in ("decay_rate", "decay_rate.linear_theory"))
        sections.append(
            "## One link (Fig. 1): decay, and Listing A1 against the Lagrange equations\n\n"
            f"The free link's swing decays at {decay:.4f} 1/s over its later swings (linear theory {theory:.4f} 1/s, "
            "spec §8.4). The listing's step stores about half of θ̈ as `acc` (I = acc.grad ≈ 2 m l²) and advances ω "
            "by (acc_prev + acc)·dt, which nearly cancels: largest angle difference from the standard AD dynamics "
            f"{free:.3f}° (free) and {pd_:.3f}° (PD), same dt.")
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        sections += _compute_time_sections(ct, runs)
    checks = metrics.get("checks")
    if checks is not None and not checks.empty:
        sections.append(_checks_section(checks))
    return sections
