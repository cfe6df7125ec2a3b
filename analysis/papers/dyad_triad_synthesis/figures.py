"""Figures of `dyad-triad-synthesis`: the paper's Figs. 10-15 regenerated from the runs, plus the defect
map of the four-bar, the servo runs, the solution counts and the solver times. Lengths are drawn in the
units of Table 4 (the runs are in m)."""

from __future__ import annotations

import math

import numpy as np
import yaml

from analysis.core.figures import Figures, paper_vline, plt
from analysis.core.targets import paper_value
from analysis.papers.dyad_triad_synthesis.metrics import METHODS, case, roots, scalars, vectors
from pipeline.core.runlog import Run

SLUG = "dyad-triad-synthesis"
ROOT_COLORS = {"trivial": "0.5", "special": "C1", "solution": "C3", "degenerate": "C4"}
BRANCH_STYLE = {"+1": dict(color="C0", label="assembly +1"), "-1": dict(color="C2", label="assembly −1")}


def _unit(run: Run) -> float:
    return float(run.config["system"]["length_unit"])


def _chain(start: complex, links: list[complex]) -> np.ndarray:
    return start + np.concatenate([[0], np.cumsum(links)])


def _draw_loops(ax, delta: dict[str, complex], beta: np.ndarray, rotation: float, unit: float, title: str) -> None:
    """Both compatibility loops from the head G of Δ1 (Fig. 10), the Δ' loop turned by `rotation` (Fig. 11);
    at a root β, Δ3 and Δ3' have turned by the same β3 (the paper's CD ∥ BE)."""
    e = np.exp(1j * beta)
    g = delta["Δ1"]
    outer = _chain(0, [delta["Δ1"], delta["Δ2"] * e[1], delta["Δ3"] * e[2], delta["Δ4"] * e[3]]) / unit
    rho = np.exp(1j * rotation)
    inner = _chain(g, [rho * delta["Δ2'"] * e[1], rho * delta["Δ3'"] * e[2], rho * delta["Δ4"] * e[4],
                       rho * delta["Δ1'"]]) / unit
    ax.plot(outer.real, outer.imag, "-o", color="C0", ms=3, label="Δ loop")
    ax.plot(inner.real, inner.imag, "-o", color="C3", ms=3, label="Δ' loop")
    for a, b, name in ((outer[2], outer[3], "Δ3"), (inner[1], inner[2], "Δ3'")):
        ax.plot([a.real, b.real], [a.imag, b.imag], lw=3, alpha=0.4, color="k")
        ax.text(((a + b) / 2).real, ((a + b) / 2).imag, name, fontsize=7)
    ax.plot(g.real / unit, g.imag / unit, "k^", ms=6)
    ax.set_title(title, fontsize=8)
    ax.set_aspect("equal", adjustable="datalim")


