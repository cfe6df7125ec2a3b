"""`admittance-assembly`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

import numpy as np
import pandas as pd

from pipeline.core.runlog import Run

CASES = ("planar", "spatial")


FORCE = ["force_x", "force_y", "force_z"]


TORQUE = ["torque_x", "torque_y", "torque_z"]


CONTACT_FORCE_ON = 1e-3  # N: a hole feature carries force above this (contact-state agreement)


def _scalars(run: Run, topic: str) -> pd.DataFrame:
    frame = run[topic]
    return frame.rename(columns=lambda c: c.removeprefix("value."))


def _vectors(frame: pd.DataFrame, parts: list[str], name: str) -> np.ndarray:
    return frame[[f"{p}.{name}" for p in parts]].to_numpy()


def _insertion_metrics(run: Run) -> dict:
    err = run["/tracking_error"]["norm"]
    state = _scalars(run, "/assembly")
    contacts = run["/wrench/contacts"]
    forces = np.linalg.norm(np.stack([contacts[[c for c in contacts if c.startswith(f"{f}.")]].to_numpy()
                                      for f in FORCE], axis=-1), axis=-1)
    wrench = run["/wrench"]
    inserted = run.metadata["outcome"] == "inserted"
    two = state["two_point_state"] > 0
    # an inserted run's last sample lies past the mated depth, where ‖δ‖ grows again by construction
    before_end = np.arange(len(state)) < len(state) - (1 if inserted else 0)
    growing = state["d_dot_v"] > 0
    return {
        "inserted": (float(inserted), "bool"),
        "insertion_time": (err.index[-1] if inserted else np.nan, "s"),
        "initial_error": (err.iloc[0], "m"),
        "final_error": (err.iloc[-1], "m"),
        "increasing_steps": (int((growing & before_end).sum()), "count"),
        "increasing_steps_two_point": (int((growing & two & before_end).sum()), "count"),
        "two_point_fraction": (two[before_end].mean(), "fraction"),
        "min_closing_rate_two_point": (state["closing_rate"][two & before_end].min() if (two & before_end).any()
                                       else np.nan, "m/s"),
        "max_contact_force": (np.nanmax(forces) if forces.size else 0.0, "N"),
        "max_total_force": (np.linalg.norm(_vectors(wrench, FORCE, "peg"), axis=1).max(), "N"),
    }


def _contact_forces(run: Run, topic: str) -> tuple[list[str], np.ndarray]:
    frame = run[topic]
    names = [c.removeprefix("force_x.") for c in frame if c.startswith("force_x.")]
    return names, np.linalg.norm(np.stack([_vectors(frame, FORCE, n) for n in names], axis=1), axis=-1)
