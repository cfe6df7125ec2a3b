"""forrest-biped end to end on a short walk: the CLI simulates both generators in MuJoCo and the LIP check, the
runs carry the common topics, the analysis computes the shares and the report page lists the targets; bad input is
refused before anything runs."""

from __future__ import annotations

import numpy as np
import pytest

from pipeline.core.runlog import read_runs

from .conftest import run_cli

SHORT = ["experiment=forrest-biped/walking", "system.walk.duration=1.5", "scenario.lipm_zmp_lags=[0.0]",
         "scenario.window=[1.0,1.5]", "progress=false"]


@pytest.mark.slow
def test_short_walk_end_to_end(data_dir):
    sim = run_cli("pipeline", *SHORT, f"data_dir={data_dir}")
    assert sim.returncode == 0, sim.stderr[-2000:]
    runs = {r.run_id.partition("__")[0]: r for r in read_runs(data_dir / "runs/forrest-biped/walking")}
    assert set(runs) == {"extended", "traditional", "lipm-extended", "lipm-traditional", "stance-zero-extended",
                         "stance-zero-traditional"}
    assert all(r.ok for r in runs.values())
    walk = runs["extended"]
    assert {"/joint_state", "/command", "/tf", "/compute_time", "/wrench/left_foot", "/wrench/right_foot",
            "/wrench/contacts", "/balance", "/tracking_error", "/reference/com"} <= set(walk.topic_names)
    assert "model.xml" in walk.attachments
    js = walk["/joint_state"]
    assert [c.removeprefix("position.") for c in js.columns if c.startswith("position.")][:3] == \
        ["l_hip_yaw", "l_hip_roll", "l_hip_pitch"]
    assert np.diff(js.index.to_numpy()).max() == pytest.approx(1e-3)           # the 1 ms controller cycle
    # standing on both feet at the start the contacts carry the weight (spec §8.9): Σ f_z ≈ M g
    feet = sum(walk[f"/wrench/{s}"]["force_z.measured"] for s in ("left_foot", "right_foot"))
    assert feet.loc[0.02:0.2].mean() == pytest.approx(32.51 * 9.81, rel=0.02)
    # the measured ZMP lies under the robot: inside the feet's hull (x within the plates)
    bal = walk["/balance"]
    assert bal["zmp.x"].abs().max() < 0.11 + 1e-3
    ana = run_cli("analysis", "experiment=forrest-biped/walking", f"data_dir={data_dir}")
    assert ana.returncode == 0, ana.stderr[-2000:]
    import pandas as pd

    metrics = pd.read_parquet(data_dir / "metrics/forrest-biped/walking.parquet")
    shares = metrics[metrics["run_id"].str.startswith("all__") & metrics["metric"].str.match(r"share\.[xy]\.window")]
    assert len(shares) == 2 and shares["value"].between(0, 1).all()
    # the shares under the other stance-foot setting, and its walks' slip, sit beside the default's
    zero = metrics[metrics["run_id"].str.startswith("all__") & metrics["metric"].str.match(r"stance-zero\.share\.")]
    assert len(zero) == 6 and zero["value"].between(0, 1).all()
    assert metrics["run_id"].str.startswith("stance-zero-extended").any()
    assert (data_dir / "figures/forrest-biped/walking/fig20-com-error.png").exists()
    page = (data_dir / "report/forrest-biped.md").read_text()
    assert "share.x" in page and "Eq. (59)" in page


@pytest.mark.parametrize("override, key", [("system.walk.duration=1e9", "system.walk.duration"),
                                           ("system.walk.eq48=typo", "system.walk.eq48"),
                                           ("scenario.window=[1.0]", "scenario.window")])
def test_bad_input_is_refused_in_one_line(data_dir, override, key):
    proc = run_cli("pipeline", "experiment=forrest-biped/walking", override, f"data_dir={data_dir}")
    assert proc.returncode == 2
    line = proc.stderr.strip()
    assert key in line and "\n" not in line and len(line) < 300
    assert not data_dir.exists()
