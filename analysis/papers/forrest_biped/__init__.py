"""Analysis of `forrest-biped`: the drive curves (Figs. 8, 10-12), the pattern generators (Figs. 14-16), the walk in
MuJoCo with both generators and the LIP check (Figs. 18-20, the Eq. (59) shares), and the robustness band."""

from analysis.papers.forrest_biped.analyses import ANALYSES
from analysis.papers.forrest_biped.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
