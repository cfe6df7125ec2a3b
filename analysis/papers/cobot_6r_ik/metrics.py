"""What the analyses of `cobot-6r-ik` read from a run and the metrics they compute: the numerical example
(Tables 2-3, with the FK check of the printed rows), completeness on random poses, compute time beside the
peers, and the Cartesian paths executed in MuJoCo. Lengths in m, angles in rad."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from analysis.core.compute_time import timing_metrics
from analysis.core.targets import paper_value
from pipeline.core.runlog import Run
from pipeline.papers.cobot_6r_ik.kinematics import Geometry, fk

SLUG = "cobot-6r-ik"
REAL = 1e-9   # |Im c1| ≤ REAL·max(1, |c1|): a real root of Λ
METHODS = ("lambda16", "octic")
TIMED = ("lambda16", "lambda16_batch", "octic", "octic_batch", "crx", "ik_geo", "eaik", "rtb")

Values = dict[str, tuple[float, str]]


def geometry(run: Run) -> Geometry:
    """The run's geometry, with the d1 it used (P1 = (0, 0, d1)): the example-d1 case overrides Table 1's."""
    g = Geometry(**run.config["system"]["geometry"])
    return dataclasses.replace(g, d1=float(run["/example/points"]["value.P1.z"].iloc[0]))


def _angle(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """Rotation between R_a and a printed (rounded, so not quite orthonormal) R_b: from ‖R_a − R_b‖_F, which
    stays linear in the rounding where the trace formula's arccos would magnify it."""
    return 2 * np.arcsin(np.minimum(1.0, np.linalg.norm(R_a - R_b, axis=(-2, -1)) / (2 * np.sqrt(2))))


def printed_table3() -> tuple[np.ndarray, np.ndarray]:
    """The paper's Table 3 (16 × 6, deg) and eq. (32) (4 × 4, m), read from targets.csv."""
    rows = np.array([[paper_value(SLUG, f"T3.{r}.q{j}") for j in range(1, 7)] for r in range(1, 17)])
    T = np.eye(4)
    for r in range(3):
        for c in range(4):
            T[r, c] = paper_value(SLUG, f"E32.T{r + 1}{c + 1}")
    return rows, T


