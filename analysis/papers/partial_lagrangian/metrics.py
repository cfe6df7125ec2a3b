"""`partial-lagrangian`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.optimize import fsolve

from analysis.core.errors import error_stats
from pipeline.core.runlog import Run
from pipeline.papers.partial_lagrangian.chain import from_config, gravity_torque

STEADY_WINDOW = 1.0      # s: steady state = mean over the last second


SETTLED_SPEED = 1e-2     # rad/s or m/s: settled if every controlled |q̇| stays below this over the last second


SETTLING_BAND = 0.02     # settling time: last entry into ±2 % of the step


SLOPE_FROM = 3           # log-log slopes fitted over n = 3..10


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
    c = d l² of the Cartesian damper or c = d of the joint damper."""
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
    """The rest posture of the PD law without gravity compensation: Kp (r − q) = ∂P/∂q, with
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


def term_count_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """Per chain of n links (links 1..n): terms of the expanded L and of all τ_ki (the usual Lagrangian's
    τ_k hold the same terms: no term of one link merges with another's), of column n alone (one thread's share,
    eq. 29), of the largest τ_ki (τ_1n); the differentiation work, term × coordinate, of the partial
    Lagrangians (L_i by θ_1..θ_i, θ̇_1..θ̇_i) over the usual one's (L by all 2n), and Table 1's share of
    non-zero entries; eqs. (28)-(29); the log-log slopes over n ≥ SLOPE_FROM and the ratio at the largest n."""
    rows = run["/symbolic/terms"].sort_values("link")
    links = rows["link"].to_numpy().astype(int)
    lagrangian = rows["lagrangian"].to_numpy().astype(float)
    tau = rows.filter(regex=r"^tau\[").to_numpy(dtype=float)     # τ_ki of link i's row, k = 1..i (NaN beyond)
    column, tau_max = np.nansum(tau, axis=1), np.nanmax(tau, axis=1)
    every = np.cumsum(column)
    usual_work = 2 * links * np.cumsum(lagrangian)
    partial_work = np.cumsum(2 * links * lagrangian)
    eq28, eq29 = paper_term_counts(links)
    values: dict[str, tuple[float, str]] = {}
    for k, n in enumerate(links):
        values |= {f"sym.lagrangian.n{n}": (float(lagrangian[:k + 1].sum()), "count"),
                   f"sym.all_tau.n{n}": (every[k], "count"), f"sym.column.n{n}": (column[k], "count"),
                   f"sym.tau_max.n{n}": (tau_max[k], "count"),
                   f"sym.half.n{n}": (partial_work[k] / usual_work[k], "ratio"),
                   f"sym.entries.n{n}": ((n + 1) / (2 * n), "ratio"),
                   f"eq28.n{n}": (float(eq28[k]), "count"), f"eq29.n{n}": (float(eq29[k]), "count"),
                   f"sym.seconds.link{n}": (float(rows["seconds"].iloc[k]), "s")}
    for name, curve in (("all_tau", every), ("column", column), ("tau_max", tau_max), ("eq28", eq28), ("eq29", eq29)):
        values[f"slope.{name}"] = (slope(links.astype(float), curve), "")
    values["slope_gap.sym"] = (values["slope.all_tau"][0] - values["slope.column"][0], "")
    values[f"sym.ratio.n{links[-1]}"] = (every[-1] / column[-1], "ratio")
    values["sym.seconds"] = (float(rows["seconds"].sum()), "s")
    return values