def table5(runs: list[Run], figures: Figures) -> None:
    for run in runs:
        unit = _unit(run)
        delta = vectors(run, "/synthesis/delta")
        found = roots(run)
        rotation = math.remainder(np.angle(delta["Δ2"]) - np.angle(delta["Δ2'"]), 2 * math.pi)
        dyads = found[found["label"] == "solution"].sort_values("W", key=lambda s: s.abs())
        zero = np.zeros(5)
        panels = [(zero, 0.0, "Fig. 10: the two Δ loops (G: head of Δ1)"),
                  (zero, rotation, f"Fig. 11: Δ' loop turned {np.degrees(rotation):.2f}°"),
                  *((d["beta"], rotation, f"Fig. 13, root {name}: β2 = {np.degrees(d['beta'][1]):.2f}°, "
                                          f"β3 = {np.degrees(d['beta'][2]):.2f}°")
                    for name, (_, d) in zip("AB", dyads.iterrows(), strict=False))]
        fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.4))
        for ax, (beta, rot, title) in zip(np.atleast_1d(axes), panels, strict=True):
            _draw_loops(ax, delta, beta, rot, unit, title)
        np.atleast_1d(axes)[0].legend(fontsize=7)
        figures.save(fig, "fig10-13-compatibility-linkage")

        # Fig. 12: where the loops close, and the roots of the second compatibility equation
        sweep = scalars(run, "/synthesis/sweep")
        ranges = scalars(run, "/synthesis/beta2_range").iloc[0]
        names = {r["beta"][1]: r["label"] for _, r in found.iterrows()}
        for k, (_, d) in enumerate(dyads.iterrows()):
            names[d["beta"][1]] = "AB"[k] if k < 2 else str(k)
        fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), gridspec_kw={"width_ratios": [1.6, 1]})
        b2 = np.degrees(sweep["beta2"])
        for ax, zoom in zip(axes, (False, True), strict=True):
            for b, style in BRANCH_STYLE.items():
                ax.plot(b2, sweep[f"residual.branch{b}"] / unit, **style)
            for loop, color, y in (("delta", "C0", 0.95), ("delta_prime", "C3", 0.9), ("both", "k", 0.85)):
                for k in range(8):
                    if f"{loop}.{k}.lo" in ranges:
                        lo, hi = np.degrees([ranges[f"{loop}.{k}.lo"], ranges[f"{loop}.{k}.hi"]])
                        ax.plot([lo, hi], [y, y], transform=ax.get_xaxis_transform(), color=color, lw=4, alpha=0.6,
                                solid_capstyle="butt", label={"delta": "Δ loop closes", "delta_prime":
                                                              "Δ' loop closes", "both": "both close"}[loop]
                                if k == 0 else None)
            for x, label in names.items():
                color = ROOT_COLORS["solution" if label in "AB" else label]
                ax.axvline(np.degrees(x), color=color, ls=":", lw=1)
                ax.text(np.degrees(x), 0.03, f" {label}", rotation=90, fontsize=7,
                        transform=ax.get_xaxis_transform(), color=color)
            for end in ("upper", "lower"):
                x = paper_value(SLUG, f"S2.5.beta2.{end}", "deg")
                paper_vline(ax, x, label=None, lw=0.8)
                if not zoom or abs(x) < 35:
                    ax.text(x, 0.75, f" paper: {x:+g}°", fontsize=7, transform=ax.get_xaxis_transform())
            ax.axhline(0, color="k", lw=0.5)
            ax.set_xlabel("β2 [deg]")
            if zoom:
                ax.set_xlim(-35, 35)
                ax.set_ylim(-0.25, 0.25)
                ax.set_title("zoom on the roots", fontsize=8)
        axes[0].set_ylabel("loop-2 closure residual [Table 4 units]")
        axes[0].set_title("Fig. 12: |Δ1' + Δ2' e^{iβ2} + Δ3' e^{iβ3}| − |Δ4| as loop 1 moves", fontsize=9)
        axes[0].legend(fontsize=7, ncol=2, loc="center left")
        figures.save(fig, "fig12-beta2-sweep")


def burmester_curves(runs: list[Run], figures: Figures) -> None:
    for run in runs:
        unit = _unit(run)
        curves = scalars(run, "/burmester/curves")
        points = np.array(list(vectors(run, "/burmester/positions").values())) / unit
        fig, ax = plt.subplots(figsize=(7, 6))
        for b, _style in BRANCH_STYLE.items():
            ok = curves[f"conditioning.branch{b}"] > 1e-6
            c = curves.loc[ok]
            ax.plot(c[f"center.x.branch{b}"] / unit, c[f"center.y.branch{b}"] / unit, ".", ms=1.5, color="C0",
                    label="centre-point curve" if b == "+1" else None)
            ax.plot(c[f"circle.x.branch{b}"] / unit, c[f"circle.y.branch{b}"] / unit, ".", ms=1.5, color="C3",
                    label="circle-point curve" if b == "+1" else None)
        for topic, marker, color, label in (("/burmester/poles", "s", "C0", "poles P_jk"),
                                            ("/burmester/image_poles", "D", "C3", "image poles P'_jk"),
                                            ("/burmester/pi_points", "x", "C0", "Π points (eq. 23, corrected)"),
                                            ("/burmester/image_pi_points", "+", "C3", "Π' points (eq. 24)")):
            named = vectors(run, topic)
            z = np.array(list(named.values())) / unit
            ax.plot(z.real, z.imag, marker, color=color, mfc="none", ms=6, label=label)
            if "pi" not in topic:
                for name, v in zip(named, z, strict=True):
                    ax.text(v.real, v.imag, " " + name, fontsize=7, color=color)
        ax.plot(points.real, points.imag, "k*", ms=8, label="precision points")
        shown = np.concatenate([points, np.array(list(vectors(run, "/burmester/poles").values())) / unit,
                                np.array(list(vectors(run, "/burmester/image_poles").values())) / unit])
        lo, hi = shown.real.min() + 1j * shown.imag.min(), shown.real.max() + 1j * shown.imag.max()
        pad = 0.25 * max((hi - lo).real, (hi - lo).imag)
        ax.set_xlim(lo.real - pad, hi.real + pad)
        ax.set_ylim(lo.imag - pad, hi.imag + pad)
        ax.set_aspect("equal")
        ax.set_xlabel("x [Table 4 units]")
        ax.set_ylabel("y")
        ax.set_title("Figs. 7/15: Burmester curves of positions 1-4 of Table 4 from the compatibility four-bar",
                     fontsize=9)
        ax.legend(fontsize=7, loc="upper left")
        figures.save(fig, "fig15-burmester-curves")


