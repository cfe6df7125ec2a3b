"""`gripper-force-control`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import yaml

from analysis.core.errors import error_stats, force_error_stats
from analysis.core.targets import paper_value
from pipeline.core.experiment import CONF_DIR
from pipeline.core.runlog import Run

SAG_WINDOW = 0.1        # s after the rotation's set point stops: Fig. 8's sag window


SURFACE_WINDOW = 0.2    # s after the backward rotation: Fig. 9's error window


SETTLED = 0.01          # a rotation is done when the gripper stays within 1 % of the move from its target


STEADY_BELOW = paper_value("gripper-force-control", "F7.most")   # N, "in most of the cases it was below" (Fig. 7b)


SAG_CASES = ("ideal", "friction", "no-feedforward")


def grasp_forces(run: Run) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, measured, commanded) grasp force; (samples, grasps) arrays for a Monte-Carlo batch."""
    measured = run["/wrench"].filter(like="force_x")
    commanded = run["/wrench/commanded"].filter(like="force_x")
    return measured.index.to_numpy(), measured.to_numpy().squeeze(), commanded.to_numpy().squeeze()


def motion_window(run: Run) -> tuple[float, float]:
    """First and last instant the set value generator moves the gripper (ω_sr ≠ 0)."""
    ref = run["/reference"]
    moving = ref.index[np.abs(ref["velocity.gripper"].to_numpy()) > 0]
    return float(moving[0]), float(moving[-1])


def window_stats(run: Run, t0: float, t1: float, tracking: bool = True) -> dict[str, tuple[float, str]]:
    """Force-error statistics of the run between t0 and t1, and the rotation's tracking error there."""
    t, measured, commanded = grasp_forces(run)
    inside = (t >= t0) & (t <= t1)
    stats = force_error_stats(t[inside], measured[inside], commanded[inside])
    stats["force_error.max_relative"] = (stats["force_error.max"][0] / float(np.max(commanded[inside])),
                                         "fraction")
    if not tracking:
        return stats
    track = run["/tracking_error"]
    inside = (track.index >= t0) & (track.index <= t1)
    stats |= error_stats(track.index[inside], track["error.gripper"].to_numpy()[inside], "rotation_error", "rad")
    return stats


def simulated_speed(run: Run) -> dict[str, tuple[float, str]]:
    t = run["/wrench"].index
    return {"simulation.wall_per_simulated_s": (float(run.metadata["wall_time_s"]) / float(t[-1] - t[0]),
                                                "ratio")}


def _config(run: Run, *keys: str):
    node = run.config
    for key in keys:
        node = node[key]
    return node


def cycle_times(run: Run) -> dict[str, tuple[float, str]]:
    """Closing (command to F_f ≥ 0.9 F_set), rotation (start to settled within 1 % of the move), opening
    (command to the finger back at its open angle), and what they make."""
    t, measured, commanded = grasp_forces(run)
    f_set = float(commanded[0])
    closing = float(t[np.argmax(measured >= 0.9 * f_set)]) if (measured >= 0.9 * f_set).any() else np.nan
    start, end = motion_window(run)
    open_at = float(_config(run, "scenario", "open_at"))
    joints = run["/joint_state"]
    phi_g, tj = joints["position.gripper"].to_numpy(), joints.index.to_numpy()
    angle = float(_config(run, "scenario", "angle"))
    turning = (tj >= start) & (tj < open_at)
    off = np.abs(phi_g[turning] - angle) > SETTLED * angle
    if not off.any():
        settled_at = start
    else:   # the sample after the last one off target; never, if the turn ends off target
        settled_at = np.nan if off[-1] else tj[turning][np.flatnonzero(off)[-1] + 1]
    l_f = float(_config(run, "system", "geometry", "l_f"))
    open_angle = -float(_config(run, "scenario", "stroke")) / l_f
    phi_f = joints["position.finger"].to_numpy()
    opened = (tj >= open_at) & (phi_f <= open_angle)
    opening = float(tj[np.argmax(opened)] - open_at) if opened.any() else np.nan
    rotation = float(settled_at - start)
    cycle = closing + rotation + opening
    hold = (t >= closing + 0.05) & (t < start)
    return {
        "closing_time": (closing, "s"), "rotation_time": (rotation, "s"), "opening_time": (opening, "s"),
        "rotation_profile_time": (end - start, "s"), "cycle_time": (cycle, "s"), "rate": (60.0 / cycle, "1/min"),
        "finger_speed.max": (float(np.abs(joints["velocity.finger"]).max() * l_f), "m/s"),
        "impact_force.max": (float(measured[t < start].max()), "N"),
        "grasp_error.before_rotation": (float(np.mean(measured[hold]) - f_set) if hold.any() else np.nan, "N"),
    }


def slug(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")


SLUG = "gripper-force-control"
OURS = "Proposed gripper v.1"


def datasheets() -> dict[str, pd.DataFrame]:
    """Tables 3-5 and the tomato text's inputs as the paper prints them (the `tables` experiment's config):
    table name -> frame indexed by gripper. The simulated values are compared with these."""
    tables = yaml.safe_load((CONF_DIR / "experiment" / "gripper-force-control" / "tables.yaml").read_text())
    return {name: pd.DataFrame(t["rows"], index=t["columns"]).T for name, t in tables["scenario"]["tables"].items()}


def competitor_ratios(finger_speed: float, closing_time: float) -> dict[str, tuple[float, str]]:
    """The simulated finger speed over each competitor's datasheet speed (Table 3), and the ONROBOT
    grippers' low-force gripping times over the simulated closing time (Sect. 5 on Table 5)."""
    sheets = datasheets()
    speed = sheets["table3"]["finger_speed"].drop(OURS)
    ratios = finger_speed / speed
    values = {f"table3.{slug(g)}.ratio": (r, "ratio") for g, r in ratios.items()}
    electric = ratios.drop([g for g in ratios.index if "pneumatic" in g])
    values |= {"table3.ratio_min": (electric.min(), "ratio"), "table3.ratio_max": (electric.max(), "ratio")}
    table5 = sheets["table5"].drop(OURS)
    # the ONROBOT grippers whose gripping time depends on the force (RG2, RG6): their low-force times
    force_dependent = table5[table5.index.str.startswith("ONROBOT") & (table5["time_max"] > table5["time_min"])]
    slow = force_dependent["time_max"] / closing_time
    values |= {"table5.onrobot_slowdown_max": (slow.max(), "ratio"),
               "table5.onrobot_slowdown_min": (slow.min(), "ratio")}
    return values


def error_ratios(force_error: float) -> dict[str, tuple[float, str]]:
    """Each competitor's datasheet force error over the simulated maximum force error (Table 4)."""
    error = datasheets()["table4"]["max_force_error"].drop(OURS)
    ratios = error / force_error
    return ({f"table4.{slug(g)}.ratio": (r, "ratio") for g, r in ratios.items()}
            | {"table4.ratio_min": (ratios.min(), "ratio"), "table4.ratio_max": (ratios.max(), "ratio")})


def tomato_force_limit(force_error: float) -> tuple[float, str]:
    """Sect. 5's argument with a given force error: the tomato's damage force over the safety factor, minus
    the error; F_set = 8.2 N is safe if it is at most this."""
    text = datasheets()["text"]["value"]
    return text["damage_force_min"] / text["safety_factor"] - force_error, "N"
