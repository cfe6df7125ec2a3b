"""The analyze stage of `quadruped-irondog`, one analysis per experiment (runs -> tidy metrics, figures on the
side)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.quadruped_irondog import figures
from analysis.papers.quadruped_irondog.metrics import (
    FEET,
    GRAVITY,
    body,
    columns,
    feet,
    feet_world,
    joints,
    robot_mass,
    torque_metrics,
    trot_timing,
)
from pipeline.core.runlog import Run
from pipeline.papers.quadruped_irondog.kinematics import JOINT_NAMES, JOINTS, LEGS

# -- tables -------------------------------------------------------------------------------------------------------


def analyze_tables(runs: list[Run], figs: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        rows = run["/tables"]
        text = run["/text"].iloc[0].rename(lambda c: c.removeprefix("value."))
        t2 = rows[rows["table"] == "table2"].set_index("row")
        t6 = rows[rows["table"] == "table6"].set_index("row")
        fea = rows[rows["table"] == "fea"].set_index("row")
        g = text["gravity_m_s2"]
        line_product = t6["value.unit_usd"] * t6["value.quantity"]
        E, nu = text["elastic_modulus_mpa"] * 1e6, text["poisson_ratio"]
        values = {
            "table2.sum": (t2["value.total_g"].sum() * 1e-3, "kg"),
            "table2.lines_consistent": (float((t2["value.single_g"] * t2["value.uses"] - t2["value.total_g"])
                                              .abs().lt(1e-9).all()), "bool"),
            "table2.total": (text["table2_total_g"] * 1e-3, "kg"),
            "table2.screws": (t2.loc["Screws", "value.uses"], "count"),
            "table6.screws": (t6.loc["M3 Screws", "value.quantity"], "count"),
            "text.robot_mass": (text["robot_mass_kg"], "kg"),
            "payload.total_mass": (text["robot_mass_kg"] + text["payload_kg"], "kg"),
            "payload.weight": ((text["robot_mass_kg"] + text["payload_kg"]) * g, "N"),
            "payload.weight_table2": ((t2["value.total_g"].sum() * 1e-3 + text["payload_kg"]) * g, "N"),
            "table6.sum_of_totals": (t6["value.total_usd"].sum(), "USD"),
            "table6.sum_of_products": (line_product.sum(), "USD"),
            "table6.total": (text["table6_total_usd"], "USD"),
            "table6.battery_product": (line_product["7.4 V 2200 mAh Battery"], "USD"),
            "table6.screws_product": (line_product["M3 Screws"], "USD"),
            "table4.shear_modulus_isotropic": (E / (2 * (1 + nu)), "Pa"),
            "servo.stall_torque": (text["servo_kg_cm"] * 1e-2 * g, "N*m"),
        }
        for part in fea.index:  # FoS = UTS / σ (Sec. 4.1, brittle): the largest stress and the strain it implies
            stress = text["tensile_strength_mpa"] * 1e6 / fea.loc[part, "value.fos_min"]
            values[f"fea.{part}.stress_max"] = (stress, "Pa")
            values[f"fea.{part}.strain_from_fos"] = (stress / E, "")
            values[f"fea.{part}.strain_max"] = (fea.loc[part, "value.strain_max"], "")
        m.add_run(run, values)
    return m.frame()


# -- kinematics ---------------------------------------------------------------------------------------------------


def analyze_kinematics(runs: list[Run], figs: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        curve = run["/reference/bezier"]
        a, d = curve["position.a"].to_numpy(), curve["position.d"].to_numpy()
        casteljau = columns(run["/bezier/de_casteljau"], "value", ["a_m", "d_m"])
        apex = int(np.argmax(d))
        s = (curve.index.to_numpy() - curve.index[0]) / (curve.index[-1] - curve.index[0])
        workspace = run["/ik/workspace"]
        corrected = run["/ik/bezier/corrected"]["value.fk_ik_error_m"]
        printed = run["/ik/bezier/printed"]["value.fk_ik_error_m"]
        standing, ideal = (columns(run[f"/table5/{state}"], "position", FEET).reshape(4, 3)
                           for state in ("standing", "ideal"))
        values = {
            "bezier.start.a": (a[0], "m"), "bezier.start.d": (d[0], "m"),
            "bezier.end.a": (a[-1], "m"), "bezier.end.d": (d[-1], "m"),
            "bezier.de_casteljau_difference": (np.abs(np.column_stack([a, d]) - casteljau).max(), "m"),
            "bezier.apex.d": (d[apex], "m"), "bezier.apex.s": (s[apex], ""),
            "bezier.a_min": (a.min(), "m"), "bezier.a_max": (a.max(), "m"),
            "bezier.arc_length": (np.hypot(np.diff(a), np.diff(d)).sum(), "m"),
            "ik.corrected.fk_ik_max": (max(workspace["value.fk_ik_error_m"].max(), corrected.max()), "m"),
            "ik.corrected.ik_fk_max": (workspace["value.ik_fk_error_rad"].max(), "rad"),
            "ik.printed.fk_ik_max": (max(workspace["value.printed_fk_ik_error_m"].max(), printed.max()), "m"),
            "ik.printed.fk_ik_max_bezier": (printed.max(), "m"),
            "ik.printed.unreachable": (float(workspace["value.printed_fk_ik_error_m"].isna().sum()), "count"),
            "ik.workspace_samples": (float(len(workspace)), "count"),
            "table5.standing.depth": (-standing[:, 2].mean(), "m"),
            "table5.standing.forward": (standing[:, 0].mean() - np.array([0.15, 0.15, -0.15, -0.15]).mean(), "m"),
            "table5.ideal.depth": (-ideal[:, 2].mean(), "m"),
        }
        times = run["/compute_time"]
        for name in ("ik_leg", "ik_4_legs", "bezier"):
            seconds = times[f"seconds.{name}"].dropna().to_numpy() / times[f"calls.{name}"].dropna().to_numpy()
            values |= timing_metrics(f"time.{name}", seconds)
        m.add_run(run, values)
        figures.bezier_swing(run, figs)
        figures.ik_round_trip(run, figs)
    return m.frame()


# -- stand --------------------------------------------------------------------------------------------------------


def analyze_stand(runs: list[Run], figs: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        sc = run.config["scenario"]
        t = run["/body"].index.to_numpy()
        window = t >= t[-1] - sc["window"]
        q = joints(run)[window].mean(axis=0).reshape(4, 3)
        sign = np.asarray(run.config["system"]["table5"]["femur_sign"])
        paper = np.degrees(np.column_stack([q[:, 0], q[:, 1] * sign, q[:, 2]]))   # Table 5's convention, deg
        b = body(run)[window]
        wrench = run["/wrench"]
        fz = columns(wrench, "force_z", LEGS)[window].mean(axis=0)
        payload = float(run.metadata["case"].removeprefix("payload-").removesuffix("kg")) \
            if run.metadata["case"].startswith("payload") else 0.0
        statics = run["/statics/torque"].iloc[-1]
        settled = columns(statics.to_frame().T, "settled", JOINT_NAMES)[0]
        commanded = columns(statics.to_frame().T, "commanded", JOINT_NAMES)[0]
        tau = joints(run, field="effort")[window].mean(axis=0)
        values = {
            "stand.roll": (b["roll"].mean(), "rad"), "stand.pitch": (b["pitch"].mean(), "rad"),
            "stand.height": (b["z"].mean(), "m"),
            "stand.femur_right": (np.radians(paper[[0, 2], 1].mean()), "rad"),
            "stand.femur_left": (np.radians(paper[[1, 3], 1].mean()), "rad"),
            "stand.tibia": (np.radians(paper[:, 2].mean()), "rad"),
            "stand.coxa": (np.radians(paper[:, 0].mean()), "rad"),
            "stand.joint_error_max": (np.abs((joints(run, "/command", "value") - joints(run))[window]
                                             .mean(axis=0)).max(), "rad"),
            "stand.fz_sum": (fz.sum(), "N"), "stand.weight": ((robot_mass(run) + payload) * GRAVITY, "N"),
            "stand.fz_front": (fz[:2].mean(), "N"), "stand.fz_back": (fz[2:].mean(), "N"),
            "stand.statics_error_max": (np.abs(tau - settled).max(), "N*m"),
            "stand.statics_commanded_error_max": (np.abs(tau - commanded).max(), "N*m"),
            "stand.upright": (1.0, "bool"),
        }
        values |= torque_metrics(run, window)
        for name, value in zip(JOINT_NAMES, tau, strict=True):
            values[f"stand.torque.{name}"] = (value, "N*m")
            values[f"stand.statics.{name}"] = (settled[JOINT_NAMES.index(name)], "N*m")
        m.add_run(run, values)
    figures.table5_poses(runs, figs)
    return m.frame()


# -- body poses (Fig. 18) -----------------------------------------------------------------------------------------

POSE = ("x", "y", "z", "roll", "pitch", "yaw")


def analyze_body_poses(runs: list[Run], figs: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        reach = run.config["scenario"]["reach"]
        b = body(run)
        pose = b[list(POSE)].to_numpy()
        command = columns(run["/reference/body"], "position", POSE)
        holding = run["/scenario"]["value.holding"].to_numpy().astype(int) - 1
        values: dict[str, tuple[float, str]] = {}
        reached = []
        ramp = run.config["scenario"]["ramp"]
        t = b.index.to_numpy()
        for k in range(holding.max() + 1):
            held = holding == k
            ramp_start = t[held][0] - ramp
            before = (t > ramp_start - 0.1) & (t <= ramp_start)      # the 0.1 s before the scenario begins
            achieved = pose[held].mean(axis=0) - pose[before].mean(axis=0)
            target = command[held].mean(axis=0)
            axis = int(np.argmax(np.abs(target)))
            others = np.abs(achieved - target)
            others[axis] = 0.0
            values[f"pose.{k + 2}.ratio"] = (achieved[axis] / target[axis], "ratio")
            values[f"pose.{k + 2}.achieved"] = (achieved[axis], "m" if axis < 3 else "rad")
            values[f"pose.{k + 2}.commanded"] = (target[axis], "m" if axis < 3 else "rad")
            values[f"pose.{k + 2}.crosstalk_translation"] = (others[:3].max(), "m")
            values[f"pose.{k + 2}.crosstalk_rotation"] = (others[3:].max(), "rad")
            reached.append(achieved[axis] / target[axis] >= reach)
        in_world = feet_world(run)
        slip = np.linalg.norm(in_world[:, :, :2] - in_world[:1, :, :2], axis=-1).max()
        values["pose.scenarios"] = (float(len(reached)), "count")
        values["pose.all_reached"] = (float(all(reached)), "bool")
        values["pose.foot_slip_max"] = (slip, "m")
        values |= torque_metrics(run, np.ones(len(b), bool))
        m.add_run(run, values)
        figures.body_poses(run, figs)
    return m.frame()


# -- self-levelling (Figs. 19-20) ---------------------------------------------------------------------------------


def analyze_self_levelling(runs: list[Run], figs: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        sc = run.config["scenario"]
        axis = run.metadata["case"].split("-")[0]
        b = body(run)
        t = b.index.to_numpy()
        tilt = b[axis].to_numpy()
        band = np.radians(sc["level_band_deg"])
        bench_done = sc["tilt_start"] + sc["tilt_ramp"]
        last = t >= t[-1] - 1.0
        outside = np.flatnonzero((np.abs(tilt) > band) & (t >= sc["tilt_start"]))
        if not len(outside):
            settling = 0.0
        elif outside[-1] == len(t) - 1:       # still tilted at the end: never settled
            settling = float("nan")
        else:
            settling = max(0.0, t[outside[-1]] - bench_done)
        q = joints(run)
        dq = np.abs(q[last].mean(axis=0) - q[t < sc["tilt_start"]].mean(axis=0)).reshape(4, 3)
        values = {
            "level.residual": (np.abs(tilt[last]).mean(), "rad"),
            "level.peak": (np.abs(tilt).max(), "rad"),
            "level.settling_time": (settling, "s"),
            "level.bench": (np.abs(run["/platform"][axis].iloc[-1]), "rad"),
            "level.other_axis_residual": (np.abs(b["pitch" if axis == "roll" else "roll"].to_numpy()[last]).mean(),
                                          "rad"),
            "level.coxa_change": (dq[:, 0].max(), "rad"),
            "level.femur_tibia_change": (dq[:, 1:].max(), "rad"),
            "claim.lies_flat": (float(np.abs(tilt[last]).mean() < band), "bool"),
        }
        if axis == "pitch":   # Fig. 19e: femur and tibia counteract the pitch, the coxa stays
            values["claim.femur_tibia_not_coxa"] = (float(dq[:, 1:].max() > np.radians(2)
                                                          and dq[:, 0].max() < np.radians(0.5)), "bool")
        else:                 # Fig. 20e: the coxa angles counteract the roll
            values["claim.coxa_counteracts"] = (float(dq[:, 0].max() > np.radians(2)), "bool")
        values |= torque_metrics(run, np.ones(len(t), bool))
        m.add_run(run, values)
    figures.self_levelling(runs, figs)
    return m.frame()


# -- trot (Sec. 4.3, Figs. 21-22) ---------------------------------------------------------------------------------


def analyze_trot(runs: list[Run], figs: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        timing = trot_timing(run)
        b = body(run)
        t = b.index.to_numpy()
        steady = t >= timing["steady_start"]
        values: dict[str, tuple[float, str]] = {}
        ts = t[steady]
        speed = np.polyfit(ts, b["x"].to_numpy()[steady], 1)[0]
        control_points = np.asarray(run.config["system"]["gait"]["control_points_mm"]) * 1e-3
        stride = abs(control_points[0, 0] - control_points[-1, 0]) * run.config["system"]["gait"]["stride_scale"]
        stance_time = timing["cycle_time"] - timing["swing_time"]
        values["trot.speed"] = (speed, "m/s")
        values["trot.speed_ratio"] = (speed / (stride / stance_time), "ratio")
        values["trot.lateral_drift"] = (abs(b["y"].iloc[-1] - b["y"].to_numpy()[steady][0]), "m")
        values["trot.heading_drift"] = (abs(b["yaw"].iloc[-1] - b["yaw"].to_numpy()[steady][0]), "rad")
        values["trot.cycles_steady"] = ((ts[-1] - ts[0]) / timing["cycle_time"], "count")
        values["claim.walks"] = (float(values["trot.speed_ratio"][0] >= 0.5), "bool")
        for angle in ("roll", "pitch"):
            x = b[angle].to_numpy()[steady]
            values[f"trot.{angle}_min"] = (x.min(), "rad")
            values[f"trot.{angle}_max"] = (x.max(), "rad")
            values[f"trot.{angle}_rms"] = (np.sqrt(np.mean((x - x.mean()) ** 2)), "rad")
        values["trot.height_mean"] = (b["z"].to_numpy()[steady].mean(), "m")
        # joints: the servo command (held between control instants) minus the measurement (/tracking_error's sign)
        error = (joints(run, "/command", "value") - joints(run))[steady]
        values |= error_stats(ts, np.linalg.norm(error, axis=1), "joint_error.norm", "rad")
        for j, joint in enumerate(JOINTS):
            e = error[:, j::3]
            values[f"joint_error.{joint}.rms"] = (np.sqrt(np.mean(e ** 2)), "rad")
            values[f"joint_error.{joint}.max"] = (np.abs(e).max(), "rad")
        # feet, in the leg frames, against the continuous Bezier/stance reference; during swing and stance
        feet_error = np.linalg.norm(feet(run, "/tracking_error/feet", "error")[steady], axis=-1)
        swing = columns(run["/gait"], "value", [f"swing.{leg}" for leg in LEGS])[steady] > 0.5
        for phase, mask in (("swing", swing), ("stance", ~swing)):
            values[f"foot_error.{phase}.rms"] = (np.sqrt(np.mean(feet_error[mask] ** 2)), "m")
            values[f"foot_error.{phase}.max"] = (feet_error[mask].max(), "m")
        measured, ref = feet(run)[steady], feet(run, "/reference/feet", "position")[steady]
        lift = measured[..., 1].max(axis=0) - measured[..., 1].min(axis=0)
        lift_ref = ref[..., 1].max(axis=0) - ref[..., 1].min(axis=0)
        values["foot.lift"] = (lift.mean(), "m")
        values["foot.lift_ratio"] = (lift.mean() / lift_ref.mean(), "ratio")
        values["foot.stride"] = ((measured[..., 2].max(axis=0) - measured[..., 2].min(axis=0)).mean(), "m")
        values |= torque_metrics(run, steady)
        # contact forces: over whole cycles the mean vertical ground reaction carries the weight
        fz = columns(run["/wrench"], "force_z", LEGS)[steady]
        cycles = int((ts[-1] - ts[0]) // timing["cycle_time"])
        whole = ts < ts[0] + cycles * timing["cycle_time"]
        values["contact.fz_sum_mean"] = (fz[whole].sum(axis=1).mean(), "N")
        values["contact.weight"] = (robot_mass(run) * GRAVITY, "N")
        values["contact.fz_peak"] = (fz.max(), "N")
        contact = columns(run["/contact"], "value", LEGS)[steady] > 0.5
        values["contact.duty_factor"] = (contact.mean(), "fraction")
        values["contact.in_swing"] = (float(contact[swing].mean()) if swing.any() else float("nan"), "fraction")
        step = run["/compute_time"]["seconds.control_step"].to_numpy()
        values |= timing_metrics("time.control_step", step)
        m.add_run(run, values)
        if np.isclose(timing["cycle_time"], run.config["system"]["gait"]["cycle_time"]):
            figures.trot(run, figs)
    return m.frame()


ANALYSES = {"tables": analyze_tables, "kinematics": analyze_kinematics, "stand": analyze_stand,
            "body-poses": analyze_body_poses, "self-levelling": analyze_self_levelling, "trot": analyze_trot}
