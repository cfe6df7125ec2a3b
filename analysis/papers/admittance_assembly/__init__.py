"""Analysis of `admittance-assembly`: condition (2) over the two-point state (corners vs interior, random
admittances, single-PC vs two-PC), the quasi-static insertions, and MuJoCo's contact forces against the
quasi-static prediction (force errors).
"""

from analysis.papers.admittance_assembly.analyses import ANALYSES
from analysis.papers.admittance_assembly.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
