"""The numerical example (Tables 2–3) from the `tables` runs: pose, points, Λ's roots, every real root's
back-substitution (ours and the paper's own path), the solutions, and the FK check of the printed rows."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from analysis.core.targets import load_targets
from pipeline.core.runlog import Run
from pipeline.papers.cobot_6r_ik.kinematics import Geometry, fk
from pipeline.robotics import dh as dhk

TARGETS = Path(__file__).with_name("targets.csv")
REAL = 1e-9   # |Im c1| ≤ REAL·max(1, |c1|): a real root of Λ (spec §6.2)


def _geometry(run: Run) -> Geometry:
    """The run's geometry, with the d1 it used (P1 = (0, 0, d1)): the example-d1 case overrides Table 1's."""
    g = Geometry(**run.config["system"]["geometry"])
    return dataclasses.replace(g, d1=float(run["/example/points"]["value.P1.z"].iloc[0]))


def _angle(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """Rotation between R_a and a printed (rounded, so not quite orthonormal) R_b: from ‖R_a − R_b‖_F, which
    stays linear in the rounding where the trace formula's arccos would magnify it."""
    return 2 * np.arcsin(np.minimum(1.0, np.linalg.norm(R_a - R_b, axis=(-2, -1)) / (2 * np.sqrt(2))))


def printed_table3() -> tuple[np.ndarray, np.ndarray]:
    """The paper's Table 3 (16 × 6, deg) and eq. (32) (4 × 4, m), read from targets.csv."""
    t = load_targets(TARGETS).set_index("target_id")
    rows = np.array([[float(t.loc[f"T3.{r}.q{j}", "value"]) for j in range(1, 7)] for r in range(1, 17)])
    T = np.eye(4)
    for r in range(3):
        for c in range(4):
            T[r, c] = float(t.loc[f"E32.T{r + 1}{c + 1}", "value"])
    return rows, T


