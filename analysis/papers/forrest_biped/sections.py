"""Extra sections of the report page: tracking errors, the Eq. (59) shares of every model, the robustness band,
contact forces, and the controller's compute time."""

from __future__ import annotations

import math

import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.core.targets import paper_value

SLUG = "forrest-biped"


def _paper(axis: str) -> float:
    """The paper's Eq. (59) share of an axis, in % (targets.csv)."""
    return paper_value(SLUG, f"share.{axis}", "%")


def _mm(frame: pd.DataFrame, run: str, metric: str) -> float:
    return metric_value(frame, run, metric) * 1e3


def tracking_section(w: pd.DataFrame) -> Section:
    rows = []
    for g in ("extended", "traditional"):
        for axis in ("x", "y", "z"):
            rows.append({"generator": g, "axis": axis,
                         "CoM RMS 1-3 s [mm]": _mm(w, g, f"com_error.{axis}.window.rms"),
                         "CoM max 1-3 s [mm]": _mm(w, g, f"com_error.{axis}.window.max"),
                         "CoM RMS 0-4 s [mm]": _mm(w, g, f"com_error.{axis}.all.rms"),
                         "CoM max 0-4 s [mm]": _mm(w, g, f"com_error.{axis}.all.max"),
                         "CP RMS 1-3 s [mm]": _mm(w, g, f"cp_error.{axis}.window.rms"),
                         "CP max 1-3 s [mm]": _mm(w, g, f"cp_error.{axis}.window.max")})
    forces = [{"generator": g,
               "ZMP p^c − CoP RMS x / y [mm]":
                   f"{_mm(w, g, 'zmp_error.x.rms'):.2f} / {_mm(w, g, 'zmp_error.y.rms'):.2f}",
               "foot force QP − measured RMS l / r [N]":
                   f"{metric_value(w, g, 'force_error.left_foot.rms'):.1f} / "
                   f"{metric_value(w, g, 'force_error.right_foot.rms'):.1f}",
               "wrench residual ‖F_d − F_opt‖ RMS [N, N m]":
                   f"{metric_value(w, g, 'wrench_residual.force.rms'):.2f}, "
                   f"{metric_value(w, g, 'wrench_residual.moment.rms'):.2f}",
               "Σ f_z, first 0.2 s [N]": metric_value(w, g, "standing.normal_force"),
               "QP not optimal [cycles]": metric_value(w, g, "qp.not_optimal")} for g in ("extended", "traditional")]
    return Section("Walking: tracking errors and contact forces (our figures; the paper gives none)",
                   "Error = reference − measured on the 1 ms controller grid. The paper only says the biped \"tracked "
                   "the trajectory accurately\".", Table(pd.DataFrame(rows), ".3f"), Table(pd.DataFrame(forces), ".1f"),
                   "The Table 4 robot weighs 32.51 kg × 9.81 m/s² = 318.9 N. The QP's friction cone and CoP "
                   "constraints hold by construction; the measured CoP is the force-weighted mean of the corner "
                   "contacts.", category="tracking errors")


def shares_section(w: pd.DataFrame) -> Section:
    models = [("MuJoCo whole body (stance foot held: the default)", ""),
              ("MuJoCo whole body, stance foot zero acceleration", "stance-zero."),
              ("LIP point mass, ideal ZMP", "lipm."), ("LIP point mass, 10 ms ZMP lag", "lipm-lag10ms.")]
    rows = []
    for label, prefix in models:
        if pd.isna(metric_value(w, "all", f"{prefix}share.x.window")):
            continue
        rows.append({"model": label,
                     **{f"share {a}, 1-3 s [%]": metric_value(w, "all", f"{prefix}share.{a}.window") * 100
                        for a in ("x", "y")},
                     **{f"share {a}, 0-4 s [%]": metric_value(w, "all", f"{prefix}share.{a}.all") * 100
                        for a in ("x", "y")},
                     "RMS difference x / y": f"{metric_value(w, 'all', f'{prefix}rms_difference.x'):.2f} / "
                                             f"{metric_value(w, 'all', f'{prefix}rms_difference.y'):.2f}"})
    rows.append({"model": "paper (Simscape, Sec. 6.3)", "share x, 1-3 s [%]": _paper("x"),
                 "share y, 1-3 s [%]": _paper("y")})
    return Section("Eq. (59): how often the extended generator's CoM error is smaller",
                   "f(t) = |x̃_trad(t)| − |x̃_ext(t)|; the share is the fraction of 1 ms samples with f > 0. The paper "
                   "does not say over which interval; we use the two steps (1-3 s) and also give the whole walk. On "
                   "the ideal LIP the traditional generator is tracked exactly (its ZMP is constant over every control "
                   "cycle) and the extended one only to the zero-order hold of its ramps, so any share there measures "
                   "the hold, not the generator.", Table(pd.DataFrame(rows), ".1f"), category="tracking errors")


