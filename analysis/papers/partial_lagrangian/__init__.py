"""Analysis of `partial-lagrangian`: the motions of Figs. 1-5a (damped oscillation, PD and PID settling,
static offsets against the closed-form equilibrium, Listing A1 against the Lagrange equations), the compute
time of Fig. 5b with log-log slopes, and the checks of the AD dynamics against MuJoCo.
"""

from analysis.papers.partial_lagrangian.analyses import ANALYSES
from analysis.papers.partial_lagrangian.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
