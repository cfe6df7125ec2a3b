"""The paper's figures regenerated: Fig. 8 (knee), Figs. 10-12 (ankle), Figs. 14-16 (generators), Figs. 18-20 (the
walk), and ours: contact wrenches, the LIP check, compute time, the robustness band."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, paper_hline, paper_vline, plt
from analysis.core.targets import paper_value
from analysis.papers.forrest_biped.metrics import XYZ, Walk, curve
from pipeline.core.runlog import Run

DESIRED, MEASURED = "tab:red", "tab:blue"      # the paper's Fig. 19 colours
GEN_COLOR = {"extended": "tab:blue", "traditional": "tab:orange"}
SLUG = "forrest-biped"
SWEEP_LABEL = {"cp_gain": "k = ", "gain_scale": "K_p × ", "mass_scale": "mass × "}


def knee_figure(run: Run, figures: Figures) -> None:
    knee = curve(run, "/knee")
    deg = np.degrees(knee["flexion_rad"])
    fig, axes = plt.subplots(1, 3, figsize=(10, 3))
    for ax, col, label in zip(axes, ("speed_rad_s", "torque_Nm", "stiffness_Nm_per_rad"),
                              ("max. speed [rad/s]", "max. torque [N m]", "stiffness [N m/rad]"), strict=True):
        ax.plot(deg, knee[col])
        paper_vline(ax, paper_value(SLUG, "knee.torque_max", "deg"), label="paper: extremum at 60°", lw=0.8)
        ax.set_xlabel("knee flexion [°]")
        ax.set_ylabel(label)
    axes[1].legend()
    fig.suptitle("Fig. 8: knee drive (eqs. 1-9; motor 1.2 N m, 2560 rpm assumed)")
    figures.save(fig, "fig08-knee")


def _grid(ankle: pd.DataFrame, column: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    q11, q12 = np.degrees(ankle["q11_rad"].to_numpy()), np.degrees(ankle["q12_rad"].to_numpy())
    n1, n2 = len(np.unique(q11)), len(np.unique(q12))
    return q11.reshape(n1, n2), q12.reshape(n1, n2), ankle[column].to_numpy().reshape(n1, n2)


def ankle_figures(run: Run, figures: Figures) -> None:
    ankle = curve(run, "/ankle")
    same, opposite = "both motors the same way", "the motors in opposite directions"
    for name, title, panels, unit in (
            ("fig10-ankle-speed", "Fig. 10: ankle speed, sliders at 0.2 m/s",
             [("speed_same_q11_rad_s", f"(a) q̇11, {same}"), ("speed_same_q12_rad_s", f"(b) q̇12, {same}"),
              ("speed_opposite_q11_rad_s", f"(c) q̇11, {opposite}"),
              ("speed_opposite_q12_rad_s", f"(d) q̇12, {opposite}")], "rad/s"),
            ("fig11-ankle-torque", "Fig. 11: ankle torque, sliders at 1.7 kN",
             [("torque_same_q11_Nm", f"(a) τ11, {same}"), ("torque_same_q12_Nm", f"(b) τ12, {same}"),
              ("torque_opposite_q11_Nm", f"(c) τ11, {opposite}"), ("torque_opposite_q12_Nm", f"(d) τ12, {opposite}")],
             "N m"),
            ("fig12-ankle-stiffness", "Fig. 12: ankle stiffness Jᵀ K_s J, K_s = 64 N/mm per slider",
             [("stiffness_q11_Nm_per_rad", "(a) k11"), ("stiffness_q12_Nm_per_rad", "(b) k12")], "N m/rad")):
        rows = len(panels) // 2
        fig, axes = plt.subplots(rows, 2, figsize=(9, 3.4 * rows), squeeze=False)
        for ax, (col, label) in zip(axes.ravel(), panels, strict=True):
            a, b, z = _grid(ankle, col)
            cs = ax.contourf(a, b, z, levels=20, cmap="viridis")
            fig.colorbar(cs, ax=ax, label=unit)
            ax.set_xlabel("q11 (pitch) [°]")
            ax.set_ylabel("q12 (roll) [°]")
            ax.set_title(label, fontsize=8)
            ax.grid(False)
        fig.suptitle(title)
        figures.save(fig, name)


def _phases(ax, steps: pd.DataFrame, T1: float, T3: float, T: float) -> None:
    for t0 in steps.index:
        ax.axvspan(t0, t0 + T1, color="0.9", lw=0)
        ax.axvspan(t0 + T - T3, t0 + T, color="0.9", lw=0)


def generator_figures(runs: dict[str, Run], figures: Figures) -> None:
    ext, trad = runs.get("extended"), runs.get("traditional")
    if ext is None:
        return
    walk = ext.config["system"]["walk"]
    T1, T3 = walk["T1"], walk["T3"]
    ref = {k: (r["/reference/com"], r["/reference/cp"], r["/reference/zmp"]) for k, r in runs.items()}
    # Fig. 14: one step of the extended generator, the three ZMP phases
    com, cp, zmp = ref["extended"]
    t = com.index.to_numpy()
    step = (t >= 1.0) & (t <= 2.0)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3))
    for ax, axis in zip(axes, ("x", "y"), strict=True):
        ax.plot(t[step], zmp[f"position.{axis}"].to_numpy()[step], label="ZMP (extended)", color="tab:blue")
        ax.plot(t[step], cp[f"position.{axis}"].to_numpy()[step], label="CP (extended)", color="tab:red")
        if trad is not None:
            tz = ref["traditional"][2][f"position.{axis}"].to_numpy()
            ax.plot(t[step], tz[step], color="tab:blue", ls=":", label="ZMP (traditional)")
        ax.axvspan(1.0, 1.0 + T1, color="0.9", lw=0)
        ax.axvspan(2.0 - T3, 2.0, color="0.9", lw=0)
        ax.text(1.0 + T1 / 2, ax.get_ylim()[1], "T1", ha="center", va="top", fontsize=7)
        ax.text(1.5, ax.get_ylim()[1], "T2", ha="center", va="top", fontsize=7)
        ax.text(2.0 - T3 / 2, ax.get_ylim()[1], "T3", ha="center", va="top", fontsize=7)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(f"{axis} [m]")
    axes[0].legend(fontsize=7)
    fig.suptitle("Fig. 14: ZMP and CP over one step (left support, 1-2 s)")
    figures.save(fig, "fig14-zmp-cp-step")
    # Fig. 15: ZMP, CP, CoM position and velocity against time
    fig, axes = plt.subplots(3, 3, figsize=(12, 7), sharex=True)
    for col, axis in enumerate(XYZ):
        for kind, (com, cp, zmp) in ref.items():
            if kind not in GEN_COLOR:
                continue
            ls = "-" if kind == "extended" else "--"
            t = com.index.to_numpy()
            axes[0, col].plot(t, zmp[f"position.{axis}"], ls=ls, color="tab:blue", lw=1, label=f"ZMP ({kind})")
            axes[0, col].plot(t, cp[f"position.{axis}"], ls=ls, color="tab:red", lw=1, label=f"CP ({kind})")
            axes[1, col].plot(t, com[f"position.{axis}"], ls=ls, color="k", lw=1, label=f"CoM ({kind})")
            axes[2, col].plot(t, com[f"velocity.{axis}"], ls=ls, color="tab:green", lw=1, label=f"CoM vel. ({kind})")
        axes[0, col].set_title(axis)
        axes[2, col].set_xlabel("t [s]")
    axes[0, 0].set_ylabel("ZMP, CP [m]")
    axes[1, 0].set_ylabel("CoM [m]")
    axes[2, 0].set_ylabel("CoM velocity [m/s]")
    axes[0, 0].legend(fontsize=6)
    axes[2, 0].legend(fontsize=6)
    fig.suptitle("Fig. 15: ZMP, CP, CoM position and velocity (solid: extended, dashed: traditional; "
                 "z: the CoM height lowered in the first second)")
    figures.save(fig, "fig15-zmp-cp-com")
    # Fig. 16: the x-y plane with the footprints
    fig, ax = plt.subplots(figsize=(8, 4.5))
    half = (ext.config["system"]["model"]["foot_length"] / 2, ext.config["system"]["model"]["foot_width"] / 2)
    feet = ext["/reference/feet"]
    for side in ("left", "right"):
        rest = feet[feet[f"position.{side}.z"] == 0.0]
        for x, y in {(round(a, 6), round(b, 6)) for a, b in zip(rest[f"position.{side}.x"],
                                                               rest[f"position.{side}.y"], strict=True)}:
            ax.add_patch(plt.Rectangle((x - half[0], y - half[1]), 2 * half[0], 2 * half[1], fill=False, color="0.5"))
    for kind, (com, cp, zmp) in ref.items():
        if kind not in GEN_COLOR:
            continue
        ls, alpha = ("-", 1.0) if kind == "extended" else ("--", 0.6)
        ax.plot(zmp["position.x"], zmp["position.y"], ls=ls, color="tab:blue", alpha=alpha, label=f"ZMP ({kind})")
        ax.plot(cp["position.x"], cp["position.y"], ls=ls, color="tab:red", alpha=alpha, label=f"CP ({kind})")
        ax.plot(com["position.x"], com["position.y"], ls=ls, color="k", alpha=alpha, label=f"CoM ({kind})")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(fontsize=7, ncol=2, loc="upper left")
    fig.suptitle("Fig. 16: ZMP, CP and CoM in the x-y plane, footprints (grey)")
    figures.save(fig, "fig16-xy-plane")
    printed = runs.get("extended-eq48-printed")
    if printed is not None:
        fig, axes = plt.subplots(1, 2, figsize=(10, 3))
        for ax, axis in zip(axes, ("x", "y"), strict=True):
            for kind, ls in (("extended", "-"), ("extended-eq48-printed", "--")):
                cp, zmp = runs[kind]["/reference/cp"], runs[kind]["/reference/zmp"]
                ax.plot(zmp.index, zmp[f"position.{axis}"], ls=ls, color="tab:blue", label=f"ZMP ({kind})")
                ax.plot(cp.index, cp[f"position.{axis}"], ls=ls, color="tab:red", label=f"CP ({kind})")
            ax.set_xlabel("t [s]")
            ax.set_ylabel(f"{axis} [m]")
        axes[0].legend(fontsize=7)
        fig.suptitle("Eq. (48) as printed: P1 is wrong and the CP leaves the footsteps (corrected: solid)")
        figures.save(fig, "eq48-printed")


def walking_figures(runs: dict[str, Run], errors: dict[str, Walk], shares: dict[str, float],
                    figures: Figures) -> None:
    ext = runs.get("extended")
    if ext is None:
        return
    # Fig. 18: side view of the walk with CoM (red) and CoP (green), from the /tf frames
    tf = ext["/tf"]
    bodies = [c.removeprefix("transforms.").removesuffix(".translation.x") for c in tf.columns
              if c.endswith(".translation.x")]
    times = np.arange(1.0, 3.01, 0.25)
    fig = plt.figure(figsize=(12, 6.5))
    grid = fig.add_gridspec(2, len(times), height_ratios=[1.3, 1])
    chains = [["base", "l_link7", "l_link9", "l_link10", "l_link11"], ["base", "r_link13", "r_link15", "r_link16",
                                                                       "r_link17"]]
    for k, t0 in enumerate(times):
        side = fig.add_subplot(grid[0, k])
        row = tf.iloc[int(np.argmin(np.abs(tf.index.to_numpy() - t0)))]
        pos = {b: np.array([row[f"transforms.{b}.translation.{a}"] for a in XYZ]) for b in bodies}
        for chain, color in zip(chains, ("tab:blue", "tab:orange"), strict=True):
            pts = np.array([pos[b] for b in chain if b in pos])
            pts = np.vstack([pts, pts[-1] - np.array([0, 0, 0.105])])        # down to the sole
            side.plot(pts[:, 0], pts[:, 2], color=color, lw=1.5)
        side.plot([pos["base"][0]] * 2, [pos["base"][2], pos["base"][2] + 0.25], color="0.4", lw=4)
        side.plot(pos["com"][0], pos["com"][2], "o", color="tab:red", ms=5)
        side.plot(pos["zmp"][0], 0.0, "o", color="tab:green", ms=5)
        side.axhline(0, color="0.6", lw=0.8)
        side.set_xlim(pos["com"][0] - 0.35, pos["com"][0] + 0.35)
        side.set_ylim(-0.05, 1.2)
        side.set_aspect("equal")
        side.set_title(f"{t0:.2f} s", fontsize=8)
        side.tick_params(labelsize=6)
        if k:
            side.set_yticklabels([])
    top = fig.add_subplot(grid[1, :])
    bal = ext["/balance"]
    top.plot(bal["com.x"], bal["com.y"], color="tab:red", label="CoM")
    top.plot(bal["zmp.x"], bal["zmp.y"], color="tab:green", lw=0.8, label="CoP (measured)")
    top.plot(bal["zmp_cmd.x"], bal["zmp_cmd.y"], color="k", lw=0.6, ls=":", label="p^c (commanded)")
    top.set_aspect("equal")
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.legend(fontsize=7, loc="upper left")
    fig.suptitle("Fig. 18: the walk in MuJoCo (extended generator), side views 1-3 s (left leg blue, right orange), "
                 "CoM red, CoP green")
    figures.save(fig, "fig18-walk")
    # Fig. 19: CoM and CP, desired (red) against measured (blue)
    fig, axes = plt.subplots(2, 2, figsize=(10, 5.5), sharex=True)
    for r, (name, ref_topic) in enumerate((("CoM", "/reference/com"), ("CP", "/reference/cp"))):
        ref = ext[ref_topic]
        meas = bal[[f"{name.lower()}.{a}" for a in XYZ]]
        for c, axis in enumerate(("x", "y")):
            ax = axes[r, c]
            ax.plot(ref.index, ref[f"position.{axis}"], color=DESIRED, label="desired")
            ax.plot(meas.index, meas[f"{name.lower()}.{axis}"], color=MEASURED, ls="--", label="measured")
            ax.set_ylabel(f"{name} {axis} [m]")
            ax.set_title(f"({'abcd'[2 * r + c]}) {name} {axis}", fontsize=8)
    axes[1, 0].set_xlabel("t [s]")
    axes[1, 1].set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Fig. 19: CoM and CP of the walk (extended generator), desired vs measured")
    figures.save(fig, "fig19-com-cp-tracking")
    # Fig. 20: CoM errors of the two generators
    fig, axes = plt.subplots(2, 1, figsize=(10, 5.5), sharex=True)
    for k, axis in enumerate(("x", "y")):
        ax = axes[k]
        for g in ("extended", "traditional"):
            if g in errors:
                ax.plot(errors[g].t, errors[g].com_error[:, k] * 1e3, color=GEN_COLOR[g], lw=0.9,
                        label=f"{g} CP generator")
        ax.axvspan(1.0, 3.0, color="0.95", lw=0)
        ax.set_ylabel(f"CoM error {axis} [mm]")
        ax.set_title(f"({'ab'[k]}) share of 1-3 s with the smaller |error| for the extended generator: "
                     f"{shares.get(axis, np.nan) * 100:.1f} % (paper {paper_value(SLUG, f'share.{axis}', '%'):g} %)",
                     fontsize=8)
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("t [s]")
    fig.suptitle("Fig. 20: CoM position error, extended vs traditional generator (same controller)")
    figures.save(fig, "fig20-com-error")
    # ours: contact wrenches and ZMP
    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    for side, color in (("left_foot", "tab:blue"), ("right_foot", "tab:orange")):
        wr = ext[f"/wrench/{side}"]
        axes[0].plot(wr.index, wr["force_z.measured"], color=color, label=f"{side} measured")
        axes[0].plot(wr.index, wr["force_z.commanded"], color=color, ls=":", label=f"{side} QP")
    axes[0].set_ylabel("normal force [N]")
    axes[0].legend(fontsize=7, ncol=2)
    for k, axis in enumerate(("x", "y")):
        axes[k + 1].plot(bal.index, bal[f"zmp_cmd.{axis}"], color="k", lw=0.8, label="p^c commanded (eq. 50)")
        axes[k + 1].plot(bal.index, bal[f"zmp.{axis}"], color="tab:green", lw=0.8, label="CoP measured")
        axes[k + 1].plot(ext["/reference/zmp"].index, ext["/reference/zmp"][f"position.{axis}"], color=DESIRED,
                         lw=0.8, ls="--", label="p^d (generator)")
        axes[k + 1].set_ylabel(f"ZMP {axis} [m]")
    axes[1].legend(fontsize=7)
    axes[2].set_xlabel("t [s]")
    fig.suptitle("Contact forces (four corner contacts per foot) and the ZMP: commanded, measured, planned")
    figures.save(fig, "walk-contact-wrenches")
    # ours: the LIP check beside the full simulation
    lipm = [k for k in errors if k.startswith("lipm") and k.endswith("extended")]
    if lipm:
        fig, axes = plt.subplots(2, 1, figsize=(10, 5.5), sharex=True)
        for k, axis in enumerate(("x", "y")):
            for name in ["extended", "traditional", *lipm, *(n.replace("extended", "traditional") for n in lipm)]:
                if name in errors:
                    ls = "-" if not name.startswith("lipm") else ("--" if "lag" in name else ":")
                    color = GEN_COLOR["traditional" if name.endswith("traditional") else "extended"]
                    axes[k].plot(errors[name].t, errors[name].com_error[:, k] * 1e3, ls=ls, color=color, lw=0.8,
                                 label=name)
            axes[k].set_ylabel(f"CoM error {axis} [mm]")
        axes[0].legend(fontsize=6, ncol=3)
        axes[1].set_xlabel("t [s]")
        fig.suptitle("CoM error: MuJoCo whole body (solid) against the LIP point mass, ideal (dotted) and with a "
                     "10 ms ZMP lag (dashed)")
        figures.save(fig, "lipm-vs-mujoco")
    # ours: the controller's compute time per cycle
    fig, ax = plt.subplots(figsize=(7, 3))
    for g in ("extended", "traditional"):
        if g in runs:
            s = runs[g]["/compute_time"]["seconds.controller"].to_numpy() * 1e6
            ax.hist(s, bins=np.geomspace(max(s.min(), 1), s.max(), 60), histtype="step", color=GEN_COLOR[g],
                    label=f"{g}: median {np.median(s):.0f} µs, p95 {np.percentile(s, 95):.0f} µs")
    ax.axvline(1000, color="k", ls="--", lw=0.8, label="1 ms cycle (Sec. 6.3)")
    ax.set_xscale("log")
    ax.set_xlabel("controller wall time per cycle [µs] (CP + PD + QP + inverse dynamics, Python)")
    ax.set_ylabel("cycles")
    ax.legend(fontsize=7)
    figures.save(fig, "walk-compute-time")


def robustness_figure(table: pd.DataFrame, figures: Figures) -> None:
    """The Eq. (59) shares of every sweep job, with the paper's values (the default run: the report's table)."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True)
    labels = ["\n".join(SWEEP_LABEL.get(key.rsplit(".", 1)[-1], key.rsplit(".", 1)[-1] + "=") + value
                        for key, value in (o.split("=") for o in job.split(","))) for job in table.index]
    for ax, axis in zip(axes, ("x", "y"), strict=True):
        ax.bar(range(len(table)), table[f"share.{axis}"] * 100, color="tab:blue", alpha=0.7, label="sweep jobs")
        paper = paper_value(SLUG, f"share.{axis}", "%")
        paper_hline(ax, paper, label=f"paper {paper:g} %")
        ax.axhline(50, color="0.5", ls=":", lw=0.8)
        ax.set_xticks(range(len(table)), labels, fontsize=6)
        ax.set_title(f"share of 1-3 s with the smaller |CoM error {axis}| for the extended generator", fontsize=8)
        ax.set_ylim(0, 100)
    axes[0].set_ylabel("%")
    axes[0].legend(fontsize=7)
    fig.suptitle("Robustness of the Eq. (59) shares over the guessed gains and the simulated robot's mass")
    figures.save(fig, "robustness-shares")
