"""Metrics of `itbot-smc` from the runs on disk (SI units).

Per closed-loop run (the exercise window [0, T]; "start" is [0, 1 s], where ω(t) = 1/(1+t²) ≥ 0.5):

    e.<joint>.max / .mean / .rms / .ise   joint error θ_d − θ (rad; Fig. 9's sign), analysis/core/errors.py
    e.max, e.rms                          the larger joint's max |e|; RMS of the error norm
    hand_error.max / .rms                 ‖p_d − p‖ of the hand (m), Figs. 6b/7b
    tau.<joint>.tv / .hf_rms              chattering of the torque (analysis/core/signals.py: total variation
                                          rate, N m/s; RMS above 10 Hz, N m); `.start.` the same over [0, 1 s],
                                          `.after.` over [1 s, T]
    tau.tv, tau.hf_rms (+ start, after)   summed over the joints (tv), root-sum-square (hf_rms)
    tau.<joint>.max, effort               max |τ| (N m); Σ ∫ τ² dt (N² m² s, torques held per tick)
    saturated                             share of ticks with a torque at the drive's limit
    force.x.max / force.y.max             peak |F| of the hand's force on the handle (N), Fig. 11, of its slow
                                          part (low-pass at 10 Hz: the load's resistance without the chattering
                                          of the rigid load's acceleration); `.raw`: of every tick's value
    v.<joint>.sign_changes                zero crossings of the sliding variable per second      (`detail`)
    controller.median / .p95              wall time of one controller call (s)                   (`detail`)
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import yaml

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from analysis.core.metrics import MetricTable, metric_value
from analysis.core.signals import chattering_stats, low_pass, sign_change_rate
from pipeline.core.runlog import Run
from pipeline.papers.itbot_smc import SYSTEM_ATTACHMENT
from pipeline.papers.itbot_smc.model import JOINTS

LAWS = ("nsmerl", "smerl", "smc")
START = 1.0          # s, the "motion start" window
AT_LIMIT = 1e-9      # relative: a torque this close to the limit is saturated


def system_of(run: Run) -> dict:
    """The system config the run was simulated with (the experiment's, as its case changed it)."""
    return yaml.safe_load(run.attachments[SYSTEM_ATTACHMENT])


def law_of(run: Run) -> str:
    """The reaching law of a closed-loop run, named in its case: `<law>-<plant or group>`, `paper-model-<law>`."""
    return next(part for part in run.metadata["case"].split("-") if part in LAWS)


def closed_loop_metrics(run: Run, detail: bool = True, forces: bool = True) -> dict[str, tuple[float, str]]:
    """The metrics above; `detail` adds the sliding variable's sign changes and the controller's timing,
    `forces` the hand force (each a 1 kHz channel to read: the analysis asks for them where it reports them)."""
    values: dict[str, tuple[float, str]] = {}
    err = run["/tracking_error"]
    t = err.index.to_numpy()
    for j in JOINTS:
        values |= error_stats(t, err[f"error.{j}"].to_numpy(), f"e.{j}", "rad")
    values["e.max"] = (max(values[f"e.{j}.max"][0] for j in JOINTS), "rad")
    values["e.rms"] = (float(np.sqrt(np.mean(err["norm"].to_numpy() ** 2))), "rad")
    windowed = t[-1] > 2 * START      # a run long enough for a start and an after window
    if windowed:
        settled = err.loc[t >= START, [f"error.{j}" for j in JOINTS]]
        values["e.settled.max"] = (float(settled.abs().to_numpy().max()), "rad")
    hand = run["/tracking_error/hand"]["norm"].to_numpy()
    values |= {k: v for k, v in error_stats(t, hand, "hand_error", "m").items() if k.endswith((".max", ".rms"))}

    command = run["/command"]
    tc = command.index.to_numpy()
    tau = command[[f"value.{j}" for j in JOINTS]].to_numpy()
    windows = {"": slice(None), **({"start.": tc <= START, "after.": tc >= START} if windowed else {})}
    for i, j in enumerate(JOINTS):
        for window, ticks in windows.items():
            values |= {k.replace(f"tau.{j}.", f"tau.{j}.{window}"): v
                       for k, v in chattering_stats(tc[ticks], tau[ticks, i], f"tau.{j}", "Nm").items()}
        values[f"tau.{j}.max"] = (float(np.abs(tau[:, i]).max()), "Nm")
    for window in windows:
        values[f"tau.{window}tv"] = (sum(values[f"tau.{j}.{window}tv"][0] for j in JOINTS), "Nm/s")
        values[f"tau.{window}hf_rms"] = (float(np.sqrt(sum(values[f"tau.{j}.{window}hf_rms"][0] ** 2 for j in JOINTS))),
                                         "Nm")
    period = float(tc[1] - tc[0])
    values["effort"] = (float((tau ** 2).sum() * period), "N^2*m^2*s")
    limit = np.asarray(system_of(run)["drive"]["torque_limit"], dtype=float)
    values["saturated"] = (float((np.abs(tau) >= limit * (1 - AT_LIMIT)).any(axis=1).mean()), "fraction")

    if forces:
        wrench = run["/wrench"]
        tw = wrench.index.to_numpy()
        for axis in ("x", "y"):
            force = wrench[f"force_{axis}.hand"].to_numpy()
            values[f"force.{axis}.max"] = (float(np.abs(low_pass(tw, force)).max()), "N")
            values[f"force.{axis}.max.raw"] = (float(np.abs(force).max()), "N")
    if detail:
        v = run["/sliding_variable"]
        for j in JOINTS:
            values[f"v.{j}.sign_changes"] = (sign_change_rate(v.index.to_numpy(), v[f"value.{j}"].to_numpy()), "1/s")
        values |= timing_metrics("controller", run["/compute_time"][f"seconds.{law_of(run)}"].to_numpy())
    return values


def group_of(run: Run) -> tuple[str, str]:
    """(group, overrides suffix) of a tracking run: `nsmerl-analytic` -> (`analytic`, ``),
    `smc-hall__system.reference.period=5` -> (`hall`, `__system.reference.period=5`)."""
    case = run.metadata["case"]
    return case.split("-", 1)[1], run.run_id.removeprefix(case)


def claims(m: MetricTable, frame: pd.DataFrame, group: str, others: str | None = None, suffix: str = "") -> None:
    """The paper's comparisons among the three laws of one group (plant / sensing), as 1 (holds) or 0, under
    run id `<group><suffix>`: nSMERL chatters less than SMC (whole run, both measures), less than SMERL at the
    motion start, and tracks better than SMC (RMS and max of the joint error). SMERL's and SMC's runs come from
    group `others` if given (a group that varies only nSMERL)."""
    def value(law: str, metric: str) -> float:
        source = group if law == "nsmerl" or others is None else others
        return metric_value(frame, f"{law}-{source}{suffix}", metric)

    label = group + suffix
    if any(np.isnan(value(law, "e.max")) or np.isnan(value(law, "tau.start.tv")) for law in LAWS):
        return                                   # a law missing, or a run too short for the start window
    m.add(label, "claim.less_chattering_than_smc",
          float(value("nsmerl", "tau.tv") < value("smc", "tau.tv")
                and value("nsmerl", "tau.hf_rms") < value("smc", "tau.hf_rms")), "bool")
    m.add(label, "claim.less_chattering_than_smerl_at_start",
          float(value("nsmerl", "tau.start.tv") < value("smerl", "tau.start.tv")
                and value("nsmerl", "tau.start.hf_rms") < value("smerl", "tau.start.hf_rms")), "bool")
    m.add(label, "claim.tracks_better_than_smc",
          float(value("nsmerl", "e.rms") < value("smc", "e.rms") and value("nsmerl", "e.max") < value("smc", "e.max")),
          "bool")
    for metric in ("tau.tv", "tau.start.tv", "tau.after.tv", "tau.hf_rms", "e.rms"):
        m.add(label, f"ratio.smc_over_nsmerl.{metric}", value("smc", metric) / value("nsmerl", metric), "ratio")
        m.add(label, f"ratio.smerl_over_nsmerl.{metric}", value("smerl", metric) / value("nsmerl", metric), "ratio")


def plant_agreement(m: MetricTable, frame: pd.DataFrame, suffix: str = "") -> None:
    """How far the MuJoCo plant's metrics lie from the analytic plant's, per law (relative)."""
    for law in LAWS:
        for metric in ("e.max", "e.rms", "tau.tv", "tau.hf_rms", "force.y.max"):
            a = metric_value(frame, f"{law}-analytic{suffix}", metric)
            b = metric_value(frame, f"{law}-mujoco{suffix}", metric)
            if np.isfinite(a) and np.isfinite(b):
                m.add(f"{law}-plants{suffix}", f"agreement.{metric}", abs(b - a) / abs(a), "fraction")


# -- the reaching-time study -------------------------------------------------------------------------------


def reaching_metrics(run: Run) -> dict[str, tuple[float, str]]:
    study = run["/reaching_time"]
    gains = run["/reaching_time/summary"].iloc[0]
    col = {name: study[f"value.{name}"].to_numpy() for name in ("v0", "smc", "smerl", "nsmerl",
                                                                 "nsmerl_no_switching", "eq7", "eq14")}
    v0, threshold = col["v0"], float(gains["value.threshold"])
    above = v0 > threshold
    return {
        "threshold": (threshold, "rad/s"),
        "eq7.max_deviation": (float(np.max(np.abs(col["smerl"] / col["eq7"] - 1))), "fraction"),
        "smc.max_deviation": (float(np.max(np.abs(col["smc"] * float(gains["value.K"]) / v0 - 1))), "fraction"),
        "eq14.holds": (float((col["smerl"] <= col["eq14"] * (1 + 1e-9)).all()), "bool"),
        "eq14.first_violation": (float(v0[np.argmax(col["smerl"] > col["eq14"])]) if (col["smerl"] > col["eq14"]).any()
                                 else float("nan"), "rad/s"),
        "crossover": (float(gains["value.crossover"]), "rad/s"),
        "crossover.no_switching": (float(gains["value.crossover_no_switching"]), "rad/s"),
        "claim.faster_above_threshold": (float((col["nsmerl"][above] < col["smerl"][above]).all()), "bool"),
        "claim.faster_above_threshold.no_switching":
            (float((col["nsmerl_no_switching"][above] < col["smerl"][above]).all()), "bool"),
        "claim.faster_everywhere": (float((col["nsmerl"] < col["smerl"]).all()), "bool"),
    }
