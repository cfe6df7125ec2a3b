"""Analysis of `nmpc-cdkd`: Table 3 (OCP solve times and their ratios), Fig. 3 (tracking errors), Figs. 4-5 (fixed
obstacles: clearance, swerve, detour, arrival) and Figs. 6-7 (moving obstacles).
"""

from analysis.papers.nmpc_cdkd.analyses import ANALYSES
from analysis.papers.nmpc_cdkd.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