def four_bar(runs: list[Run], figures: Figures) -> None:
    by_case = {case(r): r for r in runs}
    defects, replay = by_case.get("defects"), by_case.get("replay-1to5")
    if defects is not None and replay is not None:
        unit = _unit(replay)
        tf = replay["/tf"]
        pp = scalars(replay, "/precision_position")
        circuit = scalars(defects, "/circuit")
        fig, ax = plt.subplots(figsize=(8, 5.5))
        ax.plot(circuit["tracer.x"] / unit, circuit["tracer.y"] / unit, color="0.5", lw=1, ls="--",
                label="tracer, whole circuit (closed form; 5→1 not replayed)")
        tracer = tf[["transforms.tracer.translation.x", "transforms.tracer.translation.y"]].to_numpy() / unit
        ax.plot(tracer[:, 0], tracer[:, 1], color="C3", lw=1.5, label="Exudyn replay 1→2→3→4→5")
        pivots = {k: complex(*v) for k, v in yaml.safe_load(replay.attachments["model.yaml"])["pivots_m"].items()}
        js = replay["/joint_state"]
        for k, t in enumerate(pp.index):
            q = js.iloc[int(np.argmin(np.abs(js.index.to_numpy() - t)))]
            a1 = pivots["a0"] + (pivots["a1"] - pivots["a0"]) * np.exp(1j * q["position.crank_A"])
            b1 = pivots["b0"] + (pivots["b1"] - pivots["b0"]) * np.exp(1j * q["position.rocker_B"])
            p = a1 + (pivots["p"] - pivots["a1"]) * np.exp(1j * q["position.coupler"])
            chain = np.array([pivots["a0"], a1, p, b1, a1, b1, pivots["b0"]]) / unit
            shade = 0.45 + 0.1 * k
            ax.plot(chain.real, chain.imag, "-", color=(shade, shade, 0.9), lw=0.8, zorder=1)
            ax.text(p.real / unit, p.imag / unit, f" {k + 1}", fontsize=8)
        ground = np.array([pivots["a0"], pivots["b0"]]) / unit
        ax.plot(ground.real, ground.imag, "k^", ms=9, label="ground pivots")
        ax.plot(pp["target.x"] / unit, pp["target.y"] / unit, "k*", ms=9, label="Table 4")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [Table 4 units]")
        ax.set_ylabel("y")
        ax.legend(fontsize=7)
        ax.set_title("Fig. 14: the four-bar of dyads A and B at the five positions", fontsize=9)
        figures.save(fig, "fig14-four-bar")

    if defects is not None:
        circuit = scalars(defects, "/circuit")
        d = scalars(defects, "/defects").iloc[0]
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
        for ax, link, driver in zip(axes, ("rocker_B", "crank_A"), "BA", strict=True):
            x = np.degrees(np.unwrap(circuit[link].to_numpy()))
            ax.plot(x, np.degrees(circuit["coupler"]), color="0.4", lw=1)
            ax.set_xlabel(f"{link} rotation β [deg]")
            ax.set_ylabel("coupler rotation α [deg]")
            branches = [int(d[f"{driver}.branch.{j}"]) for j in range(1, 6)]
            ax.set_title(f"driver {driver}: poses on assembly " + ", ".join(f"{j}:{b:+d}" for j, b in
                                                                          enumerate(branches, start=1)), fontsize=8)
        if replay is not None:
            pp = scalars(replay, "/precision_position")
            js = replay["/joint_state"]
            for ax, link in zip(axes, ("rocker_B", "crank_A"), strict=True):
                rot = np.degrees(np.unwrap(js[f"position.{link}"].to_numpy()))
                ax.plot(rot, np.degrees(js["position.coupler"]), color="C3", lw=1, alpha=0.7, label="Exudyn replay")
                for j, t in zip(pp["position"].astype(int), pp.index, strict=True):
                    k = int(np.argmin(np.abs(js.index.to_numpy() - t)))
                    ax.plot(rot[k], np.degrees(js["position.coupler"].iloc[k]), "k*")
                    ax.text(rot[k], np.degrees(js["position.coupler"].iloc[k]), f" {j}", fontsize=8)
            axes[0].legend(fontsize=7)
        figures.save(fig, "branches")

    servos = [r for r in runs if case(r).startswith("servo-")]
    if servos:
        fig, axes = plt.subplots(2, 1, figsize=(7.5, 5), sharex=True)
        for k, run in enumerate(servos):
            err = run["/tracking_error"]
            axes[0].plot(err.index, np.degrees(err["error.driver"]), color=f"C{k}",
                         label=case(run).removeprefix("servo-2to5-"))
            cmd = run["/command"]
            axes[1].plot(cmd.index, cmd["value.rocker_B"], color=f"C{k}")
        axes[0].set_ylabel("rocker error q_ref − q [deg]")
        axes[0].set_yscale("symlog", linthresh=1e-4)
        axes[0].legend(fontsize=7)
        axes[1].set_ylabel("rocker torque [N m]")
        axes[1].set_xlabel("t [s]")
        axes[0].set_title("Exudyn four-bar, rocker servo along positions 2→5 (quintic 2 s, then held)", fontsize=9)
        figures.save(fig, "servo-2to5")


