"""Figures of `itbot-smc`: the simulated analogues of Figs. 6-11 (hardware traces in the paper), the
conventional SMC's gain/boundary-layer trade-off, the load-support band and the reaching-time study."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, paper_hline, paper_vline, plt
from analysis.core.signals import low_pass
from analysis.core.targets import paper_value
from pipeline.core.runlog import Run
from pipeline.papers.itbot_smc.model import JOINTS

COLORS = {"nsmerl": "C3", "smerl": "C0", "smc": "C2"}
LABELS = {"nsmerl": "nSMERL", "smerl": "SMERL", "smc": "SMC"}
STYLES = {"nsmerl": "-", "smerl": "--", "smc": "-."}
ZOOM = (0.0, 0.05)           # s: the start of the motion, where ω(t) acts (50 ticks: each switch visible)
ENVELOPE = 10                # ticks per min/max window of the whole-run torque panels
SLUG = "itbot-smc"


def _bound_deg() -> float:
    """The paper's error goal, Sec. 5.2 (targets.csv)."""
    return paper_value(SLUG, "err.nsmerl", "deg")


def _paper_force(axis: str) -> float:
    """The paper's peak hand force along x or y, Sec. 5.2 / Fig. 11 (targets.csv)."""
    return paper_value(SLUG, f"force.f{axis}", "N")


def _deg(x) -> np.ndarray:
    return np.degrees(np.asarray(x, dtype=float))


def hand_figures(runs: dict[str, Run], figures: Figures, where: str) -> None:
    """Figs. 6 and 7: hand position (desired dotted, actual solid) and hand tracking error."""
    for number, laws in ((6, ("nsmerl",)), (7, ("smerl", "smc"))):
        present = [law for law in laws if law in runs]
        if not present:
            continue
        fig, (pos, err) = plt.subplots(1, 2, figsize=(11, 3.6))
        for law in present:
            ref, e = runs[law]["/reference/hand"], runs[law]["/tracking_error/hand"]
            t = ref.index.to_numpy()
            for axis, shade in (("x", 1.0), ("y", 0.55)):
                desired = ref[f"position.{axis}"].to_numpy()
                pos.plot(t, desired, ":", color="k", lw=1)
                pos.plot(t, desired - e[f"error.{axis}"].to_numpy(), STYLES[law], color=COLORS[law], alpha=shade,
                         lw=1.2, label=f"{LABELS[law]} {axis}")
                err.plot(t, 1e3 * e[f"error.{axis}"].to_numpy(), STYLES[law], color=COLORS[law], alpha=shade, lw=0.8,
                         label=f"{LABELS[law]} e_{axis}")
        pos.set_xlabel("time [s]")
        pos.set_ylabel("hand position [m] (dotted: desired)")
        pos.legend(ncol=2, fontsize=7)
        err.set_xlabel("time [s]")
        err.set_ylabel("hand error p_d − p [mm]")
        err.legend(ncol=2, fontsize=7)
        names = " and ".join(LABELS[law] for law in present)
        fig.suptitle(f"Fig. {number}: (a) hand position, (b) hand tracking error under {names} ({where})")
        figures.save(fig, f"fig{number}-hand-{'-'.join(present)}")


def joint_figures(runs: dict[str, Run], figures: Figures, where: str) -> None:
    """Fig. 8 (joint angles) and Fig. 9 (joint errors, desired − actual) of the three controllers."""
    fig8, angles = plt.subplots(1, 2, figsize=(11, 3.4))
    fig9, errors = plt.subplots(1, 2, figsize=(11, 3.4))
    for law, run in runs.items():
        ref, e = run["/reference"], run["/tracking_error"]
        t = ref.index.to_numpy()
        for i, j in enumerate(JOINTS):
            desired = ref[f"position.{j}"].to_numpy()
            if law == next(iter(runs)):
                angles[i].plot(t, _deg(desired), ":", color="k", lw=1.2, label="desired")
            angles[i].plot(t, _deg(desired - e[f"error.{j}"].to_numpy()), STYLES[law], color=COLORS[law], lw=1,
                           label=LABELS[law])
            errors[i].plot(t, _deg(e[f"error.{j}"].to_numpy()), STYLES[law], color=COLORS[law], lw=0.8,
                           label=LABELS[law])
    bound = _bound_deg()
    for i, j in enumerate(JOINTS):
        angles[i].set_ylabel(f"θ{i + 1} [°]")
        errors[i].set_ylabel(f"e{i + 1} = θ{i + 1},d − θ{i + 1} [°]")
        paper_hline(errors[i], bound, label=f"paper: |e| < {bound:g}°")
        paper_hline(errors[i], -bound, label=None)
        for ax in (angles[i], errors[i]):
            ax.set_xlabel("time [s]")
            ax.set_title(j)
    angles[0].legend(fontsize=7)
    errors[0].legend(fontsize=7, ncol=2)
    fig8.suptitle(f"Fig. 8: joint angles under nSMERL, SMERL and conventional SMC ({where})")
    fig9.suptitle(f"Fig. 9: joint tracking errors ({where})")
    figures.save(fig8, "fig8-joint-angles")
    figures.save(fig9, "fig9-joint-errors")


