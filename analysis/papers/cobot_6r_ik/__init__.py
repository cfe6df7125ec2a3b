"""Analysis of `cobot-6r-ik`: Tables 2–3 from the `tables` runs, completeness on random poses, compute
time beside the peers, Cartesian paths executed in MuJoCo."""

from analysis.papers.cobot_6r_ik.analyses import ANALYSES
from analysis.papers.cobot_6r_ik.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
