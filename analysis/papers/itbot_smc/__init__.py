"""Analysis of `itbot-smc`: the simulated analogue of Figs. 6-11 (three reaching laws, two plants, Hall-sensor
and exact measurement), the conventional SMC's gain and boundary layer, the load on the handle against Fig. 11's
forces, and the reaching-time study of Proposition 1. Metric definitions: metrics.py; chattering:
analysis/core/signals.py."""

from analysis.papers.itbot_smc.analyses import (
    analyze_load_support,
    analyze_reaching_time,
    analyze_smc_sweep,
    analyze_tracking,
)
from analysis.papers.itbot_smc.tables import report_sections

ANALYSES = {"tracking": analyze_tracking, "smc-sweep": analyze_smc_sweep, "load-support": analyze_load_support,
            "reaching-time": analyze_reaching_time}

__all__ = ["ANALYSES", "report_sections"]
