"""Analysis of `ur5-ik-fsm`: Tables 3-6 and the agreement from the `tables` runs, joint jumps and
execution errors along the singular paths, per-call compute time.
"""

from analysis.papers.ur5_ik_fsm.analyses import ANALYSES
from analysis.papers.ur5_ik_fsm.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