def stance_foot_section(w: pd.DataFrame) -> Section | None:
    """The shares and the foot slip under both settings of system.controller.stance_foot."""
    if pd.isna(metric_value(w, "all", "stance-zero.share.x.window")):
        return None
    rows = []
    for setting, pair, walk in (("hold (the default, chosen after the shares were seen)", "", ""),
                                ("zero (the setting the shares were first seen with)", "stance-zero.", "stance-zero-")):
        slip = max(metric_value(w, walk + g, metric) for g in ("extended", "traditional")
                   for metric in ("stance_slip.max", "final_slip.max"))
        rows.append({"system.controller.stance_foot": setting,
                     **{f"share {a}, 1-3 s [%]": metric_value(w, "all", f"{pair}share.{a}.window") * 100
                        for a in ("x", "y")},
                     "largest stance-foot slip, both walks [mm]": slip * 1e3})
    rows.append({"system.controller.stance_foot": "paper (Simscape; not said)", "share x, 1-3 s [%]": _paper("x"),
                 "share y, 1-3 s [%]": _paper("y")})
    return Section("The stance-foot setting and the Eq. (59) shares",
                   "The default `system.controller.stance_foot` was changed from `zero` (a stance foot commanded zero "
                   "acceleration, no position feedback) to `hold` (eq. (52)'s foot PD on a stance foot too, holding "
                   "it where it was planted) **after the Eq. (59) shares under `zero` had been seen**. The reason "
                   "given is physical: under `zero` the stance feet slip. The paper does not say how its stance foot "
                   "is controlled. Both settings are run (cases `stance-zero-*` of `walking`), so that the reader can "
                   "judge how much the shares owe to this choice; the targets are judged on the default.",
                   Table(pd.DataFrame(rows), ".1f"), category="tracking errors")


def robustness_section(r: pd.DataFrame, w: pd.DataFrame | None) -> Section:
    jobs = r[r["run_id"] != "band"]
    rows = []
    for job in jobs["run_id"].unique():
        rows.append({"sweep job (overrides)": job,
                     "share x [%]": metric_value(r, job, "share.x.window") * 100,
                     "share y [%]": metric_value(r, job, "share.y.window") * 100,
                     "max ‖CoM error‖ xy [mm]": metric_value(r, job, "com_error.max_xy") * 1e3,
                     "RMS difference x / y": f"{metric_value(r, job, 'rms_difference.x'):.2f} / "
                                             f"{metric_value(r, job, 'rms_difference.y'):.2f}",
                     "'not very significant'": bool(metric_value(r, job, "claim.not_significant"))})
    band = {a: (metric_value(r, "band", f"share.{a}.min") * 100, metric_value(r, "band", f"share.{a}.max") * 100)
            for a in ("x", "y")}
    default = {a: metric_value(w, "all", f"share.{a}.window") * 100 if w is not None else float("nan")
               for a in ("x", "y")}
    summary = pd.DataFrame([{"axis": a, "default run [%]": default[a], "band min [%]": band[a][0],
                             "band max [%]": band[a][1], "paper [%]": _paper(a),
                             "paper inside the band": band[a][0] <= _paper(a) <= band[a][1]} for a in ("x", "y")])
    return Section("Robustness of the shares: a sweep over what the paper does not give",
                   "A Hydra multirun (its DVC stage) over the CP gain k ∈ {2.5, 10} 1/s (default 5), a common scale of "
                   "every PD gain ∈ {0.5, 2} (default 1) and the simulated robot's mass: Table 4's 32.51 kg or Table "
                   "1's 35.1 kg (×1.0797) under the controller's Table 4 model, with the default stance-foot setting. "
                   "Ranges fixed before the runs (paper.yaml). The band is [min, max] of the share over the jobs. 'Not "
                   "very significant' (RMS errors within 50 %) holds in "
                   f"{metric_value(r, 'band', 'claim.not_significant.holds'):.0f} of "
                   f"{metric_value(r, 'band', 'jobs'):.0f} jobs.", Table(summary, ".1f"),
                   Table(pd.DataFrame(rows), ".1f"), category="tracking errors")


