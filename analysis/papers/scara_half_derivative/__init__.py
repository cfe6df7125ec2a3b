"""Analysis of `scara-half-derivative`: the set-point (Figs. 4-5), Table 2 and Figs. 8-10, the ICE/ISE maps
and the equal-ICE locus (Fig. 6, eq. 20), the path along eq. (20) (Fig. 7), controller compute time.

Metric definitions: e = x_d − x on the fine-step samples; e_max = max |e|, e_mean = mean |e|
(MAE over [0, T_sim]); ISE = ∫ (e_x² + e_y² + e_z²) dt (eq. 19, trapezoid); ICE = Σ_i ∫ τ_i² dt (eq. 18) with τ the
actuator torques (τ_g included) held over each period, so the sum over periods is exact; percentages are
relative to KD (d_xyz = 5000) at the same stiffness.
"""

from analysis.papers.scara_half_derivative.analyses import ANALYSES
from analysis.papers.scara_half_derivative.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
