"""`scara-half-derivative`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import yaml

from analysis.core.metrics import MetricTable
from analysis.core.targets import paper_value
from pipeline.core.runlog import Run
from pipeline.core.runner import run_id
from pipeline.papers.scara_half_derivative.arm import gravity_torque, jacobian

AXES = ("x", "y", "z")


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
    return yaml.load(run.attachments["model.yaml"], Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


def _tuning(run: Run) -> dict[str, float]:
    g = _model(run)["gains"]
    return {"k_xyz": g["k_xyz"], "d_xyz": g["d_xyz"], "hd_xyz": g["hd_xyz"]}


def _stiffness_id(k: float) -> str:
    return f"k{k:g}"


GRID_KEYS = ("scenario.k_xyz", "scenario.d_xyz", "scenario.hd_xyz")   # what a case id already says


def variant(run: Run) -> dict[str, str]:
    """The run's swept parameters other than the tuning its case id names: which point of a sensitivity
    sweep (system.control.implementation, system.inertia_scale, scenario.duration) it belongs to."""
    return {k: v for k, v in run.params.items() if k not in GRID_KEYS}


def aggregate_id(name: str, run: Run) -> str:
    """`name` (e.g. k80000) suffixed like the run ids of the sweep point `run` belongs to
    (k80000__system.control.implementation=continuous,…): the aggregates of a sweep point are found, like its
    runs, under `<name>__…`."""
    return run_id(name, variant(run))


def tuning_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """Table 2's indexes, ISE (eq. 19), ICE (eq. 18) and the Exudyn loop gap of one closed-loop run: the
    indexes as the run computed them on its integration steps (`/closed_loop/indexes`; a test checks them
    against the logged signals)."""
    row = run["/closed_loop/indexes"].iloc[0]
    values: dict[str, tuple[float, str]] = {}
    for i, axis in enumerate(AXES):
        values[f"e.{axis}.max"] = (float(row[f"e_max_m[{i}]"]), "m")
        values[f"e.{axis}.mean"] = (float(row[f"e_mean_m[{i}]"]), "m")
    values["ise"] = (float(row["ise_m2s"]), "m^2*s")
    values["ice"] = (float(row["ice_N2m2s"]), "N^2*m^2*s")
    for i in range(4):
        values[f"tau{i + 1}.max"] = (float(row[f"tau_max_Nm[{i}]"]), "Nm")
    if "/loop_closure" in run.topic_names:
        values["loop_gap.max"] = (float(run["/loop_closure"]["value.gap"].abs().max()), "m")
    return values


def _percentages(m: MetricTable, reference: dict, variant: dict, run_id: str, params: dict, names) -> None:
    for name in names:
        base = reference[name][0]
        if abs(base) > NOISE:   # τ4 is zero up to round-off: no percentage of noise
            m.add(run_id, f"pct.{name}", variant[name][0] / base - 1.0, "fraction", params)


def _config_node(run: Run):
    from omegaconf import OmegaConf

    return OmegaConf.create(run.config["system"])


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


def grid_frame(runs: list[Run]) -> pd.DataFrame:
    """One row per grid point on disk (k_xyz, d_xyz, hd_xyz, run_id, ISE, ICE, peak torques) and the id of
    its stiffness's aggregates (`group`: k80000, or k80000__<sweep point>); a point run twice in one group
    (a sweep and the default run) is kept once."""
    rows = [{**_tuning(run), "run_id": run.run_id, "group": aggregate_id(_stiffness_id(_tuning(run)["k_xyz"]), run),
             **variant(run), **{k: v for k, (v, _) in tuning_metrics(run).items()}} for run in runs]
    if not rows:
        return pd.DataFrame(columns=["k_xyz", "d_xyz", "hd_xyz", "run_id", "group", "ise", "ice"])
    frame = pd.DataFrame(rows).sort_values(["group", "d_xyz", "hd_xyz", "run_id"])
    return frame.drop_duplicates(["group", "d_xyz", "hd_xyz"]).reset_index(drop=True)


def equal_ice_locus(grid: pd.DataFrame) -> tuple[float, list[tuple[float, float]]]:
    """(ICE of KD at d = 5000, the points (d, hd) of the equal-ICE line through KD): from KD upward in hd, on
    each row of the grid the d at which ICE crosses KD's level (linear interpolation along d) nearest to the
    previous point's, until a row has no crossing (the level set through KD has left the grid or closed)."""
    kd = grid[(grid["hd_xyz"] == 0) & np.isclose(grid["d_xyz"], KD_DAMPING, rtol=LEVEL_TOLERANCE)]
    if kd.empty:
        return float("nan"), []
    level = float(kd["ice"].iloc[0])
    points = [(KD_DAMPING, 0.0)]
    for hd, row in grid[grid["hd_xyz"] > 0].groupby("hd_xyz"):
        row = row.sort_values("d_xyz")
        d, ice = row["d_xyz"].to_numpy(), row["ice"].to_numpy() - level
        crossings = [float(d[i]) for i in range(len(d)) if ice[i] == 0]
        crossings += [float(d[i] - ice[i] * (d[i + 1] - d[i]) / (ice[i + 1] - ice[i]))
                      for i in range(len(d) - 1) if ice[i] * ice[i + 1] < 0]
        if not crossings:
            break
        points.append((min(crossings, key=lambda c: abs(c - points[-1][0])), float(hd)))
    return level, points
