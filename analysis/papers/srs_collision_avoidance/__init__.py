"""Analysis of `srs-collision-avoidance`: Figs. 5-14 and the clearance, smoothness and tracking metrics of the
circle task, the filter ablation, and the per-iteration compute time."""

from analysis.papers.srs_collision_avoidance.analyses import ANALYSES
from analysis.papers.srs_collision_avoidance.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
