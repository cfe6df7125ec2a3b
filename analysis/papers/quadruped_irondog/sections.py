"""Report tables of `quadruped-irondog` beside its targets: the real robot's IMU next to the simulation, the
standing statics, the body poses, the levelling, the trot, the kinematics and the compute times."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.core.targets import paper_value
from pipeline.papers.quadruped_irondog.kinematics import JOINT_NAMES

SLUG = "quadruped-irondog"
DEG = 180 / np.pi


def _imu(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> Section:
    rows = []
    for quantity, target, experiment, run_id, metric in (
            ("trot: min roll", "imu.trot.roll_min", "trot", "cycle-0.5s", "trot.roll_min"),
            ("trot: max roll", "imu.trot.roll_max", "trot", "cycle-0.5s", "trot.roll_max"),
            ("trot: min pitch", "imu.trot.pitch_min", "trot", "cycle-0.5s", "trot.pitch_min"),
            ("trot: max pitch", "imu.trot.pitch_max", "trot", "cycle-0.5s", "trot.pitch_max"),
            ("standing: pitch", "imu.stand.pitch", "stand", "robot", "stand.pitch"),
            ("standing: roll", "imu.stand.roll", "stand", "robot", "stand.roll")):
        frame = metrics.get(experiment)
        simulated = metric_value(frame, run_id, metric) * DEG if frame is not None else float("nan")
        rows.append({"quantity": quantity, "target": target,
                     "paper: real robot [deg]": paper_value(SLUG, target, "deg"),
                     "MuJoCo stand-in [deg]": simulated, "MuJoCo run": f"{experiment}/{run_id}"})
    failed = runs[(runs["experiment"] == "trot") & ~runs["ok"]] if not runs.empty else runs
    note = "".join(f" Run `trot/{r.run_id}` {r.status}." for r in failed.itertuples())
    return Section("IMU: the real robot and a simulated stand-in",
                   "The paper's only motion numbers come from the real robot's MPU-6050 (Fig. 22, Sec. 4.3): not "
                   "reproducible in simulation (the targets above are `not-reproducible`). Beside them, the MuJoCo "
                   "robot over the steady trot and the settled stance — a stand-in, not a reproduction, and not "
                   "judged (no six-bar; assumed servo, gait timing and mass distribution)." + note,
                   Table(pd.DataFrame(rows), ".2f"), category="tracking errors")


def _stand(frame: pd.DataFrame) -> Section:
    rows = [{"joint": j, "MuJoCo servo torque [N·m]": metric_value(frame, "robot", f"stand.torque.{j}"),
             "hand statics [N·m]": metric_value(frame, "robot", f"stand.statics.{j}")} for j in JOINT_NAMES]
    fz = {k: metric_value(frame, "robot", f"stand.{k}") for k in ("fz_front", "fz_back", "fz_sum", "weight")}
    loads = (f"Vertical ground reaction: front feet {fz['fz_front']:.2f} N, rear feet {fz['fz_back']:.2f} N each; "
             f"Σ {fz['fz_sum']:.3f} N against m g = {fz['weight']:.3f} N. The feet stand 35 mm ahead of the hips in "
             "the Table 5 pose, so the rear legs carry more and sag more (the trunk pitches nose-up). The "
             "SPT5535LV's stall torque is 3.43 N·m.")
    return Section("Standing in the Table 5 pose (robot only)",
                   "Servo torques of the settled MuJoCo robot against the hand statics at the same pose "
                   "(pipeline/papers/quadruped_irondog/statics.py: lumped masses, leg Jacobians, least-norm foot "
                   "loads).", Table(pd.DataFrame(rows), ".4f"), loads, category="trajectories")


def _poses(frame: pd.DataFrame) -> Section:
    rows = []
    for k in range(2, 13):
        commanded = metric_value(frame, "fig18", f"pose.{k}.commanded")
        if np.isnan(commanded):
            continue
        scale, unit = (1e3, "mm") if k <= 6 else (DEG, "deg")
        rows.append({"scenario": k, "commanded": f"{commanded * scale:.1f} {unit}",
                     "achieved": f"{metric_value(frame, 'fig18', f'pose.{k}.achieved') * scale:.1f} {unit}",
                     "ratio": metric_value(frame, "fig18", f"pose.{k}.ratio"),
                     "cross-talk, translation [mm]":
                         metric_value(frame, "fig18", f"pose.{k}.crosstalk_translation") * 1e3,
                     "cross-talk, rotation [deg]": metric_value(frame, "fig18", f"pose.{k}.crosstalk_rotation") * DEG})
    slip = metric_value(frame, "fig18", "pose.foot_slip_max") * 1e3
    return Section("Body poses (Fig. 18)",
                   "Held trunk offset (mean over each hold, from the pose just before the scenario) against the "
                   "command; the feet stay where the stance put them (largest horizontal foot displacement "
                   f"{slip:.1f} mm).", Table(pd.DataFrame(rows), ".2f"), category="trajectories")


def _levelling(frame: pd.DataFrame) -> Section:
    rows = [{"run": run_id, "bench [deg]": metric_value(frame, run_id, "level.bench") * DEG,
             "residual tilt [deg]": metric_value(frame, run_id, "level.residual") * DEG,
             "peak tilt [deg]": metric_value(frame, run_id, "level.peak") * DEG,
             "settled after the bench stops [s] (nan: never)": metric_value(frame, run_id, "level.settling_time"),
             "coxa change [deg]": metric_value(frame, run_id, "level.coxa_change") * DEG,
             "femur/tibia change [deg]": metric_value(frame, run_id, "level.femur_tibia_change") * DEG,
             "peak |τ| [N·m]": metric_value(frame, run_id, "torque.peak")}
            for run_id in sorted(set(frame["run_id"]))]
    return Section("Self-levelling on a tilting bench (Figs. 19-20)",
                   "Residual tilt: mean |angle| over the last 1 s; settled: the last time the tilt left the ±1° band, "
                   "after the bench stopped.", Table(pd.DataFrame(rows), ".3g"), category="tracking errors")


TROT_ROWS = [  # (metric, label, factor)
    ("trot.speed", "forward speed [m/s]", 1.0), ("trot.speed_ratio", "speed / (stride / stance time)", 1.0),
    ("trot.lateral_drift", "lateral drift [mm]", 1e3), ("trot.heading_drift", "heading drift [deg]", DEG),
    ("trot.roll_rms", "roll RMS [deg]", DEG), ("trot.pitch_rms", "pitch RMS [deg]", DEG),
    ("joint_error.coxa.rms", "joint error RMS, coxa [deg]", DEG),
    ("joint_error.femur.rms", "joint error RMS, femur [deg]", DEG),
    ("joint_error.tibia.rms", "joint error RMS, tibia [deg]", DEG),
    ("joint_error.tibia.max", "joint error max, tibia [deg]", DEG),
    ("foot_error.swing.rms", "foot error RMS in swing [mm]", 1e3),
    ("foot_error.swing.max", "foot error max in swing [mm]", 1e3),
    ("foot_error.stance.rms", "foot error RMS in stance [mm]", 1e3),
    ("foot.lift_ratio", "foot lift achieved / commanded", 1.0), ("foot.stride", "foot stride [mm]", 1e3),
    ("torque.peak", "peak |τ| [N·m]", 1.0), ("torque.peak_ratio", "peak |τ| / stall torque", 1.0),
    ("torque.saturated_fraction", "share of samples × joints saturated", 1.0),
    ("contact.fz_sum_mean", "mean Σ f_z over whole cycles [N]", 1.0), ("contact.weight", "m g [N]", 1.0),
    ("contact.fz_peak", "peak foot f_z [N]", 1.0), ("contact.duty_factor", "feet in contact (share)", 1.0),
    ("contact.in_swing", "contact while commanded in swing (share)", 1.0),
]


def _trot(frame: pd.DataFrame, runs: pd.DataFrame) -> Section:
    run_ids = sorted(set(frame["run_id"]), key=_cycle)
    table = pd.DataFrame([{"": label, **{r: metric_value(frame, r, metric) * factor for r in run_ids}}
                          for metric, label, factor in TROT_ROWS])
    return Section("Trot on flat ground (Sec. 4.3, Figs. 21-22)",
                   "Over the steady window (after the stride ramp and one more cycle). Joint errors: servo command "
                   "minus joint angle; foot errors: the continuous Table 3 swing / straight stance minus the FK of the "
                   "measured joints, in the leg frames. Runs that fell have no column here:", _falls(runs),
                   Table(table, ".3g"), category="trajectories")


def _cycle(run_id: str) -> float:
    return float(run_id.removeprefix("cycle-").split("s")[0])


def _falls(runs: pd.DataFrame) -> Table:
    trot = runs[runs["experiment"] == "trot"].copy()
    trot["step cycle [s]"] = trot["run_id"].map(_cycle)
    trot["outcome"] = trot["status"].where(~trot["ok"], "walks the whole run")
    return Table(trot.sort_values("step cycle [s]")[["step cycle [s]", "outcome"]])


def _kinematics(frame: pd.DataFrame) -> Section:
    def value(metric: str, scale: float = 1.0) -> float:
        return metric_value(frame, "ik-bezier", metric) * scale

    rows = [("de Casteljau vs eqs. (41)-(44), max [mm]", f"{value('bezier.de_casteljau_difference', 1e3):.2g}", ""),
            ("apex d [mm]", f"{value('bezier.apex.d', 1e3):.2f}", "−153.09"),
            ("apex at s", f"{value('bezier.apex.s'):.3f}", "≈ 0.499"),
            ("a range [mm]", f"{value('bezier.a_min', 1e3):.2f} … {value('bezier.a_max', 1e3):.2f}",
             "−122.69 … 128.82"),
            ("arc length [mm]", f"{value('bezier.arc_length', 1e3):.1f}", "≈ 411.0"),
            ("FK(IK(p)), eq. (40) corrected, max [mm]", f"{value('ik.corrected.fk_ik_max', 1e3):.2g}", ""),
            ("IK(FK(q)) on the IK's branch, max [rad]", f"{value('ik.corrected.ik_fk_max'):.2g}", ""),
            ("FK(IK(p)), eq. (40) printed, max over the swing [mm]",
             f"{value('ik.printed.fk_ik_max_bezier', 1e3):.1f}", ""),
            ("FK(IK(p)), eq. (40) printed, max over all poses [mm]", f"{value('ik.printed.fk_ik_max', 1e3):.1f}",
             "up to 14.7 (its samples)"),
            ("poses out of the printed form's reach (NaN)",
             f"{value('ik.printed.unreachable'):.0f} of {value('ik.workspace_samples'):.0f}", ""),
            ("Table 5 standing: foot below the hip [mm]", f"{value('table5.standing.depth', 1e3):.1f}", "≈ 205")]
    table = pd.DataFrame(rows, columns=["quantity", "pipeline", "derived by hand from Tables 3, 5 (not printed)"])
    return Section("Kinematics (Secs. 3.1, 3.3)",
                   "The Bezier curve's shape against values derived by hand from Table 3's control points (the paper "
                   "prints only the control points), and the IK round trips.", Table(table), category="trajectories")


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    if "trot" in metrics or "stand" in metrics:
        sections.append(_imu(metrics, runs))
    for name, build in (("stand", _stand), ("body-poses", _poses), ("self-levelling", _levelling),
                        ("kinematics", _kinematics)):
        frame = metrics.get(name)
        if frame is not None and not frame.empty:
            sections.append(build(frame))
    trot = metrics.get("trot")
    if trot is not None and not trot.empty:
        sections.append(_trot(trot, runs))
    timing = [(label, metric, "not reported") for label, metric, experiment in (
        ("IK of one leg, eqs. (38)-(40)", "kinematics/time.ik_leg", "kinematics"),
        ("IK of four legs in one call, per leg", "kinematics/time.ik_4_legs", "kinematics"),
        ("Bezier point, eqs. (41)-(44)", "kinematics/time.bezier", "kinematics"),
        ("trot control step (gait + IK of 4 legs)", "trot/time.control_step", "trot")) if experiment in metrics]
    if timing:
        merged = pd.concat([metrics[e].assign(metric=e + "/" + metrics[e]["metric"], run_id="all")
                            for e in ("kinematics", "trot") if e in metrics])
        sections.append(compute_time_section("Compute time per call", merged, "all", timing,
                                             machine_of(runs, "kinematics"), unit="us"))
    return sections
