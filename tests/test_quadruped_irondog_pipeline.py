"""`quadruped-irondog` end to end on short runs: every experiment simulated (in process, as the CLI's runner does),
then the analysis and report CLI; the targets it judges, the run files a user opens (common topics, joint names,
the model, markers), a fall kept as a failed run with its reason, determinism, and bad input refused up front."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pipeline.core.checks import BadInput, preflight
from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli, simulate_experiment

SLUG = "quadruped-irondog"
SHORT = {  # reduced sizes: the same code paths, a fraction of the time
    "tables": [],
    "kinematics": ["scenario.workspace_samples=300", "scenario.timing_calls=50", "scenario.bezier_samples=101"],
    "stand": ["scenario.duration=1.5", "scenario.payloads=[0,7.5]"],
    "body-poses": ["scenario.settle=0.6", "scenario.ramp=0.25", "scenario.hold=0.25"],
    "self-levelling": ["scenario.axes=[pitch]", "scenario.duration=4.0", "scenario.tilt_ramp=1.5"],
    "trot": ["scenario.cycle_times=[0.5]", "scenario.cycles=5"],
}


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    data_dir = tmp_path_factory.mktemp("quadruped") / "data"
    for name, extra in SHORT.items():
        simulate_experiment(data_dir, f"{SLUG}/{name}", extra)
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr
    targets = pd.read_csv(data_dir / "report" / "targets.csv")
    return data_dir, targets[targets["slug"] == SLUG].set_index("target_id")


def test_targets_judged_from_the_short_runs(report):
    _, targets = report
    status = targets["status"]
    for target in ("fig12.start.a", "fig12.end.d", "ik.corrected", "T5.coxa", "T5.femur.right", "T5.femur.left",
                   "T5.tibia", "fig18.poses", "fig19e.joints", "level.pitch", "trot.walks"):
        assert status[target] == "match", (target, targets.loc[target, "pipeline_value"], targets.loc[target, "note"])
    assert status["ik.printed"] == "miss" and targets.loc["ik.printed", "pipeline_value"] > 1.0   # mm
    # the payload collapses the stance: a failed run, and the target says why
    assert status["payload.stand"] == "miss" and "fell at t = " in targets.loc["payload.stand", "note"]
    for target in ("trot.walks.cycle-1s", "fig20e.coxa"):     # their runs were left out of the short set
        assert status[target] in ("not run", "miss") and np.isnan(targets.loc[target, "pipeline_value"])
    # the paper's arithmetic
    assert status["T2.total"] == "agrees" and status["payload.load"] == "agrees" and status["cost.text"] == "agrees"
    for target in ("mass.text", "T6.total", "T6.total.products", "T6.battery", "T4.shear", "fea.femur.strain_vs_fos",
                   "screws.count"):
        assert status[target] == "disagrees", target
    # hardware rows: not reproducible, never given a pipeline value; the simulated stand-in is in its own section
    imu = targets.loc[targets.index.str.startswith("imu.")]
    assert (imu["status"] == "not-reproducible").all() and imu["pipeline_value"].isna().all()
    assert (imu["cause"] == "hardware-only").all()
    page = (report[0] / "report" / f"{SLUG}.md").read_text()
    assert "IMU: the real robot and a simulated stand-in" in page and "Trot on flat ground" in page


def test_run_files_carry_the_robot(report):
    data_dir, _ = report
    run = read_run(run_files(data_dir / f"runs/{SLUG}/trot")[0])
    assert run.ok and {"/joint_state", "/reference", "/command", "/tracking_error", "/wrench", "/tf", "/markers",
                       "/compute_time", "/body", "/feet", "/reference/feet", "/gait"} <= set(run.topic_names)
    js = run["/joint_state"]
    assert {f"position.{leg}_{j}" for leg in ("FR", "FL", "BR", "BL") for j in ("coxa", "femur", "tibia")} \
        <= set(js.columns)
    assert "<mujoco model=\"iron_dog_mini\">" in run.attachments["model.xml"].decode()
    tf = run["/tf"]
    assert "transforms.FL_foot.translation.z" in tf.columns and "transforms.trunk.rotation.w" in tf.columns
    wrench = run["/wrench"]
    assert wrench["frame_id"].iloc[0] == "world" and (wrench[[f"force_z.{leg}" for leg in ("FR", "FL", "BR", "BL")]]
                                                      >= -1e-9).all().all()
    # the trunk's pose on /body and on /tf agree
    assert np.allclose(run["/body"]["z"].to_numpy()[::4][:len(tf)], tf["transforms.trunk.translation.z"])
    failed = read_run(data_dir / f"runs/{SLUG}/stand/payload-7.5kg.mcap")
    assert failed.status.startswith("failed: fell at t = ") and "BR_tibia" in failed.status
    assert len(failed["/joint_state"]) > 10          # what happened before the fall is kept
    figures = {p.name for p in (data_dir / f"figures/{SLUG}").rglob("*.png")}
    assert {"fig12-bezier.png", "fig16-table5-poses.png", "fig18-body-poses.png", "fig19-20-self-levelling.png",
            "fig22-trot-cycle-0.5s.png", "fig21-trot-sequence-cycle-0.5s.png"} <= figures


def test_runs_are_deterministic(tmp_path):
    for k in (0, 1):
        simulate_experiment(tmp_path / f"d{k}", f"{SLUG}/stand", ["scenario.duration=0.3", "scenario.payloads=[0]"])
    a, b = (read_run(tmp_path / f"d{k}/runs/{SLUG}/stand/robot.mcap") for k in (0, 1))
    for topic in ("/joint_state", "/wrench", "/tf"):
        pd.testing.assert_frame_equal(a[topic], b[topic])


@pytest.mark.parametrize(("override", "key"), [
    ("scenario.cycles=1000000000", "scenario.cycles"),
    ("system.gait.duty_factor=1.5", "system.gait.duty_factor"),
    ("system.leg.ik_form=typo", "system.leg.ik_form"),
    ("system.servo.stall_torque=-1", "system.servo.stall_torque"),
    ("system.log.rate_hz=1e6", "system.log.rate_hz"),
    ("scenario.cycle_times=[0.5,nan]", "scenario.cycle_times[1]"),
    ("scenario.cycle_times=0.5", "scenario.cycle_times"),                     # a list is needed
    ("system.gait.control_points_mm=[[100,-252.4]]", "system.gait.control_points_mm"),  # Table 3 has 14 points
])
def test_bad_input_is_refused_before_anything_runs(override, key):
    with pytest.raises(BadInput) as err:
        preflight([f"experiment={SLUG}/trot", override])
    message = str(err.value)
    assert key in message and len(message) < 300 and "\n" not in message


@pytest.mark.parametrize("override", ["scenario.axes=[yaw]", "scenario.tilt_deg=90"])
def test_bad_input_on_the_cli_exits_2_and_writes_nothing(data_dir, override):
    proc = run_cli("pipeline", f"experiment={SLUG}/self-levelling", override, f"data_dir={data_dir}")
    assert proc.returncode == 2 and override.split("=")[0] in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and not data_dir.exists()