def round_trips(runs: list[Run], figures: Figures) -> None:
    by_case = {case(r): r for r in runs}
    counts = by_case.get("solution-counts")
    triad7 = by_case.get("triad-7pp")
    if counts is None and triad7 is None:
        return
    fig, axes = plt.subplots(1, 2, figsize=(8, 3.2))
    if counts is not None:
        d = scalars(counts, "/solution_count")
        axes[0].hist(d["real_dyads"], bins=np.arange(-0.5, 7), rwidth=0.8, color="C0")
        axes[0].set_title(f"dyad, 5 PP: real dyads of {len(d)} random problems", fontsize=8)
    if triad7 is not None:
        d = scalars(triad7, "/round_trip")
        axes[1].hist(d["solutions"], bins=np.arange(-0.5, 11), rwidth=0.8, color="C3")
        axes[1].set_title(f"triad, 7 PP: real triads of {len(d)} random chains", fontsize=8)
    for ax in axes:
        ax.yaxis.get_major_locator().set_params(integer=True)
        ax.set_xlabel("real solutions (special roots excluded)")
        ax.set_ylabel("problems")
    figures.save(fig, "solution-counts")


def compute_time(runs: list[Run], figures: Figures) -> None:
    for run in runs:
        times = run["/compute_time"]
        fig, ax = plt.subplots(figsize=(6.5, 3.2))
        data = []
        for m in METHODS:
            x = times[[c for c in times.columns if c.startswith(f"seconds.{m}.")]].to_numpy(dtype=float).ravel()
            data.append(x[np.isfinite(x)] * 1e3)
        ax.boxplot(data, tick_labels=[m.replace("_", " ") for m in METHODS], showfliers=True)
        ax.set_yscale("log")
        ax.set_ylabel("time per complete solve [ms]")
        ax.set_title("dyad in 5 PP: one solve of every problem, three methods (this machine)", fontsize=9)
        figures.save(fig, "solver-times")