def roots(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """(Re, Im) of Λ's roots as logged."""
    logged = run["/ik/roots"].iloc[0]
    n = len(logged) // 2
    return (np.array([logged[f"value.root{k + 1:02d}.re"] for k in range(n)]),
            np.array([logged[f"value.root{k + 1:02d}.im"] for k in range(n)]))


def solutions(run: Run) -> np.ndarray:
    return run["/ik/solutions"].filter(like="position.").to_numpy()


def tables_metrics(run: Run) -> Values:
    """Eq. (32)'s pose, eq. (33)'s points, Λ's roots, every real root's back-substitution (ours and the paper's own
    path), the solutions against the multi-start reference, and the FK check of the printed Table 3 rows."""
    values: Values = {}
    pose = run["/example/pose"].iloc[0]
    for r in range(3):
        for c in range(4):
            values[f"pose.T{r + 1}{c + 1}"] = (pose[f"value.T{r + 1}{c + 1}"], "m" if c == 3 else "1")
    points = run["/example/points"].iloc[0]
    values |= {k.removeprefix("value."): (v, "m") for k, v in points.items()}
    re, im = roots(run)
    for k in range(len(re)):
        values[f"root{k + 1:02d}.re"] = (re[k], "1")
        values[f"root{k + 1:02d}.im"] = (im[k], "1")
    real = np.abs(im) <= REAL * np.maximum(1.0, np.abs(re))
    values["roots.count"] = (len(re), "count")
    values["roots.real"] = (int(real.sum()), "count")
    extraneous = 0
    for k, (_, c) in enumerate(run["/ik/candidates"].iterrows(), start=1):
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
    ref = run["/ik/reference"]
    q_sol, q_ref = solutions(run), ref.filter(like="position.").to_numpy()
    values["solutions.count"] = (len(q_sol), "count")
    values["extraneous.real_roots"] = (extraneous, "count")
    values["claim.no_extraneous_roots"] = (float(extraneous == 0), "bool")
    same = np.abs(np.remainder(q_sol[:, None] - q_ref[None] + np.pi, 2 * np.pi) - np.pi).max(axis=2) < 1e-6
    values["reference.count"] = (len(ref), "count")
    values["reference.common"] = (int(same.any(axis=1).sum()), "count")
    # consistency: the printed Table 3 rows through FK against the printed eq. (32)
    rows, T_printed = printed_table3()
    T_rows = fk(np.deg2rad(rows), geometry(run))
    for r in range(16):
        values[f"printed_row{r + 1}.pos_err"] = (np.linalg.norm(T_rows[r, :3, 3] - T_printed[:3, 3]), "m")
        values[f"printed_row{r + 1}.rot_err"] = (_angle(T_rows[r, :3, :3], T_printed[:3, :3]), "rad")
    return values


def generating_found(run: Run) -> dict[str, np.ndarray]:
    """Per method, whether each random pose's generating joints were found."""
    return {m: run[f"/completeness/{m}"]["value.generating_found"].to_numpy() > 0.5 for m in METHODS}


def completeness_metrics(run: Run) -> Values:
    """Per method (`lambda16.*` the paper's Λ with the FK filter, `octic.*` its genuine factor, ours): the generating
    joints and their twin found, the multi-start reference's solutions found, the roots the FK filter rejects, and
    which misses sit near the Cayley singularity."""
    ref = run["/completeness/reference"]
    near_c = float(run.config["scenario"]["near_singular_c"])
    values: Values = {}
    for method, found in generating_found(run).items():
        poses = run[f"/completeness/{method}"]
        n = poses["value.solutions"].to_numpy()
        twin = poses["value.twin_found"].to_numpy() > 0.5
        near = poses["value.c_generating"].to_numpy() > near_c
        agree = (ref[f"value.{method}.ours_only"] == 0) & (ref[f"value.{method}.reference_only"] == 0)
        values |= {f"{method}.{k}": v for k, v in {
            "poses": (len(n), "count"),
            "solutions.mean": (n.mean(), "count"), "solutions.max": (n.max(), "count"),
            "solutions.odd_poses": (int((n % 2 == 1).sum()), "count"),
            "generating_found.fraction": (found.mean(), "fraction"),
            "twin_found.fraction": (twin.mean(), "fraction"),
            "missed_poses": (int((~found).sum()), "count"),
            "near_singular.poses": (int(near.sum()), "count"),
            "near_singular.missed": (int((near & ~found).sum()), "count"),
            "real_roots.mean": (poses["value.real_roots"].mean(), "count"),
            "rejected_roots.mean": (poses["value.rejected_roots"].mean(), "count"),
            "reference.found_by_ours": (ref[f"value.{method}.common"].sum() / max(1, ref["value.reference"].sum()),
                                        "fraction"),
            "reference.ours_only": (ref[f"value.{method}.ours_only"].sum(), "count"),
            "reference.agree_fraction": (agree.mean(), "fraction"),
            "claim.all_found": (float(found.all() and agree.all()), "bool"),
        }.items()}
    values["reference.poses"] = (len(ref), "count")
    values["reference.solutions"] = (ref["value.reference"].sum(), "count")
    return values


def per_item(run: Run, name: str) -> np.ndarray:
    """Seconds per pose of one timed solver (empty if it was not timed)."""
    ct = run["/compute_time"]
    if f"seconds.{name}" not in ct:
        return np.zeros(0)
    return (ct[f"seconds.{name}"] / ct[f"calls.{name}"]).dropna().to_numpy()


def peers(run: Run) -> dict[str, dict]:
    """The peers the run tried: name -> label, version, whether available and why not, all solutions or not."""
    return json.loads(run.metadata.get("peers", "{}"))


def compute_time_metrics(run: Run) -> Values:
    """Median and p95 of every timed solver, the ratios of ours to the peers', and how the peers' solution sets
    compare with ours."""
    values: Values = {}
    for name in TIMED:
        t = per_item(run, name)
        if len(t):
            values |= timing_metrics(name, t)
    for name in peers(run):
        topic = f"/peers/{name}"
        if topic not in run.topic_names:
            continue
        p = run[topic]
        values |= {f"{name}.poses": (len(p), "count"), f"{name}.solutions": (p["value.solutions"].sum(), "count")}
        for method in METHODS:
            agree = (p[f"value.{method}.ours_only"] == 0) & (p[f"value.{method}.peer_only"] == 0)
            values |= {f"{name}.{method}.{k}": (p[f"value.{method}.{k}"].sum(), "count")
                       for k in ("common", "ours_only", "peer_only")}
            values[f"{name}.{method}.agree_fraction"] = (agree.mean(), "fraction")
    for name in ("crx", "ik_geo", "rtb"):
        for ours in ("lambda16", "lambda16_batch", "octic", "octic_batch"):
            if f"{name}.median" in values and f"{ours}.median" in values:
                values[f"ratio.{ours}_to_{name}"] = (values[f"{ours}.median"][0] / values[f"{name}.median"][0],
                                                     "ratio")
    same = run["/ik/octic_vs_lambda16"]
    values["octic.extra_over_lambda16"] = (same["value.octic_only"].sum(), "count")
    values["octic.missing_from_lambda16"] = (same["value.lambda16_only"].sum(), "count")
    return values


def trajectory_metrics(run: Run) -> Values:
    """Solutions per sample, the followed branch's joint jumps and FK error, and the MuJoCo execution's tracking."""
    s = run["/ik/samples"]
    threshold = float(run.config["execute"]["jump_threshold"])
    joint = run["/tracking_error"]["norm"].to_numpy()
    flange = run["/tracking_error/flange"]
    tau = run["/command"].filter(like="value.").to_numpy()
    limits = np.asarray(run.config["system"]["dynamics"]["torque_limit"])
    return {
        "samples": (len(s), "count"),
        "solutions.min": (s["count"].min(), "count"), "solutions.max": (s["count"].max(), "count"),
        "solutions.changes": (int((np.diff(s["count"].to_numpy()) != 0).sum()), "count"),
        "max_joint_jump": (s["jump"].max(), "rad"),
        "jumps": (int((s["jump"] > threshold).sum()), "count"),
        "max_ik_fk_error": (s["fk_error_position"].max(), "m"),
        "max_ik_fk_rotation_error": (s["fk_error_rotation"].max(), "rad"),
        "max_joint_error": (joint.max(), "rad"), "rms_joint_error": (np.sqrt(np.mean(joint ** 2)), "rad"),
        "max_flange_error": (flange["norm"].max(), "m"),
        "rms_flange_error": (np.sqrt(np.mean(flange["norm"].to_numpy() ** 2)), "m"),
        "max_flange_rotation_error": (flange["error.rotation"].max(), "rad"),
        "max_torque_ratio": ((np.abs(tau) / limits).max(), "ratio"),
    }
