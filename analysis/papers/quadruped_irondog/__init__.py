"""Analysis of `quadruped-irondog`: what is read from a run and the shared metrics (metrics.py), one analysis per
experiment (analyses.py), figures (figures.py), report sections (sections.py)."""

from analysis.papers.quadruped_irondog.analyses import ANALYSES
from analysis.papers.quadruped_irondog.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
