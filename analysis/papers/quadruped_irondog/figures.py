"""Figures of `quadruped-irondog`: the paper's Figs. 12, 16, 18, 19-20 and 21-22 regenerated from the runs, and
the robot drawn as a stick figure from its /tf frames (hips, knees, feet)."""

from __future__ import annotations

import numpy as np

from analysis.core.figures import Figures, plt
from analysis.core.targets import paper_value
from analysis.papers.quadruped_irondog.metrics import columns, feet, robot_mass, trot_timing
from pipeline.core.runlog import Run
from pipeline.papers.quadruped_irondog.kinematics import JOINT_NAMES, LEGS, Layout, Leg, feet_in_body, fk, leg_to_body

SLUG = "quadruped-irondog"
LEG_COLORS = {"FR": "C3", "FL": "C0", "BR": "C1", "BL": "C2"}


def _xyz(frame, prefix: str) -> np.ndarray:
    return frame[[f"{prefix}.{a}" for a in "xyz"]].to_numpy(dtype=float)


def skeleton(run: Run, k: int) -> dict[str, np.ndarray]:
    """World points of /tf sample k: 'trunk' (5, 3) closed hip rectangle, and per leg (4, 3) hip-femur-knee-foot."""
    tf = run["/tf"].iloc[[k]]
    out = {}
    for leg in LEGS:
        out[leg] = np.concatenate([_xyz(tf, f"transforms.{leg}_{part}.translation")
                                   for part in ("coxa", "femur", "tibia", "foot")])
    out["trunk"] = np.stack([out[leg][0] for leg in ("FR", "FL", "BL", "BR", "FR")])
    return out


def draw_robot(ax, points: dict[str, np.ndarray], plane: tuple[int, int] = (0, 2), **style) -> None:
    """The stick figure projected on two world axes (0 x, 1 y, 2 z)."""
    i, j = plane
    ax.plot(points["trunk"][:, i], points["trunk"][:, j], color=style.get("color", "0.3"), lw=2,
            alpha=style.get("alpha", 1.0))
    for leg in LEGS:
        p = points[leg]
        ax.plot(p[:, i], p[:, j], "-o", ms=2, lw=1.5, color=style.get("color", LEG_COLORS[leg]),
                alpha=style.get("alpha", 1.0))


# -- kinematics -----------------------------------------------------------------------------------------------------


def bezier_swing(run: Run, figs: Figures) -> None:
    """Fig. 12: the Table 3 swing with its control polygon, and the straight stance (a, d in mm)."""
    points = np.asarray(run.config["system"]["gait"]["control_points_mm"])
    curve = run["/reference/bezier"]
    a, d = curve["position.a"] * 1e3, curve["position.d"] * 1e3
    t = curve.index.to_numpy()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 3.8))
    ax.plot(points[:, 0], points[:, 1], "--o", color="0.6", ms=3, lw=0.8, label="control points P0…P13 (Table 3)")
    labels: dict[tuple[float, float], list[str]] = {}
    for k, (x, y) in enumerate(points):        # coinciding control points share one label (P3,4,5; P9,10)
        labels.setdefault((x, y), []).append(str(k))
    for (x, y), ks in labels.items():
        ax.annotate("P" + ",".join(ks), (x, y), fontsize=6, xytext=(2, 2), textcoords="offset points")
    ax.plot(a, d, "C0", lw=2, label="swing B(s), eqs. (41)-(44)")
    ax.plot([points[-1, 0], points[0, 0]], [points[-1, 1], points[0, 1]], "C1", lw=2, label="stance (assumed)")
    ticks = np.linspace(0, len(a) - 1, 11).astype(int)
    ax.plot(a.iloc[ticks], d.iloc[ticks], "k.", ms=4)
    ax.set_xlabel("a [mm]")
    ax.set_ylabel("d [mm]")
    ax.set_aspect("equal")
    ax.set_title("Fig. 12b: 14-point Bezier swing (dots: s = 0, 0.1, …, 1)", fontsize=9)
    ax.legend(fontsize=6, loc="upper right")
    bx.plot(t, a, label="a(t)")
    bx.plot(t, d, label="d(t)")
    bx.set_xlabel("t [s] (swing)")
    bx.set_ylabel("[mm]")
    bx.set_title("Fig. 12a: the swing's coordinates over its 0.25 s", fontsize=9)
    bx.legend(fontsize=7)
    figs.save(fig, "fig12-bezier")


