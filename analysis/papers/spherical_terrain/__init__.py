"""Analysis of `spherical-terrain`: convergence time, steady-state and vertex errors, control effort and tilt
saturation of every tracking run; the paper's Figs. 6-12 regenerated; the gain/start sweep
tabulated from whatever sweep runs are on disk; and the physics check (MuJoCo vs the no-slip model).
"""

from analysis.papers.spherical_terrain.analyses import ANALYSES
from analysis.papers.spherical_terrain.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
