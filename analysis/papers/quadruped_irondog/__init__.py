"""Analysis of `quadruped-irondog`: metrics per experiment (metrics.py), figures (figures.py), report tables
(sections.py)."""

from analysis.papers.quadruped_irondog.metrics import (
    analyze_body_poses,
    analyze_kinematics,
    analyze_self_levelling,
    analyze_stand,
    analyze_tables,
    analyze_trot,
)
from analysis.papers.quadruped_irondog.sections import report_sections

ANALYSES = {"tables": analyze_tables, "kinematics": analyze_kinematics, "stand": analyze_stand,
            "body-poses": analyze_body_poses, "self-levelling": analyze_self_levelling, "trot": analyze_trot}

__all__ = ["ANALYSES", "report_sections"]
