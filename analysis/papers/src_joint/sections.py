"""`src-joint`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.papers.src_joint.metrics import EULER


def _joint_section(frame: pd.DataFrame) -> Section:
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
    return Section(
        "Joint model against the plants (Figs. 8-10)", "The paper's model is fed the Ω^B each plant "
            "realised; 'printed-radius' runs eqs. (1), (5), (13)-(16) as printed, 'printed-sign' Table I's sign of "
            "Φ_v. "
            "Mean |error| per XYZ Euler angle over 0-30 s (paper: [4.92, 0.01, 9.83]·10⁻⁴, unit not stated).",
        Table(pd.DataFrame(rows), ".3g"),
        f"MuJoCo contact (SI): {details}. What remains of the model–physics difference comes from the soft "
            "contact (penetration): it falls with the square of the contact time constant `physics.solref[0]` "
            "(tests/test_src_joint_control.py), which MuJoCo bounds below by 2 `physics.dt`.",
        category="tracking errors")


def _reach_section(frame: pd.DataFrame) -> Section:
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
    return Section(
        "Reaching poses (Figs. 13-14) and the hardware stand-in", "IK from the Table II start, then the "
            "trolleys. Plants: `nominal` steers by the measured contact point ((53)-(55) online, FreeBOT-SIM); the "
            "others by wheel encoders only, with the EVA foam compressed by 1 mm and/or 2 % of the forward travel "
            "lost — the labelled stand-in for the paper's hardware errors (A: [4.17, −0.21, −4.19] mm, "
            "[1.07, −0.8, 1.45]°; B: [−3.51, 3.9, 1.47] mm, [0.13, 1.86, 0.52]°). 'Δ vs nominal' compares the "
            "final pose with FreeBOT-SIM's (the defects' own effect). A and B are not reachable with exact rolling "
            "kinematics: the IK stops at the residual shown.",
        Table(pd.DataFrame(rows), ".3g"), category="tracking errors")


def _obstacle_section(frame: pd.DataFrame) -> Section:
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
    return Section(
        "Target C between the bars (Figs. 16-17)", "Bars parallel to x through the Table II points, radius "
            "5 mm (assumed); dampers act below 40 mm with gain 0.5 s⁻¹ and keep 10 mm (the paper's safety distance). "
            "`unconstrained` is the same loop without the dampers.",
        Table(pd.DataFrame(rows), ".4g"), category="trajectories")


def _floor_section(frame: pd.DataFrame) -> Section:
    """The floor under A and B: per mode and reading, and the paper's IK per mode."""
    modes = {"incremental": "exact rolling (eq. 5 per step)", "global": "eq. 5 literal (twist allowed)"}
    rows = []
    for target in ("A", "B"):
        for mode, label in modes.items():
            for reading in ("printed", "scalar-last", "conjugate"):
                position = metric_value(frame, target, f"floor.position.{mode}.{reading}")
                if np.isnan(position):
                    continue
                rows.append({"target": target, "kinematics": label, "Table II quaternion read": reading,
                             "closest position [mm], orientation matched": 1e3 * position,
                             "closest orientation [deg], position first": np.degrees(
                                 metric_value(frame, target, f"floor.orientation.{mode}.{reading}")),
                             "at position error [mm]": 1e3 * metric_value(
                                 frame, target, f"floor.position_at_orientation_floor.{mode}.{reading}")})
    ik = [{"target": target, "kinematics": label,
           "paper's IK: position error [mm]": 1e3 * metric_value(frame, target, f"ik.{mode}.position_error"),
           "orientation error [deg]": np.degrees(metric_value(frame, target, f"ik.{mode}.orientation_error")),
           "max |ε_z| of its q^r_i": metric_value(frame, target, f"ik.{mode}.eps_z_max")}
          for target in ("A", "B") for mode, label in modes.items()]
    loop = {m: metric_value(frame, "eq5-loop", f"eps_z.max_abs.{m}") for m in ("incremental", "global", "plant")}
    check = max(metric_value(frame, t, "floor.model_difference_max") for t in ("A", "B"))
    return Section(
        "How close the 3-joint chain can come to targets A and B (every convention)",
        "For each joint-update mode and each reading of Table II's quaternion [η, ε], the closest pose over every "
        "configuration the mode allows (32 random starts, Levenberg-Marquardt continued from position first to "
        "orientation first). With equal spheres the radius conventions coincide and the free-mode sign enters "
        "only velocities: the closed form used for the search equals the paper's model in all four forms to "
        f"{check:.1g} m. A 0 means reachable.",
        Table(pd.DataFrame(rows), ".3g"),
        "The paper's own IK (Sec. III-B) in each mode, from the identity (what reach-poses runs with exact rolling):",
        Table(pd.DataFrame(ik), ".3g"),
        f"One joint rolled round a closed square of Ω^B: max |ε_z| of q_i is {loop['plant']:.1g} for the exact "
        f"rolling plant, {loop['incremental']:.1g} for the model with eq. (5) per step, and {loop['global']:.3f} "
        "with eq. (5) read literally. Exact rolling of equal spheres never gives ε_z ≠ 0 (they are mirror "
        "images); the literal update does, as the paper's own solutions (66)-(67) have.",
        category="tracking errors")


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    if metrics.get("joint-model") is not None and not metrics["joint-model"].empty:
        sections.append(_joint_section(metrics["joint-model"]))
    if metrics.get("reach-poses") is not None and not metrics["reach-poses"].empty:
        sections.append(_reach_section(metrics["reach-poses"]))
    if metrics.get("reach-floor") is not None and not metrics["reach-floor"].empty:
        sections.append(_floor_section(metrics["reach-floor"]))
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
