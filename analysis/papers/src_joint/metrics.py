"""`src-joint`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from analysis.core.targets import paper_value
from pipeline.core.runlog import Run
from pipeline.papers.src_joint.model import rotation
from pipeline.papers.src_joint.reachability import READINGS, read_quaternion

# "converges to zero" / "reached accurately" (Figs. 13a, 14a, 16), made a rule: final position error below
# 0.1 mm and final orientation error below 0.05°
REACHED_POSITION = 1e-4


REACHED_ANGLE = np.radians(0.05)


# "value consistency" (Fig. 8) and "coincidence" (Fig. 10), made a rule: the largest model-minus-measured
# difference below 1 % of the largest measured value
CONSISTENT = 0.01


SLUG = "src-joint"
EULER = ["X", "Y", "Z"]


SIX = ["wx", "wy", "wz", "vx", "vy", "vz"]


# eqs. (66), (67): the paper's IK solutions q^r_i for targets A and B, scalar first (read from targets.csv)
PRINTED_IK = {target: [[paper_value(SLUG, f"{equation}.q{i}.{c}") for c in "wxyz"] for i in (1, 2, 3)]
              for target, equation in (("A", "eq66"), ("B", "eq67"))}


def _columns(frame: pd.DataFrame, prefix: str, names) -> np.ndarray:
    return frame[[f"{prefix}.{k}" for k in names]].to_numpy()


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


def _bars(frame: pd.DataFrame) -> list[str]:
    return sorted({c.rsplit(".", 1)[1] for c in frame.columns})


# -- the floor under A and B (reach-floor) ----------------------------------------------------------------------

def floor_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """Per joint-update mode and reading of the target: the position floor with the orientation matched (the
    largest weight) and the orientation floor with the position first (the smallest); per mode the floor over
    every reading; the paper's IK per mode; how far the closed form ever is from the paper's model."""
    floor = run["/reach/floor"]
    values: dict[str, tuple[float, str]] = {}
    for (mode, reading), rows in floor.groupby(["mode", "reading"], sort=False):
        last, first = rows.loc[rows["weight_m_per_rad"].idxmax()], rows.loc[rows["weight_m_per_rad"].idxmin()]
        values[f"floor.position.{mode}.{reading}"] = (float(last["position_error_m"]), "m")
        values[f"floor.orientation.{mode}.{reading}"] = (float(first["orientation_error_rad"]), "rad")
        values[f"floor.position_at_orientation_floor.{mode}.{reading}"] = (float(first["position_error_m"]), "m")
    for mode, rows in floor.groupby("mode", sort=False):
        weight = rows["weight_m_per_rad"] == rows["weight_m_per_rad"].max()
        values[f"floor.position.{mode}.every_reading"] = (float(rows.loc[weight, "position_error_m"].min()), "m")
    values["floor.model_difference_max"] = (float(floor["model_difference_m"].max()), "m")
    ik = run["/reach/ik"].iloc[0]
    values |= {f"ik.{k.removeprefix('value.')}": (float(v), "m" if k.endswith("position_error") else
                                                  "rad" if k.endswith("orientation_error") else "1")
               for k, v in ik.items() if k.startswith("value.")}
    if run.metadata["case"] in PRINTED_IK:
        values["paper.solution_orientation_mismatch"] = (printed_solution_mismatch(run), "rad")
    return values


def printed_solution_mismatch(run: Run) -> float:
    """The paper's own arithmetic: the angle between the orientation its printed IK solutions (66)/(67) compose
    to by eq. (17) and Table II's target, the smallest over every reading tried (rad): the target as printed,
    scalar last or conjugated; the solutions scalar first or last, each possibly conjugated, in any order."""
    name = run.metadata["case"]
    target = np.asarray(run.config["scenario"]["targets"][name]["quaternion"], dtype=float)
    targets = [rotation(read_quaternion(target, reading)) for reading in READINGS]
    best = np.inf
    for solution_reading in ("printed", "scalar-last"):
        joints = [read_quaternion(q, solution_reading) for q in PRINTED_IK[name]]
        for conjugated in itertools.product((False, True), repeat=3):
            rotations = [rotation(q * np.array([1, -1, -1, -1]) if c else q) for q, c in zip(joints, conjugated,
                                                                                               strict=True)]
            for order in itertools.permutations(rotations):
                composed = order[0] @ order[1] @ order[2]
                best = min(best, *(float(Rotation.from_matrix(R @ composed.T).magnitude()) for R in targets))
    return best


def loop_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """The joint rolled round a closed loop: the largest |ε_z| of its rotation per model mode and the plant,
    and the twist the literal eq. (5) leaves against exact rolling at the end (rad)."""
    q = run["/eq5/joint_quaternion"]
    values = {f"eps_z.max_abs.{m}": (float(q[f"value.{m}.qz"].abs().max()), "1")
              for m in ("incremental", "global", "plant")}
    end = q.iloc[-1]
    for mode in ("incremental", "global"):
        model = Rotation.from_quat([end[f"value.{mode}.q{c}"] for c in "xyzw"])
        plant = Rotation.from_quat([end[f"value.plant.q{c}"] for c in "xyzw"])
        values[f"loop.angle_to_plant.{mode}"] = (float((plant.inv() * model).magnitude()), "rad")
    return values