def ik_round_trip(run: Run, figs: Figures) -> None:
    """‖FK(IK(p)) − p‖ of eq. (40) as printed and as corrected, over the swing and over random leg poses."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 3.4))
    floor = 1e-16   # exact zeros are drawn here
    for form, color in (("printed", "C3"), ("corrected", "C0")):
        e = run[f"/ik/bezier/{form}"]["value.fk_ik_error_m"]
        ax.semilogy(e.index, np.maximum(e * 1e3, floor), color=color, label=f"eq. (40) {form}")
    ax.set_xlabel("t [s] (swing)")
    ax.set_ylabel("‖FK(IK(p)) − p‖ [mm] (0 drawn at 1e-16)")
    ax.set_title("over the Table 3 swing")
    ax.legend(fontsize=7)
    ws = run["/ik/workspace"]
    for column, form, color in (("printed_fk_ik_error_m", "printed", "C3"), ("fk_ik_error_m", "corrected", "C0")):
        e = np.maximum(ws[f"value.{column}"].dropna().to_numpy() * 1e3, floor)
        bx.hist(np.log10(e), bins=60, color=color, alpha=0.7, label=f"eq. (40) {form}")
    bx.set_xlabel("log10 ‖FK(IK(p)) − p‖ [mm]")
    bx.set_ylabel("leg poses")
    bx.set_title(f"over {len(ws)} random leg poses")
    bx.legend(fontsize=7)
    figs.save(fig, "ik-round-trip")


# -- stand ----------------------------------------------------------------------------------------------------------


def _pose_points(leg: Leg, layout: Layout, q: np.ndarray, height: float) -> dict[str, np.ndarray]:
    """Stick-figure points of a pose q (4, 3), trunk level at `height`."""
    hips = layout.hips
    knees = hips + leg_to_body(fk(Leg(leg.L1, leg.L2, 0.0), q))
    femur = hips + leg_to_body(fk(Leg(leg.L1, 0.0, 0.0), q))
    feet = feet_in_body(leg, layout, q)
    lift = np.array([0.0, 0.0, height])
    out = {name: np.stack([hips[i], femur[i], knees[i], feet[i]]) + lift for i, name in enumerate(LEGS)}
    out["trunk"] = np.stack([hips[i] for i in (0, 1, 3, 2, 0)]) + lift
    return out


def table5_poses(runs: list[Run], figs: Figures) -> None:
    """Fig. 16: the ideal and standing poses of Table 5 (side and front), the MuJoCo robot as it settled (grey),
    and its servo torques against the hand statics and the stall torque."""
    run = next((r for r in runs if r.metadata["case"] == "robot"), runs[0])
    system = run.config["system"]
    leg = Leg(system["leg"]["L1"], system["leg"]["L2"], system["leg"]["L3"])
    layout = Layout(system["body"]["length"], system["body"]["hip_width"])
    sign = np.asarray(system["table5"]["femur_sign"])
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), gridspec_kw={"width_ratios": [1.3, 1, 1.6]})
    for state, dx in (("ideal", -0.45), ("standing", 0.0)):
        t5 = system["table5"][f"{state}_deg"]
        q = np.radians(np.column_stack([t5["coxa"], np.asarray(t5["femur"]) * sign, t5["tibia"]]))
        height = -feet_in_body(leg, layout, q)[:, 2].min() + system["body"]["foot_radius"]
        points = _pose_points(leg, layout, q, height)
        for plane, ax, shift in (((0, 2), axes[0], dx), ((1, 2), axes[1], dx * 0.6)):
            moved = {k: v + np.array([shift, shift, 0.0]) for k, v in points.items()}
            draw_robot(ax, moved, plane)
            ax.text(moved["trunk"][:4, plane[0]].mean(), height + 0.02, state, ha="center", fontsize=8)
    settled = skeleton(run, -1)
    base = settled["trunk"][:4, :2].mean(axis=0)
    settled = {k: v - np.array([base[0], base[1], 0.0]) for k, v in settled.items()}
    draw_robot(axes[0], settled, (0, 2), color="0.5", alpha=0.6)
    draw_robot(axes[1], settled, (1, 2), color="0.5", alpha=0.6)
    for ax, label in ((axes[0], "x [m] (side view)"), (axes[1], "y [m] (front view)")):
        ax.axhline(0, color="k", lw=0.8)
        ax.set_ylim(-0.01, 0.36)
        ax.set_aspect("equal")
        ax.set_xlabel(label)
    axes[0].set_ylabel("z [m]")
    axes[0].set_title("Table 5 / Fig. 16: ideal and standing (grey: MuJoCo, settled)", fontsize=9)
    tau = columns(run["/joint_state"], "effort", JOINT_NAMES)[-200:].mean(axis=0)
    hand = columns(run["/statics/torque"], "settled", JOINT_NAMES)[-1]
    x = np.arange(len(JOINT_NAMES))
    ax = axes[2]
    ax.bar(x - 0.2, np.abs(tau), 0.4, label="MuJoCo servo torque")
    ax.bar(x + 0.2, np.abs(hand), 0.4, label="hand statics (settled pose)")
    ax.axhline(system["servo"]["stall_torque"], color="C3", ls="--", label="SPT5535LV stall torque")
    ax.set_xticks(x, JOINT_NAMES, rotation=60, fontsize=7)
    ax.set_ylabel("|τ| [N·m]")
    ax.set_title("standing torques, robot only", fontsize=9)
    ax.legend(fontsize=7)
    figs.save(fig, "fig16-table5-poses")


# -- body poses -----------------------------------------------------------------------------------------------------


def body_poses(run: Run, figs: Figures) -> None:
    """Fig. 18: the stance and scenarios 2-12 at the middle of each hold (side view for x, z, pitch; front view
    for y, roll; top view for yaw), and commanded vs achieved trunk offsets over time."""
    holding = run["/scenario"]["value.holding"].to_numpy().astype(int)
    tf_t = run["/tf"].index.to_numpy()
    names = ["1 stand", "2 +x", "3 −x", "4 +y", "5 −y", "6 −z", "7 +pitch", "8 −pitch", "9 +roll", "10 −roll",
             "11 +yaw", "12 −yaw"]
    planes = [(0, 2), (0, 2), (0, 2), (1, 2), (1, 2), (0, 2), (0, 2), (0, 2), (1, 2), (1, 2), (0, 1), (0, 1)]
    fig, axes = plt.subplots(2, 6, figsize=(15, 5))
    t = run["/body"].index.to_numpy()
    settle = run.config["scenario"]["settle"]
    reference = skeleton(run, int(np.argmin(np.abs(tf_t - settle))))
    for k, ax in enumerate(axes.ravel()):
        if k == 0:
            when = settle
        else:
            held = t[holding == k]
            when = held[len(held) // 2]
        points = skeleton(run, int(np.argmin(np.abs(tf_t - when))))
        draw_robot(ax, reference, planes[k], color="0.75")
        draw_robot(ax, points, planes[k])
        ax.set_aspect("equal")
        ax.set_title(f"{names[k]} (t = {when:.1f} s)", fontsize=8)
        ax.tick_params(labelsize=6)
    fig.suptitle("Fig. 18: body translations and rotations by body IK (grey: the settled stance)", fontsize=9)
    figs.save(fig, "fig18-body-poses")

    b = run["/body"]
    ref = run["/reference/body"]
    settle = run.config["scenario"]["settle"]
    stance = (t > settle - 0.1) & (t <= settle)
    fig, axes = plt.subplots(2, 3, figsize=(12, 4.6), sharex=True)
    for ax, name in zip(axes.ravel(), ("x", "y", "z", "roll", "pitch", "yaw"), strict=True):
        scale, unit = (1e3, "mm") if name in "xyz" else (180 / np.pi, "deg")
        achieved = (b[name] - b[name][stance].mean()) * scale
        ax.plot(ref.index, ref[f"position.{name}"] * scale, "k--", lw=1, label="commanded")
        ax.plot(b.index, achieved, "C0", label="MuJoCo trunk")
        ax.set_ylabel(f"{name} [{unit}]")
    axes[0, 0].legend(fontsize=7)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    fig.suptitle("Fig. 18 scenarios 2-12: trunk offset from the settled stance, commanded and achieved", fontsize=9)
    figs.save(fig, "fig18-tracking")


# -- self-levelling -------------------------------------------------------------------------------------------------


def self_levelling(runs: list[Run], figs: Figures) -> None:
    """Figs. 19-20: the bench tilts to 9°; the trunk's pitch (roll) with the IMU loop on and off, and the joints
    that do the work (femur and tibia for pitch, coxa for roll)."""
    axes_of = sorted({r.metadata["case"].split("-")[0] for r in runs})      # pitch (Fig. 19), roll (Fig. 20)
    fig, axes = plt.subplots(2, len(axes_of), figsize=(6 * len(axes_of), 5.6), sharex=True, squeeze=False)
    for col, axis in enumerate(axes_of):
        top, bottom = axes[0, col], axes[1, col]
        for run in sorted((r for r in runs if r.metadata["case"].startswith(axis)), key=lambda r: r.run_id):
            b = run["/body"]
            style = "-" if "levelled" in run.run_id else ":"
            top.plot(b.index, np.degrees(b[axis]), style, label=f"trunk {axis}, {run.run_id}")
            if "levelled" in run.run_id:
                bench = run["/platform"][axis]
                top.plot(bench.index, np.degrees(bench), "k--", lw=1, label=f"bench {axis}")
                js = run["/joint_state"]
                shown = ["FR_coxa", "FL_coxa"] if axis == "roll" else ["FR_femur", "FR_tibia", "BR_femur", "BR_tibia"]
                for name in shown:
                    q = np.degrees(js[f"position.{name}"])
                    bottom.plot(js.index, q - q.iloc[0], label=name)
        band = runs[0].config["scenario"]["level_band_deg"]
        top.axhspan(-band, band, color="C2", alpha=0.15, label=f"level ±{band:g}°")
        top.set_ylabel("[deg]")
        top.set_title(f"Fig. {'19' if axis == 'pitch' else '20'}: {axis} test", fontsize=9)
        top.legend(fontsize=7)
        bottom.set_ylabel("joint change, levelled [deg]")
        bottom.set_xlabel("t [s]")
        bottom.legend(fontsize=7)
    figs.save(fig, "fig19-20-self-levelling")


# -- trot -----------------------------------------------------------------------------------------------------------


def trot(run: Run, figs: Figures) -> None:
    timing = trot_timing(run)
    b = run["/body"]
    t = b.index.to_numpy()
    # Fig. 22 and Fig. 12a
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 3.8))
    for name, color in (("roll", "C0"), ("pitch", "C1")):
        ax.plot(t, np.degrees(b[name]), color=color, label=f"{name}, MuJoCo")
        low, high = (paper_value(SLUG, f"imu.trot.{name}_{end}", "deg") for end in ("min", "max"))
        ax.axhspan(low, high, color=color, alpha=0.12,
                   label=f"paper: {name} range of the real robot ({low:g}…{high:g}°)")
    ax.axvline(timing["trot_start"], color="k", lw=0.8, ls=":")
    ax.axvline(timing["steady_start"], color="k", lw=0.8, ls="--")
    ax.set_xlabel("t [s] (dotted: trot starts; dashed: steady window)")
    ax.set_ylabel("[deg]")
    ax.set_title(f"Fig. 22: trunk roll and pitch, trot (cycle {timing['cycle_time']:g} s)", fontsize=9)
    ax.legend(fontsize=6, ncol=2)
    measured, ref = feet(run), feet(run, "/reference/feet", "position")
    last = t >= t[-1] - 2 * timing["cycle_time"]
    for i, leg in enumerate(("FL", "BR")):
        k = LEGS.index(leg)
        bx.plot(ref[last, k, 2] * 1e3, ref[last, k, 1] * 1e3, "--", color=f"C{i}", lw=1, label=f"{leg} reference")
        bx.plot(measured[last, k, 2] * 1e3, measured[last, k, 1] * 1e3, color=f"C{i}",
                label=f"{leg} MuJoCo (FK of joints)")
    bx.set_xlabel("forward [mm] (leg frame)")
    bx.set_ylabel("up [mm]")
    bx.set_aspect("equal")
    bx.set_title("Fig. 12a: foot paths over the last two cycles", fontsize=9)
    bx.legend(fontsize=7)
    figs.save(fig, f"fig22-trot-{run.run_id}")

    # joints, torques, contact forces over two steady cycles
    window = (t >= timing["steady_start"]) & (t <= timing["steady_start"] + 2 * timing["cycle_time"])
    fig, axes = plt.subplots(1, 3, figsize=(15, 3.6))
    js, cmd = run["/joint_state"], run["/command"]
    for j, name in enumerate(("FL_coxa", "FL_femur", "FL_tibia")):
        axes[0].plot(t[window], np.degrees(cmd[f"value.{name}"].to_numpy()[window]), "--", color=f"C{j}", lw=1)
        axes[0].plot(t[window], np.degrees(js[f"position.{name}"].to_numpy()[window]), color=f"C{j}", label=name)
    axes[0].set_ylabel("[deg] (dashed: servo command)")
    axes[0].set_title("FL joints", fontsize=9)
    limit = run.config["system"]["servo"]["stall_torque"]
    for j, name in enumerate(("FL_coxa", "FL_femur", "FL_tibia")):
        axes[1].plot(t[window], js[f"effort.{name}"].to_numpy()[window], color=f"C{j}", label=name)
    for sign in (1, -1):
        axes[1].axhline(sign * limit, color="C3", ls="--", lw=1)
    axes[1].set_ylabel("servo torque [N·m] (dashed: stall torque)")
    axes[1].set_title("FL servo torques", fontsize=9)
    fz = columns(run["/wrench"], "force_z", LEGS)
    for leg in LEGS:
        axes[2].plot(t[window], fz[window, LEGS.index(leg)], color=LEG_COLORS[leg], label=leg)
    axes[2].plot(t[window], fz[window].sum(axis=1), "k", lw=1, label="Σ f_z")
    axes[2].axhline(robot_mass(run) * 9.81, color="k", ls=":", lw=1, label="m g")
    axes[2].set_ylabel("vertical ground reaction [N]")
    axes[2].set_title("contact forces (/wrench)", fontsize=9)
    for ax in axes:
        ax.set_xlabel("t [s]")
        ax.legend(fontsize=7)
    figs.save(fig, f"trot-joints-{run.run_id}")

    # Fig. 21: eight frames of one cycle, side view
    tf_t = run["/tf"].index.to_numpy()
    frames = timing["steady_start"] + np.arange(8) * timing["cycle_time"] / 8
    fig, axes = plt.subplots(1, 8, figsize=(16, 2.2), sharey=True)
    for ax, when in zip(axes, frames, strict=True):
        points = skeleton(run, int(np.argmin(np.abs(tf_t - when))))
        x0 = points["trunk"][:, 0].mean()
        draw_robot(ax, {k: v - np.array([x0, 0.0, 0.0]) for k, v in points.items()}, (0, 2))
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xlim(-0.3, 0.3)
        ax.set_xticks([-0.2, 0.0, 0.2])
        ax.set_aspect("equal")
        ax.set_title(f"t = {when:.2f} s", fontsize=8)
        ax.tick_params(labelsize=6)
    fig.suptitle("Fig. 21: one trot cycle, side view (FL blue, FR red, BL green, BR orange)", fontsize=9)
    figs.save(fig, f"fig21-trot-sequence-{run.run_id}")
