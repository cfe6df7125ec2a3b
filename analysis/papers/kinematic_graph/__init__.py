"""Analysis of `kinematic-graph`: Table 1 and Sec. 3.2 (`table1`), the planar searches of Figs. 2-5 (`search`) and the
spatial graph of Fig. 6 (`spatial`)."""

from analysis.papers.kinematic_graph.analyses import analyze_search, analyze_spatial, analyze_table1
from analysis.papers.kinematic_graph.sections import report_sections

ANALYSES = {"table1": analyze_table1, "search": analyze_search, "spatial": analyze_spatial}

__all__ = ["ANALYSES", "report_sections"]