def ice_argmin(grid: pd.DataFrame) -> float:
    """The d_xyz of least ICE along KD's row (hd_xyz = 0): where "more damping, more effort" stops or starts."""
    row = grid[grid["hd_xyz"] == 0]
    return float(row.loc[row["ice"].idxmin(), "d_xyz"]) if len(row) else float("nan")


def rising_fraction(grid: pd.DataFrame, metric: str) -> float:
    """The fraction of the grid's steps (along d and along hd) over which `metric` rises."""
    table = grid.pivot(index="d_xyz", columns="hd_xyz", values=metric).to_numpy()
    steps = np.concatenate([np.diff(table, axis=0).ravel(), np.diff(table, axis=1).ravel()])
    steps = steps[np.isfinite(steps)]
    return float((steps > 0).mean()) if len(steps) else float("nan")


def _monotonic(grid: pd.DataFrame, metric: str, sign: int) -> bool:
    """`metric` changes with the sign `sign` along every grid line of d and of hd."""
    table = grid.pivot(index="d_xyz", columns="hd_xyz", values=metric)
    steps = [np.diff(table.to_numpy(), axis=0), np.diff(table.to_numpy(), axis=1)]
    finite = [s[np.isfinite(s)] for s in steps]
    return bool(all((sign * s > 0).all() for s in finite) and any(s.size for s in finite))


SLUG = "scara-half-derivative"
TABLE2_ROWS = ("e.x.max", "e.y.max", "e.z.max", "e.x.mean", "e.y.mean", "e.z.mean", "tau1.max", "tau2.max",
               "tau3.max", "tau4.max", "ise")


def paper_table2() -> dict[str, tuple[float, float, float]]:
    """Table 2 as printed, read from targets.csv: metric -> (KD, KDHD, KHD) in mm, Nm, m²s."""
    def target(metric: str, controller: str) -> str:
        name = metric.replace("e.", "e").replace(".", "_") if metric != "ise" else "ise"
        return f"T2.{name}.{controller}.k8e5"

    return {m: tuple(paper_value(SLUG, target(m, c)) for c in ("kd", "kdhd", "khd")) for m in TABLE2_ROWS}


SCALE = {"e": 1e3}   # m -> mm for the error rows


def stiffness_bound(arm, q) -> float:
    """The largest k_xyz Table 2's KD column allows (arithmetic on the paper's numbers and its kinematics): where
    |e_a| peaks, ė_a = 0 and KD's Cartesian force has |F| ≥ k |e_a|; the torque it takes, J^T F = τ − τ_g, has a
    norm of at least σ_min(J) |F|, and at most ‖(τ1max, τ2max, τ3max + max|τ_g,3|)‖. So k ≤ that norm /
    (σ_min · max_a e_a,max), with σ_min the least singular value of the translational Jacobian (eq. 7) over the
    set-point's poses `q` (the arm is within mm of them) and τ_g,3 of eq. (12) along them."""
    paper = paper_table2()
    sigma = np.linalg.svd(jacobian(arm, q)[:, :3, :3], compute_uv=False)[:, -1].min()
    gravity = np.abs(gravity_torque(arm, q[:, 2])).max()
    torque = np.hypot(np.hypot(paper["tau1.max"][0], paper["tau2.max"][0]), paper["tau3.max"][0] + gravity)
    error = max(paper[f"e.{a}.max"][0] for a in AXES) * 1e-3   # Table 2 prints mm
    return float(torque / (sigma * error))
