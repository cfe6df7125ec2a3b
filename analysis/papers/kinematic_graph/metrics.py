"""Metrics of `kinematic-graph` from the runs: graph sizes (Table 1), search benchmarks, executed showcase plans.

Names: a Table 1 cell is `C<deg>_T<m>` (C2_T0.1); a benchmark group is `<graph>.<metric>` (kg.tspace, grid.cspace,
tonly.tspace). Explored shares are fractions (the targets show %).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from analysis.core.metrics import MetricTable
from analysis.core.targets import paper_value
from pipeline.core.runlog import Run

SLUG = "kinematic-graph"
PAPER_METRICS = ("cspace", "tspace", "manipulability")


def cell(c_res_rad: float, t_res: float) -> str:
    return f"C{round(math.degrees(c_res_rad), 6):g}_T{t_res:g}"


# -- Table 1 -------------------------------------------------------------------------------------------------------


def table1_metrics(run: Run) -> dict[str, tuple[float, str]]:
    size, ct = run["/kg/size"], run["/compute_time"]
    stages = [c for c in ct.columns if c.startswith("seconds.")]
    values: dict[str, tuple[float, str]] = {}
    for (_, row), (_, times) in zip(size.iterrows(), ct.iterrows(), strict=True):
        name = cell(row["c_res_rad"], row["t_res_m"])
        c_name = name.split("_")[0]
        histogram = row.filter(like="clusters_per_voxel").dropna().to_numpy()
        values |= {
            f"{name}.vertices": (row["vertices"], "count"), f"{name}.edges": (row["edges"], "count"),
            f"{name}.vertex_ratio": (row["vertices"] / row["grid_nodes"], "ratio"),
            f"{name}.edge_ratio": (row["edges"] / row["grid_edges"], "ratio"),
            f"{name}.occupied_voxels": (row["occupied_voxels"], "count"),
            f"{name}.components": (row["kg_components"], "count"),
            f"{name}.mean_degree": (2 * row["edges"] / row["vertices"], "count"),
            f"{name}.max_clusters_per_voxel": (float(np.flatnonzero(histogram)[-1]), "count"),
            f"{name}.construction_seconds": (float(times[stages].sum()), "s"),
            f"{c_name}.jv": (row["jv[0]"], "count"), f"{c_name}.grid_nodes": (row["grid_nodes"], "count"),
            f"{c_name}.grid_edges": (row["grid_edges"], "count"),
            f"{c_name}.grid_edges_closed_form": (row["grid_edges_closed_form"], "count"),
        }
        values |= {f"{name}.voxels_with_{k}_clusters": (float(n), "count") for k, n in enumerate(histogram) if k}
    branching = run["/kg/branching"].iloc[0]
    values |= {k.removeprefix("value."): (v, "count") for k, v in branching.items()}
    return values


def paper_consistency() -> dict[str, tuple[float, str]]:
    """Arithmetic on the paper's own printed numbers (basis `paper`): eqs. (5)-(7) at the printed |jv|, and the
    0.5° edge ratios of Table 1 recomputed from its printed counts."""
    values = {}
    for c in ("C2", "C1", "C0.5"):
        jv = paper_value(SLUG, f"jv.{c}")
        values[f"paper.eq6.{c}"] = (jv ** 2, "count")                       # eq. (6)
        values[f"paper.eq7.{c}"] = (4 * jv ** 2 - 6 * jv + 2, "count")      # eq. (7)
    values["paper.eq5.dim6"] = (3.0 ** 6 - 1, "count")                      # eq. (5)
    for t in ("0.1", "0.05", "0.03", "0.01"):
        edges = paper_value(SLUG, f"T1.C0.5_T{t}.edges")
        values[f"paper.C0.5_T{t}.edge_ratio.printed_denominator"] = (edges / paper_value(SLUG, "EC.C0.5"), "ratio")
        values[f"paper.C0.5_T{t}.edge_ratio.eq7_denominator"] = (edges / values["paper.eq7.C0.5"][0], "ratio")
    return values


# -- search benchmarks ------------------------------------------------------------------------------------------------


def _median(s: pd.Series) -> float:
    s = s.dropna()
    return float(s.median()) if len(s) else float("nan")


def benchmark_metrics(run: Run, mu_unit: str) -> dict[str, tuple[float, str]]:
    df = run["/kg/search"]
    values: dict[str, tuple[float, str]] = {}
    for (graph, metric), g in df.groupby(["graph", "metric"]):
        name = f"{graph}.{metric}"
        ok = g[g["found"]]
        values |= {
            f"{name}.queries": (len(g), "count"),
            f"{name}.success_rate": (g["found"].mean(), "fraction"),
            f"{name}.feasible_rate": ((g["found"] & g["collision_free"]).mean(), "fraction"),
            f"{name}.collision_free_rate": (ok["collision_free"].mean() if len(ok) else float("nan"), "fraction"),
            f"{name}.explored.median": (_median(g["explored_pct"]) / 100, "fraction"),
            f"{name}.explored.p05": (float(np.percentile(g["explored_pct"], 5)) / 100, "fraction"),
            f"{name}.explored.p95": (float(np.percentile(g["explored_pct"], 95)) / 100, "fraction"),
            f"{name}.expanded.median": (_median(g["expanded"]), "count"),
            f"{name}.met.median": (_median(g["met"] / g["vertices"]), "fraction"),
            f"{name}.expansions_per_vertex.max": (float((g["expansions"] / g["vertices"]).max()), "ratio"),
            f"{name}.path_vertices.median": (_median(ok["path_vertices"]), "count"),
            f"{name}.t_length.median": (_median(ok["t_length_m"]), "m"),
            f"{name}.c_length.median": (_median(ok["c_length_rad"]), "rad"),
            f"{name}.max_step.median": (_median(ok["max_step_rad"]), "rad"),
            f"{name}.max_step.max": (float(ok["max_step_rad"].max()) if len(ok) else float("nan"), "rad"),
            f"{name}.mean_mu.median": (_median(ok["mean_mu"]), mu_unit),
            f"{name}.min_mu.median": (_median(ok["min_mu"]), mu_unit),
            f"{name}.min_base_distance.median": (_median(ok["min_base_distance_m"]), "m"),
            f"{name}.min_clearance.median": (_median(ok["min_clearance_m"]), "m"),
        }
        values |= timing_metrics(f"{name}.time", g["seconds"])
        if graph == "kg":
            optimal = ok["optimal_cost"]
            values[f"{name}.suboptimality.median"] = (_median(ok["cost"] / optimal.where(optimal > 0)), "ratio")
            values[f"{name}.suboptimality.max"] = (float((ok["cost"] / optimal.where(optimal > 0)).max()), "ratio")
            admissible = g["h_start"] <= g["optimal_cost"] * (1 + 1e-9) + 1e-12
            values[f"{name}.admissible_start_rate"] = (admissible[g["found"]].mean(), "fraction")
            values[f"{name}.h_over_optimal.median"] = (_median(ok["h_start"] / optimal.where(optimal > 0)), "ratio")
    shares = df[df["graph"] == "kg"].pivot(index="query", columns="metric", values="explored_pct")
    values["kg.order.C_T_M.fraction"] = (float(((shares["cspace"] < shares["tspace"])
                                                & (shares["tspace"] < shares["manipulability"])).mean()), "fraction")
    values["kg.order.T_M_C.fraction"] = (float(((shares["tspace"] < shares["manipulability"])
                                                & (shares["manipulability"] < shares["cspace"])).mean()), "fraction")
    kg = {m: values.get(f"kg.{m}.explored.median", (float("nan"),))[0] for m in PAPER_METRICS}
    for a in PAPER_METRICS:
        for b in PAPER_METRICS:
            if a != b:
                values[f"kg.ratio.explored.{a}_over_{b}"] = (kg[a] / kg[b], "ratio")
    savings, speedups = [], []
    for m in PAPER_METRICS:
        if f"grid.{m}.expanded.median" in values:
            saving = values[f"grid.{m}.expanded.median"][0] / values[f"kg.{m}.expanded.median"][0]
            speedup = values[f"grid.{m}.time.median"][0] / values[f"kg.{m}.time.median"][0]
            values[f"saving.expanded.{m}"] = (saving, "ratio")
            values[f"speedup.time.{m}"] = (speedup, "ratio")
            savings.append(saving)
            speedups.append(speedup)
    if savings:
        values["claim.kg_explores_fewer"] = (float(min(savings) > 1), "bool")
        values["claim.kg_plans_faster"] = (float(min(speedups) > 1), "bool")
    mu = {m: values[f"kg.{m}.mean_mu.median"][0] for m in PAPER_METRICS}
    values["claim.manipulability_highest_mu"] = (float(mu["manipulability"] > max(mu["cspace"], mu["tspace"])), "bool")
    c_len = {m: values[f"kg.{m}.c_length.median"][0] for m in PAPER_METRICS}
    shortest = c_len["cspace"] < min(c_len["tspace"], c_len["manipulability"])
    values["claim.cspace_shortest_joint_path"] = (float(shortest), "bool")
    values["claim.cspace_lower_mu"] = (float(mu["cspace"] < mu["manipulability"]), "bool")
    base = {m: values[f"kg.{m}.min_base_distance.median"][0] for m in PAPER_METRICS}
    values["claim.tspace_nearest_base"] = (float(base["tspace"] < min(base["cspace"], base["manipulability"])), "bool")
    values["claim.eq12_admissible"] = (float(values["kg.manipulability.admissible_start_rate"][0] == 1.0), "bool")
    if "tonly.tspace.feasible_rate" in values:
        kg_feasible = min(values[f"kg.{m}.feasible_rate"][0] for m in PAPER_METRICS)
        values["claim.kg_more_feasible_than_tonly"] = (float(kg_feasible > values["tonly.tspace.feasible_rate"][0]),
                                                       "bool")
    scene = run["/kg/scene"].iloc[0]
    values |= {f"scene.{k.removeprefix('value.')}": (v, "s" if k.endswith("seconds") else "count")
               for k, v in scene.items() if k != "value.mu_max"}
    values["claim.kg_collision_mapping_faster"] = (
        float(scene["value.kg.check_seconds"] < scene["value.grid.check_seconds"]), "bool")
    return values


# -- showcases: a plan executed in MuJoCo ----------------------------------------------------------------------------


def showcase_metrics(run: Run, mu_unit: str) -> dict[str, tuple[float, str]]:
    record = run["/kg/search"].iloc[0]
    joint = run["/tracking_error"]
    pw = run["/tracking_error/pw"]
    t = joint.index.to_numpy()
    values = {"plan.explored": (record["explored_pct"] / 100, "fraction"),
              "plan.expanded": (record["expanded"], "count"), "plan.path_vertices": (record["path_vertices"], "count"),
              "plan.t_length": (record["t_length_m"], "m"), "plan.c_length": (record["c_length_rad"], "rad"),
              "plan.max_step": (record["max_step_rad"], "rad"), "plan.mean_mu": (record["mean_mu"], mu_unit),
              "plan.seconds": (record["seconds"], "s"), "duration": (float(t[-1]), "s"),
              "goal.ik_error": (run["/kg/goal"]["value.ik_error_m"].iloc[0], "m")}
    values |= error_stats(t, joint["norm"].to_numpy(), "tracking.joint", "rad")
    values |= error_stats(t, pw["norm"].to_numpy(), "tracking.pw", "m")
    if "/clearance" in run.topic_names:
        clearance = run["/clearance"]
        values["clearance.executed.min"] = (clearance["value.executed.min"].min(), "m")
        values["clearance.reference.min"] = (clearance["value.reference.min"].min(), "m")
    return values


def analyze_benchmarks(runs: list[Run], mu_unit: str) -> MetricTable:
    m = MetricTable()
    showcases = {}
    for run in runs:
        if run.metadata["case"].startswith("benchmark"):
            m.add_run(run, benchmark_metrics(run, mu_unit))
        else:
            values = showcase_metrics(run, mu_unit)
            m.add_run(run, values)
            showcases[run.run_id] = values
    obstacle = {k: v for k, v in showcases.items() if k.startswith("obstacle-")}
    if "obstacle-tspace-only" in obstacle:
        kg_clear = all(obstacle[f"obstacle-{x}"]["clearance.reference.min"][0] >= 0 for x in PAPER_METRICS
                       if f"obstacle-{x}" in obstacle)
        tonly_collides = obstacle["obstacle-tspace-only"]["clearance.reference.min"][0] < 0
        m.add("showcase", "claim.tonly_infeasible_kg_feasible", float(kg_clear and tonly_collides), "bool")
    return m