def _band(ax, t: np.ndarray, u: np.ndarray, color: str, style: str, label: str | None) -> None:
    """A chattering signal: the band it switches in (min-max per ENVELOPE ticks) and its part below 10 Hz (drawn
    every ENVELOPE ticks: it is smooth)."""
    blocks = len(t) // ENVELOPE
    chunks = u[:blocks * ENVELOPE].reshape(blocks, ENVELOPE)
    ax.fill_between(t[:blocks * ENVELOPE:ENVELOPE], chunks.min(axis=1), chunks.max(axis=1), color=color, alpha=0.2,
                    lw=0)
    ax.plot(t[::ENVELOPE], low_pass(t, u)[::ENVELOPE], style, color=color, lw=1.1, label=label)


def torque_figure(runs: dict[str, Run], figures: Figures, where: str, name: str, number: str = "10") -> None:
    """Fig. 10: joint torques over the run (the band each law's torque chatters in, min/max per 10 ticks, and its
    part below 10 Hz) and the first 50 ticks, where every switch shows."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 5.6), gridspec_kw={"width_ratios": [2.2, 1]})
    for law, run in runs.items():
        command = run["/command"]
        t = command.index.to_numpy()
        zoom = (t >= ZOOM[0]) & (t <= ZOOM[1])
        for i, j in enumerate(JOINTS):
            tau = command[f"value.{j}"].to_numpy()
            _band(axes[i, 0], t, tau, COLORS[law], STYLES[law], LABELS[law])
            axes[i, 1].plot(t[zoom], tau[zoom], STYLES[law], color=COLORS[law], lw=0.9, drawstyle="steps-post")
            axes[i, 0].set_ylabel(f"τ{i + 1} [N m]")
    axes[1, 0].set_xlabel("time [s] (line: below 10 Hz; band: min-max per 10 ms)")
    axes[1, 1].set_xlabel(f"time [s] (first {1000 * ZOOM[1]:g} ms, held per tick)")
    axes[0, 0].legend(ncol=3, fontsize=7)
    fig.suptitle(f"Fig. {number}: joint torques ({where})")
    figures.save(fig, name)


def force_figure(runs: dict[str, Run], figures: Figures, where: str) -> None:
    """Fig. 11: the force of the hand on the handle (its band, min-max per 10 ms; below 10 Hz, lines), with the
    paper's peaks."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.6))
    for law, run in runs.items():
        wrench = run["/wrench"]
        t = wrench.index.to_numpy()
        for ax, axis in zip(axes, ("x", "y"), strict=True):
            _band(ax, t, wrench[f"force_{axis}.hand"].to_numpy(), COLORS[law], STYLES[law], f"{LABELS[law]} (< 10 Hz)")
    for ax, axis in zip(axes, ("x", "y"), strict=True):
        peak = _paper_force(axis)
        for sign in (1, -1):
            paper_hline(ax, sign * peak, label=f"paper: |F{axis}| ≈ {peak:g} N" if sign == 1 else None)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"F{axis} [N] (hand on handle, frame 0)")
        ax.legend(fontsize=7, ncol=2)
    fig.suptitle(f"Fig. 11: hand force on the handle with the 11 lb weight ({where})")
    figures.save(fig, "fig11-hand-force")


