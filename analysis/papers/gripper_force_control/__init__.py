"""Analysis of `gripper-force-control`: force sag (Fig. 8), the max-force-error surface (Fig. 9), the
pick-and-place timings (Tables 3 and 5, the tomato test), the Monte-Carlo stand-in for Fig. 7, and Tables
2-5 with their ratios.

The force error is always `/wrench` (measured grasp force) minus `/wrench/commanded` (F_set), through
analysis.core.errors.force_error_stats (max, mean, RMS, ISE of |error|; sag as a fraction of F_set).
"""

from analysis.papers.gripper_force_control.analyses import ANALYSES
from analysis.papers.gripper_force_control.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
