"""Analysis of `curve-discretization`: the Fig. 2 chain and its checks, the Fig. 3 timing sweep with scaling
exponents, and the MuJoCo snake's shape error and per-step compute time.
"""

from analysis.papers.curve_discretization.analyses import ANALYSES
from analysis.papers.curve_discretization.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