def analyze_tables(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        g = _geometry(run)
        values: dict[str, tuple[float, str]] = {}
        pose = run["/example/pose"].iloc[0]
        for r in range(3):
            for c in range(4):
                values[f"pose.T{r + 1}{c + 1}"] = (pose[f"value.T{r + 1}{c + 1}"], "m" if c == 3 else "1")
        points = run["/example/points"].iloc[0]
        values |= {k.removeprefix("value."): (v, "m") for k, v in points.items()}
        roots = run["/ik/roots"].iloc[0]
        n = len(roots) // 2
        re = np.array([roots[f"value.root{k + 1:02d}.re"] for k in range(n)])
        im = np.array([roots[f"value.root{k + 1:02d}.im"] for k in range(n)])
        for k in range(n):
            values[f"root{k + 1:02d}.re"] = (re[k], "1")
            values[f"root{k + 1:02d}.im"] = (im[k], "1")
        real = np.abs(im) <= REAL * np.maximum(1.0, np.abs(re))
        values["roots.count"] = (n, "count")
        values["roots.real"] = (int(real.sum()), "count")
        cands = run["/ik/candidates"]
        extraneous = 0
        for k, (_, c) in enumerate(cands.iterrows(), start=1):
            p = f"cand{k}"
            values[f"{p}.c1"] = (c["c1"], "1")
            for key in ("c2", "c2_eq29", "c3", "c3_paper"):
                values[f"{p}.{key}"] = (c[key], "1")
            for i, a in enumerate("xyz"):
                values[f"{p}.p4.{a}"] = (c[f"p4[{i}]"], "m")
                values[f"{p}.p4_paper.{a}"] = (c[f"p4_paper[{i}]"], "m")
            for t, twin in enumerate("ab"):
                for j in range(6):
                    values[f"{p}.q_{twin}.q{j + 1}"] = (c[f"q_{twin}[{j}]"], "rad")
                values[f"{p}.pos_err_{twin}"] = (c[f"pos_err[{t}]"], "m")
                values[f"{p}.solution_{twin}"] = (float(c[f"accepted[{t}]"] >= 1), "bool")
            extraneous += int(c["accepted[0]"] == 0 and c["accepted[1]"] == 0)
        sols = run["/ik/solutions"]
        ref = run["/ik/reference"]
        values["solutions.count"] = (len(sols), "count")
        values["extraneous.real_roots"] = (extraneous, "count")
        values["claim.no_extraneous_roots"] = (float(extraneous == 0), "bool")
        q_sol = sols.filter(like="position.").to_numpy()
        q_ref = ref.filter(like="position.").to_numpy()
        same = np.abs(np.remainder(q_sol[:, None] - q_ref[None] + np.pi, 2 * np.pi) - np.pi).max(axis=2) < 1e-6
        values["reference.count"] = (len(ref), "count")
        values["reference.common"] = (int(same.any(axis=1).sum()), "count")
        # consistency: the printed Table 3 rows through FK against the printed eq. (32)
        rows, T_printed = printed_table3()
        T_rows = fk(np.deg2rad(rows), g)
        for r in range(16):
            values[f"printed_row{r + 1}.pos_err"] = (np.linalg.norm(T_rows[r, :3, 3] - T_printed[:3, 3]), "m")
            values[f"printed_row{r + 1}.rot_err"] = (_angle(T_rows[r, :3, :3], T_printed[:3, :3]), "rad")
        m.add_run(run, values)
        _roots_figure(run, re, im, figures)
        _configurations_figure(run, q_sol, g, figures)
    return m.frame()


def _roots_figure(run: Run, re: np.ndarray, im: np.ndarray, figures: Figures) -> None:
    t = load_targets(TARGETS).set_index("target_id")
    paper_re = [float(t.loc[f"T2.root{k:02d}.re", "value"]) for k in range(1, 17)]
    paper_im = [float(t.loc[f"T2.root{k:02d}.im", "value"]) if f"T2.root{k:02d}.im" in t.index else 0.0
                for k in range(1, 17)]
    cands = run["/ik/candidates"]
    genuine = {round(c, 6) for c, a in zip(cands["c1"], cands["accepted[0]"], strict=True) if a >= 1}
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), gridspec_kw={"width_ratios": [2, 1]})
    for ax, xlim in zip(axes, (None, (-0.75, 0.05)), strict=True):
        ax.scatter(paper_re, paper_im, s=90, facecolors="none", edgecolors="k", label="paper, Table 2")
        is_gen = np.array([any(abs(x - gv) < 1e-3 for gv in genuine) and abs(y) < 1e-9 for x, y in
                           zip(re, im, strict=True)])
        ax.scatter(re[is_gen], im[is_gen], s=22, color="C2", label="ours: real root, genuine (a solution)")
        ax.scatter(re[~is_gen], im[~is_gen], s=22, color="C3", marker="x", label="ours: extraneous or complex")
        ax.set_xlabel("Re c1")
        if xlim:
            ax.set_xlim(*xlim)
            ax.set_title("zoom near 0")
    axes[0].set_ylabel("Im c1")
    axes[0].legend(fontsize=7)
    axes[0].set_title(f"{run.run_id}: the 16 roots of Λ (eq. 25)")
    figures.save(fig, f"{run.run_id}-roots")


def _configurations_figure(run: Run, q: np.ndarray, g: Geometry, figures: Figures) -> None:
    """The solutions as stick figures (the paper's Fig. 3 is an image only)."""
    F = dhk.frames(dhk.DH.from_config(g.dh), q)
    fig = plt.figure(figsize=(10, 5))
    for k in range(len(q)):
        ax = fig.add_subplot(2, (len(q) + 1) // 2, k + 1, projection="3d")
        p = F[k, :, :3, 3]
        ax.plot(p[:, 0], p[:, 1], p[:, 2], "-o", ms=3, lw=2)
        ax.plot([0, 0], [0, 0], [0, p[1, 2]], "k-", lw=3)
        ax.set_xlim(-1, 1)
        ax.set_ylim(-1, 1)
        ax.set_zlim(0, 1.6)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_zticks([])
        ax.set_title(np.array2string(np.rad2deg(q[k]), precision=0, separator=",", suppress_small=True), fontsize=6)
    fig.suptitle(f"{run.run_id}: the {len(q)} solutions of eq. (32) (the paper's Fig. 3 shows 16 rows of Table 3)")
    figures.save(fig, f"{run.run_id}-configurations")
