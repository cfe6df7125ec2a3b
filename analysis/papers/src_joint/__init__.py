"""Analysis of `src-joint`: the joint model against MuJoCo and the exact rolling plant (Figs. 8-10), poses A,
B and reachable FK targets with the hardware stand-in (Figs. 13-14), target C between two bars (Figs. 16-17),
and the per-step compute times of the IK and the QP.
"""

from analysis.papers.src_joint.analyses import ANALYSES
from analysis.papers.src_joint.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
