"""Analysis of `itbot-smc`: the simulated analogue of Figs. 6-11 (three reaching laws, two plants, exact and
Hall-sensor measurement), the conventional SMC's gain and boundary layer, the load on the handle against Fig. 11's
forces, and the reaching-time study of Proposition 1. Metric definitions: metrics.py; chattering:
analysis/core/signals.py."""

from analysis.papers.itbot_smc.analyses import ANALYSES
from analysis.papers.itbot_smc.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
