"""Analysis of `cobot-6r-ik`: Tables 2–3 from the `tables` runs, completeness on random poses, compute
time beside the peers, Cartesian paths executed in MuJoCo."""

from analysis.papers.cobot_6r_ik.completeness import analyze_completeness
from analysis.papers.cobot_6r_ik.compute_time import analyze_compute_time
from analysis.papers.cobot_6r_ik.report import report_sections
from analysis.papers.cobot_6r_ik.tables import analyze_tables
from analysis.papers.cobot_6r_ik.trajectory import analyze_trajectory

ANALYSES = {"tables": analyze_tables, "completeness": analyze_completeness, "compute-time": analyze_compute_time,
            "trajectory": analyze_trajectory}

__all__ = ["ANALYSES", "report_sections"]
