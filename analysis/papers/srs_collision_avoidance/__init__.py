"""Analysis of `srs-collision-avoidance`: Figs. 5-14 and the clearance, smoothness and tracking metrics of the
circle task, the filter ablation, and the per-iteration compute time."""

from analysis.papers.srs_collision_avoidance.analyses import analyze_ablation, analyze_circle, analyze_compute_time
from analysis.papers.srs_collision_avoidance.tables import report_sections

ANALYSES = {"circle": analyze_circle, "ablation": analyze_ablation, "compute-time": analyze_compute_time}

__all__ = ["ANALYSES", "report_sections"]