def mechanisms_section(m: pd.DataFrame) -> Section:
    run = "knee-ankle"
    deg = 180 / math.pi

    def paper(target: str) -> str:
        return f"{paper_value(SLUG, target):g}"

    rows = [
        ("knee moment arm largest at [°]", metric_value(m, run, "knee.argmax_arm") * deg, "– (not printed)"),
        ("knee torque largest at [°]", metric_value(m, run, "knee.argmax_torque") * deg, paper("knee.torque_max")),
        ("knee stiffness largest at [°]", metric_value(m, run, "knee.argmax_stiffness") * deg,
         paper("knee.stiffness_max")),
        ("knee speed smallest at [°]", metric_value(m, run, "knee.argmin_speed") * deg, paper("knee.speed_min")),
        ("knee largest moment arm [m]", metric_value(m, run, "knee.arm_max"), "–"),
        ("knee largest stiffness k_s h² [N m/rad]", metric_value(m, run, "knee.stiffness_max"), "–"),
        ("knee spring energy at 1800 N, 74 N/mm [J]", metric_value(m, run, "claim.knee_spring_energy_J"),
         paper("knee.energy")),
        ("speed of 30 kg holding 33 J [m/s]", metric_value(m, run, "claim.speed_for_33J_m_s"),
         f"≈ {paper('knee.speed_33J')}"),
        ("speed of 30 kg holding the knee spring's energy [m/s]",
         metric_value(m, run, "claim.speed_for_knee_spring_m_s"), f"≈ {paper('knee.speed_spring')}"),
        ("ankle spring energy at 760 N, 64 N/mm [J]", metric_value(m, run, "claim.ankle_spring_energy_J"), "–"),
        ("ankle stiffness q11 / q12 at the zero pose [N m/rad]",
         f"{metric_value(m, run, 'ankle.zero_pose.stiffness_q11'):.0f} / "
         f"{metric_value(m, run, 'ankle.zero_pose.stiffness_q12'):.0f}", "–"),
    ]
    table = pd.DataFrame([(q, v if isinstance(v, str) else f"{v:.4g}", paper) for q, v, paper in rows],
                         columns=["quantity", "pipeline", "paper"])
    return Section("Knee and ankle drives (Secs. 3-4)",
                   "From the printed geometry and springs; motor torque and speed, drum radii and slider limits are "
                   "not given (assumptions in paper.yaml).", Table(table), category="trajectories")


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    m = metrics.get("mechanisms")
    if m is not None and not m.empty:
        sections.append(mechanisms_section(m))
    w = metrics.get("walking")
    if w is not None and not w.empty:
        sections += [s for s in (shares_section(w), stance_foot_section(w), tracking_section(w)) if s]
        sections.append(compute_time_section(
            "Compute time of the walking controller (ours; the paper gives none)", w, "extended",
            [("controller cycle: CP + PD + QP + inverse dynamics", "compute.controller", "1 ms cycle (Sec. 6.3)"),
             ("in it: the wrench QP (DAQP)", "compute.qp", "–"),
             ("in it: the model update (MuJoCo kinematics, M, h)", "compute.model_update", "–")],
            machine_of(runs, "walking"),
            note=f"Simulated {metric_value(w, 'extended', 'simulated_time'):.1f} s in "
                 f"{metric_value(w, 'extended', 'wall_time'):.2f} s of wall time (0.1 ms physics steps, "
                 "logging included); `python -m pipeline.benchmark forrest-biped` times it on a quiet machine."))
    r = metrics.get("robustness")
    if r is not None and not r.empty and (r["run_id"] == "band").any():
        sections.append(robustness_section(r, w))
    return sections
