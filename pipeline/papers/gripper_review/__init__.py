"""`gripper-review`: Hernandez et al. — Current Designs of Robotic Arm Grippers: A Comprehensive Systematic
Review (Robotics 2023, 12, 5).

A review reports no results of its own: its "simulate" stage is the curation of what it quotes. The
grippers of its Sect. 2 and its Tables 1-3 are transcribed in grippers.yaml and tables.yaml (this folder);
the `dataset` experiment checks and types them (curated.py) and logs one record per gripper, per table
row and per transcribed cell (experiments.py).
"""

from __future__ import annotations

from pipeline.core.experiment import OneOf, Range

__all__ = ["EXPERIMENTS", "LIMITS"]


def __getattr__(name: str):
    if name == "EXPERIMENTS":  # the run-file machinery is imported only when an experiment runs
        from pipeline.papers.gripper_review import experiments

        return {"dataset": experiments.dataset}
    raise AttributeError(name)


LIMITS = {
    "system.gravity": Range(ge=9.7, le=9.9),   # m/s^2, anywhere on Earth
    "scenario.table2_large_unit": OneOf(("cm", "mm")),
}
