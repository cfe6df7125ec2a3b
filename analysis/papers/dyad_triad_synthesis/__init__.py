"""Analysis of `dyad-triad-synthesis`: Table 5 and the worked example, the Burmester curves, the synthetic
round trips, the four-bar in Exudyn and the solvers' compute time."""

from analysis.papers.dyad_triad_synthesis.analyses import ANALYSES
from analysis.papers.dyad_triad_synthesis.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