def plant_figure(analytic: Run, mujoco: Run, figures: Figures, law: str) -> None:
    """The same run on both plants: joint errors and torques over each other."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 5))
    for run, label, style, color in ((analytic, "analytic (eqs. A7-A12)", "-", "C0"), (mujoco, "MuJoCo", "--", "C1")):
        e, command = run["/tracking_error"], run["/command"]
        t = command.index.to_numpy()
        for i, j in enumerate(JOINTS):
            axes[0, i].plot(e.index, _deg(e[f"error.{j}"]), style, color=color, lw=0.8, label=label)
            _band(axes[1, i], t, command[f"value.{j}"].to_numpy(), color, style, label)
            axes[0, i].set_ylabel(f"e{i + 1} [°]")
            axes[1, i].set_ylabel(f"τ{i + 1} [N m] (line: < 10 Hz; band: min-max per 10 ms)")
            axes[1, i].set_xlabel("time [s]")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(f"{LABELS[law]} on the two plants: joint errors and torques")
    figures.save(fig, f"plants-{law}")


def sweep_figure(frame: pd.DataFrame, figures: Figures) -> None:
    """Conventional SMC: max joint error and torque total variation against the gain, per boundary layer."""
    fig, (err, tv) = plt.subplots(1, 2, figsize=(11, 3.6))
    for layer, part in frame.groupby("boundary_layer"):
        part = part.sort_values("K1")
        label = "sign" if layer == 0 else f"sat, Φ = {layer:g} rad/s"
        err.plot(part["K1"], _deg(part["e.max"]), "o-", label=label)
        tv.plot(part["K1"], part["tau.tv"], "o-", label=label)
    paper_hline(err, _bound_deg(), label="paper: < 2°")
    gains = sorted(frame["K1"].unique())
    for ax in (err, tv):
        ax.set_xscale("log")
        ax.set_xticks(gains, [f"{k:g}" for k in gains])
        ax.minorticks_off()
        ax.set_xlabel("K of joint 1 [rad/s²] (joint 2: × 0.4)")
        ax.legend(fontsize=7)
    err.set_ylabel("max joint error [°]")
    tv.set_ylabel("torque total variation, both joints [N m/s]")
    tv.set_yscale("log")
    fig.suptitle("Conventional SMC: tracking against chattering over its gain and boundary layer")
    figures.save(fig, "smc-gain-boundary-layer")


def support_figure(frame: pd.DataFrame, figures: Figures) -> None:
    """Peak hand forces and the max joint error against the share of the load the subject carries."""
    fig, (force, err) = plt.subplots(1, 2, figsize=(11, 3.6))
    for axis, color, style in (("x", "C0", "--"), ("y", "C1", ":")):
        force.plot(frame["support"], frame[f"force.{axis}.max"], "o-", color=color, label=f"max |F{axis}|")
        paper_hline(force, _paper_force(axis), label=f"paper: |F{axis}| ≈ {_paper_force(axis):g} N", ls=style)
    force.set_xlabel("share of the load (weight + arm) the subject carries")
    force.set_ylabel("peak hand force [N]")
    force.legend(fontsize=7)
    err.plot(frame["support"], _deg(frame["e.max"]), "o-", color="C3")
    paper_hline(err, _bound_deg(), label="paper: < 2°")
    err.set_xlabel("share of the load the subject carries")
    err.set_ylabel("max joint error [°] (nSMERL)")
    err.legend(fontsize=7)
    fig.suptitle("Fig. 11's peaks against the load on the handle (nSMERL, the model knows the share)")
    figures.save(fig, "load-support")


def reaching_figure(studies: dict[str, Run], figures: Figures) -> None:
    """Reaching time against |v(0)|: integrated (markers) and the paper's formulas (lines)."""
    fig, axes = plt.subplots(1, len(studies), figsize=(5.5 * len(studies), 4), squeeze=False)
    by_alpha = sorted(studies.items(), key=lambda item: float(item[1]["/reaching_time/summary"]["value.alpha"].iloc[0]))
    for ax, (case, run) in zip(axes[0], by_alpha, strict=True):
        study = run["/reaching_time"]
        gains = run["/reaching_time/summary"].iloc[0]
        v0 = study["value.v0"]
        for name, style, label in (("smc", "o", "SMC (integrated)"), ("smerl", "s", "ERL (integrated)"),
                                   ("nsmerl", "^", "nSMERL, eq. (6) (integrated)"),
                                   ("nsmerl_no_switching", "v", "nSMERL without ω-term (integrated)")):
            ax.plot(v0, study[f"value.{name}"], style, ms=3.5, mfc="none", label=label)
        for name, style, label in (("eq7", "k-", "eq. (7)"), ("eq14", "k--", "bound (14)"),
                                   ("eq13", "m:", "eq. (13), ω = 1"), ("eq21", "c-.", "eq. (21), ω → 0")):
            ax.plot(v0, study[f"value.{name}"], style, lw=1, label=label)
        paper_vline(ax, paper_value(SLUG, "reach.threshold"), label="paper: threshold (1−ϕ)^(−1/ϕ), eq. (27)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("|v(0)| [rad/s]")
        ax.set_ylabel("reaching time [s]")
        ax.set_title(f"{case}: K = {gains['value.K']:g}, φ = {gains['value.phi']:g}, α = {gains['value.alpha']:g}, "
                     f"p = {gains['value.p']:g}, ϕ = {gains['value.power']:g}", fontsize=8)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Reaching time of v̇ = r(v, t) against |v(0)| (Proposition 1, eqs. 7-30)")
    figures.save(fig, "reaching-time")
