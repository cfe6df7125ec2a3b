"""Analysis of `gripper-review`: the review's grippers and Tables 1-3 exported as a dataset (Parquet, CSV,
card), its counts and Table 2-3 claims checked against its own prose (consistency targets), the force and
payload figure, and the link to gripper-force-control."""

from analysis.papers.gripper_review.analyses import ANALYSES
from analysis.papers.gripper_review.sections import report_sections

__all__ = ["ANALYSES", "report_sections"]
