"""The two NMPCs: their predictions are the kinematics they stand for, they agree on an unconstrained move,
the obstacle and height constraints hold in closed loop, and the pipeline runs the paper's experiments."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pipeline.core.checks import compose_config
from pipeline.core.runlog import read_run, run_files
from pipeline.papers.nmpc_cdkd import experiments as ex
from pipeline.papers.nmpc_cdkd import kinematics as kin
from pipeline.papers.nmpc_cdkd.plant import KinematicPlant
from pipeline.papers.nmpc_cdkd.simulation import Move, Obstacles, run

from .conftest import run_cli


@pytest.fixture(scope="module")
def cfg():
    return compose_config(["experiment=nmpc-cdkd/fixed-obstacles", "system.plant.kind=kinematic"])


@pytest.fixture(scope="module")
def arm(cfg):
    return ex.arm_of(cfg)


def _move(cfg, z: float, obstacles: Obstacles | None = None, band=None) -> Move:
    return Move(ex.tool_pose(cfg, [0.11, -0.35, z]), ex.tool_pose(cfg, [0.78, 0.39, z]), 0.5, 1.5, 2.6,
                obstacles or Obstacles.none(), band)


@pytest.mark.parametrize("model", ["decomposed", "full"])
def test_predictions_are_the_direct_kinematics(cfg, arm, model):
    # (10d) integrates the differential kinematics; along the optimum it must equal FK of the predicted joints
    nmpc = ex.nmpc_of(cfg, arm, model, 10, 0, False)
    q = np.array([-0.9, 1.0, 1.9, 0.2, 0.4, -1.0])
    goal = q + np.array([0.3, -0.2, 0.25, 0.2, -0.1, 0.3])
    x0 = nmpc.state(q)
    ref = nmpc.reference(np.linspace(q, goal, 11)[1:], quat_sign_of=None if model == "decomposed" else x0[3:7])
    sol = nmpc.solve(x0, ref, np.zeros((2, nmpc.nu)), np.tile(x0, (11, 1)), np.zeros((10, nmpc.nu)))
    assert sol.success and sol.iterations > 0 and np.abs(sol.u).max() > 0.1
    joints = sol.x[:, nmpc.joint_slice]
    full = np.concatenate([joints, np.tile(q[nmpc.nu:], (11, 1))], axis=1)
    predicted = sol.x[:, :3] * nmpc.s.length_unit
    direct = kin.wrist_point(arm, joints) if model == "decomposed" else kin.tool_pose(arm, full)[:, :3, 3]
    assert np.abs(predicted - direct).max() < 1e-6   # m: RK4 at 10 ms
    if model == "full":
        quat = kin.quaternion(kin.tool_pose(arm, full)[:, :3, :3])
        assert np.abs(np.abs(np.sum(quat * sol.x[:, 3:7], axis=1)) - 1).max() < 1e-9
    # the acceleration and jerk bounds of (10e) hold on the optimal inputs
    u = np.vstack([np.zeros((2, nmpc.nu)), sol.u])
    assert np.abs(np.diff(u, axis=0)).max() / nmpc.s.dt <= nmpc.s.acceleration * (1 + 1e-6)
    assert np.abs(np.diff(u, 2, axis=0)).max() / nmpc.s.dt ** 2 <= nmpc.s.jerk * (1 + 1e-6)


def test_decomposed_and_full_agree_on_an_unconstrained_move(cfg, arm):
    move = _move(cfg, -0.405)
    paths = {}
    for model in ("decomposed", "full"):
        tr = run(arm, ex.nmpc_of(cfg, arm, model, 10, 0, False), ex.controller_of(cfg), move, KinematicPlant)
        assert all(s.success for s in tr.solves)
        paths[model] = kin.frames(arm, tr.q)
        goal = kin.tool_pose(arm, tr.q_ref[-1])
        assert np.linalg.norm(kin.tool_pose(arm, tr.q[-1])[:3, 3] - goal[:3, 3]) < 1e-3
    wrist = {m: F[:, 4, :3, 3] for m, F in paths.items()}
    # both place the wrist point on the same path (the full NMPC trades a few mm of wrist for tool orientation)
    assert np.linalg.norm(wrist["decomposed"] - wrist["full"], axis=1).max() < 0.01


def test_obstacles_and_height_band_hold_in_closed_loop(cfg, arm):
    obstacles = ex.scene_obstacles(cfg, np.zeros((4, 3)))
    band = tuple(cfg.system.scene.band)
    nmpc = ex.nmpc_of(cfg, arm, "decomposed", 10, len(obstacles), True)
    tr = run(arm, nmpc, ex.controller_of(cfg), _move(cfg, -0.445, obstacles, band), KinematicPlant)
    wrist = kin.wrist_point(arm, tr.q[:, :3])
    margin = np.linalg.norm(wrist[:, None] - tr.centres, axis=2) - (obstacles.radii + arm.safety_radius)
    reference = kin.wrist_point(arm, tr.q_ref[:, :3])
    passes = np.linalg.norm(reference[:, None] - tr.centres, axis=2) - (obstacles.radii + arm.safety_radius)
    assert passes.min() < -0.1                 # the reference runs through the safety spheres …
    assert margin.min() > -1e-5                # … the robot does not (solver tolerance, m)
    assert wrist[:, 2].min() > band[0] - 1e-5 and wrist[:, 2].max() < band[1] + 1e-5


def test_pipeline_runs_fig3_and_reports(data_dir):
    proc = run_cli("pipeline", "experiment=nmpc-cdkd/tracking", f"data_dir={data_dir}", "progress=false")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", "experiment=nmpc-cdkd/tracking", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr
    frame = pd.read_parquet(data_dir / "metrics/nmpc-cdkd/tracking.parquet")
    metrics = frame[frame["run_id"] == "decomposed"].set_index("metric")["value"]
    assert metrics["claim.no_stationary_error"] == 1 and metrics["solve.failures"] == 0
    assert metrics["wrist_error.max"] < 0.1 * metrics["tool_error.max"]
    assert abs(metrics["reference.z_deviation_time"] - 1.2) < 0.1
    # Sec. 4.2: the same wrist path with a 50 mm rod gives smaller tool errors (the lever: 150 vs 250 mm)
    short = frame[frame["run_id"] == "decomposed-de50mm"].set_index("metric")["value"]
    assert short["wrist_error.max"] == pytest.approx(metrics["wrist_error.max"], rel=1e-6)
    assert short["tool_error.max"] / metrics["tool_error.max"] == pytest.approx(150 / 250, rel=0.05)
    assert (data_dir / "figures/nmpc-cdkd/tracking/fig3-decomposed.png").is_file()


def test_bad_horizon_is_refused():
    proc = run_cli("pipeline", "experiment=nmpc-cdkd/tracking", "system.nmpc.horizon_steps=1")
    assert proc.returncode == 2 and "horizon_steps" in proc.stderr


def test_compute_time_runs_on_the_kinematic_plant(data_dir):
    proc = run_cli("pipeline", "experiment=nmpc-cdkd/compute-time", "scenario.cases=[no-obstacle]",
                   "scenario.horizons=[10]", f"data_dir={data_dir}", "progress=false")
    assert proc.returncode == 0, proc.stderr
    runs = [read_run(p) for p in run_files(data_dir / "runs/nmpc-cdkd/compute-time")]
    assert len(runs) == 2 and all(r.ok for r in runs), [r.status for r in runs]
    assert "effort" not in " ".join(runs[0]["/joint_state"].columns)  # a kinematic plant has no torques
    assert {"/robot_description", "/joint_states"} <= set(runs[0].topic_names)  # the arm drawn all the same


# -- Table 3's probes ---------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def table3_cfg():
    return compose_config(["experiment=nmpc-cdkd/compute-time", "scenario.moves=1"])


def test_a_probe_resumes_the_closed_loop(table3_cfg):
    """Started where a closed loop stands (its command, its last two inputs, its previous plan shifted), a probe
    solves the OCP the loop solved there: the same plan."""
    from pipeline.papers.nmpc_cdkd.simulation import Start

    cfg = table3_cfg
    arm = ex.arm_of(cfg)
    m = ex.random_moves(cfg, arm)[0]
    move = ex._move_of(cfg, m, "no-obstacle")
    nmpc = ex.nmpc_of(cfg, arm, "decomposed", 10, 0, False)
    ctl = ex.controller_of(cfg)
    plant = ex.plant_factory(cfg, arm, move.obstacles, None)
    loop = run(arm, nmpc, ctl, move, plant, m["selection"], solves=4)
    j, cs = 3 * ctl.control_steps, ctl.control_steps                   # the loop's fourth OCP
    previous = loop.solves[2]
    shifted = np.concatenate([previous.x[cs:, 3:6], np.repeat(previous.x[-1:, 3:6], cs, axis=0)])
    guess_q = np.concatenate([shifted, np.tile(loop.q_cmd[j, 3:], (len(shifted), 1))], axis=1)
    guess_u = np.concatenate([previous.u[cs:], np.repeat(previous.u[-1:], cs, axis=0)])
    start = Start(tick=j, q=loop.q_cmd[j], u_prev=loop.qd_cmd[[j - 1, j - 2]],
                  guess_q=guess_q, guess_u=np.pad(guess_u, ((0, 0), (0, 3))))
    probe = run(arm, nmpc, ctl, move, plant, m["selection"], start, solves=1)
    assert len(probe.solves) == 1 and probe.solve_t[0] == pytest.approx(loop.solve_t[3])
    np.testing.assert_allclose(probe.solves[0].u, loop.solves[3].u, atol=1e-5)
    assert np.abs(loop.solves[3].u).max() > 0.1                           # the arm is moving there


def test_the_probes_feasible_path_keeps_the_constraints(table3_cfg):
    """The feasible path keeps the wrist out of the obstacle's safety sphere and inside the height band, and is the
    reference wherever the reference keeps them itself."""
    cfg = table3_cfg
    arm = ex.arm_of(cfg)
    m = ex.random_moves(cfg, arm)[0]
    poly = ex.planning.JointPolynomial(m["selection"].q_start, m["selection"].q_goal, 0.0, m["T"])
    q_ref = poly(np.linspace(0.0, m["T"], 120))
    for case in ("obstacle", "obstacle-height"):
        move = ex._move_of(cfg, m, case)
        path = ex.feasible_path(arm, q_ref, move.obstacles, move.band, 0.001)
        wrist, wrist_ref = kin.wrist_point(arm, path[:, :3]), kin.wrist_point(arm, q_ref[:, :3])
        safety = move.obstacles.radii[0] + arm.safety_radius
        assert (np.linalg.norm(wrist - move.obstacles.centres[0], axis=1) >= safety - 1e-9).all()
        if move.band is not None:
            assert (wrist[:, 2] >= move.band[0] - 1e-9).all() and (wrist[:, 2] <= move.band[1] + 1e-9).all()
        free = np.linalg.norm(wrist_ref - move.obstacles.centres[0], axis=1) > safety + 0.001
        if move.band is None:
            np.testing.assert_array_equal(path[free], q_ref[free])
        assert (~free).any()                                               # the reference runs into the obstacle
        # the tool keeps the reference's orientation
        np.testing.assert_allclose(kin.tool_pose(arm, path)[:, :3, :3], kin.tool_pose(arm, q_ref)[:, :3, :3],
                                   atol=1e-9)
