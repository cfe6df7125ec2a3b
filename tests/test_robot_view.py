"""Every robot in 3-D: the URDF generated from the MuJoCo model parses with a maintained URDF library, its FK
equals MuJoCo's, its joints are the joint-state channel's, the channels decode, the Foxglove layout uses only
what Foxglove's schema knows, and Rerun's own MCAP loader turns a run into 3-D geometry."""

from __future__ import annotations

import io
import json
import shutil
import subprocess

import mujoco
import numpy as np
import pytest
import yourdfpy
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms

from pipeline.core import layouts, robot
from pipeline.core.runlog import RunWriter, read_run
from pipeline.robotics.urdf import Pose, _euler, _quat_mul, _rotate, describe, described

from .conftest import ENV, simulate_case

# hinge with anchor and ref, slide with ref, ball, free, a geom-less body, a mocap body, capsules: every case
MODEL = """<mujoco model="demo"><worldbody><geom type="plane" size="1 1 0.1"/>
<body name="a" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2"><joint name="h1" axis="0.3 0.4 0.5" pos="0.05 0 0.1" ref="0.4"/>
 <joint name="s1" type="slide" axis="1 0.2 0" pos="0 0.1 0" ref="0.1" range="-1 1"/>
 <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/>
 <body name="b" pos="0.3 0 0" euler="0.3 0.2 0.1"><joint name="ball" type="ball" pos="0.01 0.02 0.03"/>
  <geom type="box" size="0.1 0.05 0.02"/>
  <body name="c" pos="0 0 0.2"><joint name="h2" axis="0 1 0" range="-2 2"/><site name="tip" pos="0 0 0.3"/>
   <inertial pos="0 0 0.1" mass="1" diaginertia="1 1 1"/></body></body></body>
<body name="f" pos="1 1 1"><freejoint name="fj"/><geom type="sphere" size="0.1"/>
 <body name="g" pos="0.2 0 0"><joint name="h3" axis="0 0 1"/><geom type="cylinder" size="0.02 0.1"/></body></body>
<body name="m" mocap="true" pos="0.5 0.5 0.5"><geom type="sphere" size="0.05"/></body>
</worldbody></mujoco>"""


def random_states(model, n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    qpos = rng.uniform(-1.5, 1.5, (n, model.nq))
    for j in range(model.njnt):
        a, kind = model.jnt_qposadr[j], model.jnt_type[j]
        if kind in (mujoco.mjtJoint.mjJNT_BALL, mujoco.mjtJoint.mjJNT_FREE):
            q = slice(a, a + 4) if kind == mujoco.mjtJoint.mjJNT_BALL else slice(a + 3, a + 7)
            qpos[:, q] /= np.linalg.norm(qpos[:, q], axis=1, keepdims=True)
    mocap_pos = rng.uniform(-1, 1, (n, model.nmocap, 3))
    mocap_quat = rng.normal(size=(n, model.nmocap, 4))
    return qpos, mocap_pos, mocap_quat / np.linalg.norm(mocap_quat, axis=-1, keepdims=True)


def mujoco_poses(model, qpos, mocap_pos, mocap_quat):
    data = mujoco.MjData(model)
    out = []
    for q, mp, mq in zip(qpos, mocap_pos, mocap_quat, strict=True):
        data.qpos[:], data.mocap_pos[:], data.mocap_quat[:] = q, mp, mq
        mujoco.mj_kinematics(model, data)
        out.append((data.xpos.copy(), data.xmat.reshape(-1, 3, 3).copy()))
    return out


def assert_urdf_fk_is_mujocos(urdf: yourdfpy.URDF, description, model, states) -> None:
    """At each of the (qpos, mocap_pos, mocap_quat) `states`, every body of the URDF moved by the description's
    joint positions sits where MuJoCo's FK puts it (1e-9)."""
    qpos, mocap_pos, mocap_quat = states
    positions = description.joint_positions(qpos, mocap_pos, mocap_quat)
    for q, (xpos, xmat) in zip(positions, mujoco_poses(model, qpos, mocap_pos, mocap_quat), strict=True):
        urdf.update_cfg(dict(zip(description.joint_names, q, strict=True)))
        for b in range(1, model.nbody):
            T = urdf.get_transform(f"{description.name}/{model.body(b).name}", "world")
            assert np.allclose(T[:3, 3], xpos[b], atol=1e-9) and np.allclose(T[:3, :3], xmat[b], atol=1e-9)


def test_urdf_parses_and_its_fk_is_mujocos():
    model = mujoco.MjModel.from_xml_string(MODEL)
    description = describe(model)
    urdf = yourdfpy.URDF.load(io.StringIO(description.urdf()), load_meshes=False, load_collision_meshes=False)
    assert sorted(urdf.actuated_joint_names) == sorted(description.joint_names)
    assert_urdf_fk_is_mujocos(urdf, description, model, random_states(model, 12))


def test_models_differing_only_in_actuators_share_one_model_and_description():
    servo = '<actuator><position joint="h2" kp="{}"/></actuator></mujoco>'
    tuned = [MODEL.replace("</mujoco>", servo.format(kp)) for kp in (10, 20)]
    (model_a, a), (model_b, b) = described(tuned[0]), described(tuned[1])
    assert model_b is model_a and b is a  # the second text is not compiled again
    assert a.urdf() == describe(mujoco.MjModel.from_xml_string(tuned[1])).urdf()
    moved = MODEL.replace('<body name="c" pos="0 0 0.2">', '<body name="c" pos="0 0 0.25">')
    assert described(moved)[1].urdf() != a.urdf()


def test_link_transforms_compose_to_mujocos_poses():
    """/tf/robot (what Rerun and Foxglove place links by) chained from the root equals MuJoCo's FK."""
    model = mujoco.MjModel.from_xml_string(MODEL)
    description = describe(model)
    qpos, mocap_pos, mocap_quat = random_states(model, 5, seed=1)
    trans, quats = description.transforms(description.joint_positions(qpos, mocap_pos, mocap_quat))
    for i, (xpos, xmat) in enumerate(mujoco_poses(model, qpos, mocap_pos, mocap_quat)):
        pose = {"world": Pose.identity()}
        moving = {j.child: (j.parent, Pose(trans[i, k], quats[i, k])) for k, j in enumerate(description.movable)}
        moving |= {j.child: (j.parent, j.origin) for j in description.fixed}
        while len(pose) < len(moving) + 1:
            for child, (parent, local) in moving.items():
                if parent in pose and child not in pose:
                    pose[child] = pose[parent] @ local
        for b in range(1, model.nbody):
            p = pose[f"demo/{model.body(b).name}"]
            R = np.zeros(9)
            mujoco.mju_quat2Mat(R, p.q)
            assert np.allclose(p.p, xpos[b], atol=1e-9) and np.allclose(R.reshape(3, 3), xmat[b], atol=1e-9)


def test_column_encoding_equals_protobufs():
    times_ns = np.array([0, 7, 1_500_000_000, 300 * 10**9 + 999])
    trans, quats = np.random.default_rng(2).normal(size=(4, 2, 3)), np.random.default_rng(3).normal(size=(4, 2, 4))
    for payload, t, tr, q in zip(robot.frame_transforms(times_ns, ["world", "a"], ["a", "b" * 200], trans, quats),
                                 times_ns, trans, quats, strict=True):
        message = FrameTransforms.FromString(payload)
        assert [x.child_frame_id for x in message.transforms] == ["a", "b" * 200]
        assert message.transforms[1].timestamp.ToNanoseconds() == t
        assert np.allclose([[x.translation.x, x.translation.y, x.translation.z] for x in message.transforms], tr)
        assert np.allclose([[x.rotation.w, x.rotation.x, x.rotation.y, x.rotation.z] for x in message.transforms], q)
    assert robot.decode_ros2_string(robot.ros2_string("<robot/>")) == "<robot/>"


def write_run(path, n: int = 400):
    model = mujoco.MjModel.from_xml_string(MODEL)
    qpos, mocap_pos, mocap_quat = random_states(model, n)
    t = np.arange(n) * 1e-3
    with RunWriter(path, {"run_id": path.stem, "slug": "demo"}) as w:
        w.attach("model.xml", MODEL, "application/xml")
        w.log_series("/tracking_error", t, units="m", name=["x"], error=qpos[:, :1], norm=np.abs(qpos[:, 0]))
        w.log_robot(t, qpos, mocap_pos, mocap_quat)
        w.close("ok")
    return t


def test_run_carries_the_robot(tmp_path):
    t = write_run(tmp_path / "r.mcap")
    run = read_run(tmp_path / "r.mcap")
    assert {robot.ROBOT_DESCRIPTION, robot.JOINT_STATES, robot.ROBOT_TF} <= set(run.topic_names)
    urdf = run["/robot_description"]["data"].iloc[0]
    assert urdf == run.attachments[robot.URDF_ATTACHMENT].decode()
    names = sorted(yourdfpy.URDF.load(io.StringIO(urdf), load_meshes=False).actuated_joint_names)
    states = run["/joint_states"]
    assert sorted(c.removeprefix("joints.").removesuffix(".name") for c in states.columns
                  if c.endswith(".name")) == names
    assert len(states) == len(robot.thinned(t)) < len(t)  # thinned to VIEW_RATE_HZ for drawing
    assert np.diff(states.index).max() <= 1 / robot.VIEW_RATE_HZ + 1e-12


def test_joint_state_names_draw_the_robot_unasked(tmp_path):
    xml = """<mujoco model="arm"><worldbody><body name="l1"><joint name="j1" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/></body></worldbody></mujoco>"""
    with RunWriter(tmp_path / "r.mcap", {"run_id": "r"}) as w:
        w.attach("model.xml", xml, "application/xml")
        w.log_series("/joint_state", np.arange(3) * 0.1, units="rad", name=["j1"],
                     position=np.array([[0.0], [0.1], [0.2]]))
        w.close("ok")
    states = read_run(tmp_path / "r.mcap")["/joint_states"]
    assert np.allclose(states["joints.j1.position"], [0.0, 0.1, 0.2])


def test_foxglove_layout_is_foxgloves_schema(tmp_path):
    write_run(tmp_path / "r.mcap", 20)
    layout = json.loads(read_run(tmp_path / "r.mcap").attachments[layouts.LAYOUT_ATTACHMENT])
    scene, plots = layout["content"]["items"]
    three_d = scene["content"]
    assert three_d["panelType"] == "ThreeDee"
    urdf = three_d["config"]["layers"]["robot"]
    assert (urdf["layerId"], urdf["sourceType"], urdf["topic"], urdf["controlMode"], urdf["jointStatesTopic"]) == \
        ("foxglove.Urdf", "topic", "/robot_description", "jointStates", "/joint_states")
    [plot] = plots["content"]["items"]
    assert plot["content"]["config"]["paths"][0]["value"] == "/tracking_error.norm"


@pytest.mark.skipif(shutil.which("rerun") is None, reason="rerun CLI (rerun-sdk) not on PATH")
def test_rerun_mcap_loader_draws_the_robot(tmp_path):
    write_run(tmp_path / "r.mcap", 50)
    out = tmp_path / "r.rrd"
    subprocess.run(["rerun", "mcap", "convert", str(tmp_path / "r.mcap"), "-o", str(out)], check=True, env=ENV,
                   capture_output=True, timeout=120)
    printed = subprocess.run(["rerun", "rrd", "print", str(out)], check=True, env=ENV, capture_output=True,
                             text=True, timeout=120).stdout
    for geometry in ("Boxes3D", "Cylinders3D", "Ellipsoids3D"):  # the URDF's visuals, not only transforms
        assert geometry in printed
    assert "Transform3D:child_frame" in printed


def test_view_writes_under_data_views(tmp_path):
    from analysis import view

    run_dir = tmp_path / "runs" / "demo" / "e"
    run_dir.mkdir(parents=True)
    write_run(run_dir / "r.mcap", 30)
    out = view.convert(run_dir / "r.mcap")
    assert out == tmp_path / "views" / "demo" / "e" / "r.rrd" and out.stat().st_size > 0
    assert sorted(p.name for p in run_dir.iterdir()) == ["r.mcap"]


# -- every articulated paper: one short run each, simulated in-process ----------------------------------------
# slug (or slug/experiment where a paper has more than one robot): (experiment, overrides that shorten it, the
# case drawn, whether the run's own /tf names the model's bodies)
PAPER_RUNS = {
    "ur5-ik-fsm": ("singular-paths", ["scenario.paths=[wrist]", "scenario.duration=0.5"], "wrist-near-alg1", False),
    "curve-discretization": ("snake-gait", ["scenario.duration=0.2", "scenario.joints=6"], "lateral-undulation", False),
    "curve-discretization/bezier-fig2": ("bezier-fig2", [], "paper", False),
    "gripper-force-control": ("pick-and-place", [], None, False),
    "gripper-force-control/lumped": ("force-sag", ["scenario.plants=[lumped]", "scenario.forms=[]"],
                                     "no-feedforward-lumped", True),
    "partial-lagrangian": ("two-link", ["scenario.pd.duration=0.3"], "pd", False),
    "cobot-6r-ik": ("trajectory", ["scenario.duration=0.2"], "line", False),
    "nmpc-cdkd": ("tracking", ["scenario.duration=0.6", "scenario.t0=0.1", "scenario.t1=0.5"], None, False),
    "scara-half-derivative": ("table2", ["scenario.duration=0.1", "scenario.k_xyz=[80000]",
                                         "scenario.controllers=[kd]"], None, False),
    "spherical-terrain": ("physics-check", ["system.duration=0.5", "scenario.classes=[rt]"], None, False),
    "src-joint": ("joint-model", ["scenario.duration=0.5", "scenario.plants=[mujoco]"], "mujoco-corrected", False),
    "src-joint/avoid-obstacles": ("avoid-obstacles", ["scenario.duration=1.0", "scenario.cases=[avoid]"], "avoid",
                                  True),
    "src-joint/exact": ("joint-model", ["scenario.duration=2.0", "scenario.plants=[exact]"], "exact-corrected", True),
    "src-joint/eq5-loop": ("reach-floor", ["scenario.loop.side=0.3"], "eq5-loop", True),
    "admittance-assembly": ("mujoco-crosscheck", ["scenario.cases=[spatial]", "scenario.runs=[static]",
                                                  "scenario.admittance=isotropic"], None, False),
    "srs-collision-avoidance": ("circle", ["scenario.cases=[avoid]", "system.task.samples=40"], None, False),
    "quadruped-irondog": ("stand", ["scenario.duration=0.2", "scenario.payloads=[0]"], None, True),
    "forrest-biped": ("walking", ["system.walk.duration=0.6", "scenario.window=[0.2,0.6]",
                                  "scenario.lipm_zmp_lags=[0.0]"], "traditional", True),
    "dyad-triad-synthesis": ("four-bar", ["scenario.leg_duration=0.1"], "replay-1to5", True),
    "itbot-smc": ("tracking", ["system.reference.period=2.5"], "smc-mujoco", False),
    "kinematic-graph": ("search", ["scenario.scenes=[obstacle]"], "obstacle-cspace", False),
}


@pytest.fixture(scope="module")
def paper_runs(tmp_path_factory):
    """Runs are made on demand, one per paper, in this process (no CLI start-up)."""
    made: dict[str, object] = {}

    def run(key: str):
        if key not in made:
            name, overrides, case_id, _ = PAPER_RUNS[key]
            slug = key.split("/")[0]
            made[key] = simulate_case(tmp_path_factory.mktemp(slug), f"{slug}/{name}", overrides, case_id)
        return made[key]

    return run


def _urdf(run) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(io.StringIO(run["/robot_description"]["data"].iloc[0]), load_meshes=False,
                              load_collision_meshes=False)


def _joint_state_names(run) -> list[str]:
    columns = run["/joint_states"].columns
    return [c.removeprefix("joints.").removesuffix(".name") for c in columns if c.endswith(".name")]


@pytest.mark.parametrize("slug", sorted(PAPER_RUNS))
def test_every_articulated_paper_draws_its_robot(slug, paper_runs):
    """The run carries its URDF; it parses, its movable joints are the joint-state channel's, and its FK equals
    MuJoCo's on the attached model at random states; where the paper's /tf names the model's bodies, the URDF
    moved by the logged joint states puts them there."""
    run = paper_runs(slug)
    assert {robot.ROBOT_DESCRIPTION, robot.JOINT_STATES, robot.ROBOT_TF} <= set(run.topic_names)
    urdf = _urdf(run)
    assert sorted(urdf.actuated_joint_names) == sorted(_joint_state_names(run))
    model = mujoco.MjModel.from_xml_string(run.attachments["model.xml"].decode())
    description = describe(model)
    assert description.urdf() == run.attachments[robot.URDF_ATTACHMENT].decode()
    assert_urdf_fk_is_mujocos(urdf, description, model, random_states(model, 3, seed=7))
    if PAPER_RUNS[slug][3]:
        states, tf = run["/joint_states"], run["/tf"]
        names = _joint_state_names(run)
        shared = [model.body(b).name for b in range(1, model.nbody)
                  if f"transforms.{model.body(b).name}.translation.x" in tf.columns]
        assert shared
        for t in states.index[::max(1, len(states) // 4)].intersection(tf.index):
            urdf.update_cfg({n: states.loc[t, f"joints.{n}.position"] for n in names})
            for body in shared:
                logged = [tf.loc[t, f"transforms.{body}.translation.{a}"] for a in "xyz"]
                assert np.allclose(urdf.get_transform(f"{description.name}/{body}", "world")[:3, 3], logged,
                                   atol=1e-9), (body, t)


@pytest.mark.parametrize("slug", ["admittance-assembly", "forrest-biped", "quadruped-irondog", "spherical-terrain",
                                  "src-joint"])
def test_contacts_are_drawn_as_points_with_force_arrows(slug, paper_runs):
    """Contact forces on /markers: an arrow from each contact point, sent again at every drawn instant."""
    scene = paper_runs(slug)["/markers"]
    contacts = scene[scene["entities.0.id"] == "contacts"]
    drawn = (contacts.filter(regex=r"^entities\.0\.arrows\.\d+\.shaft_length$").fillna(0) > 0).any(axis=1)
    assert drawn.sum() > 1 and np.diff(contacts.index).min() > 0


@pytest.mark.skipif(shutil.which("rerun") is None, reason="rerun CLI (rerun-sdk) not on PATH")
def test_view_places_every_marker_in_its_frame(tmp_path):
    """Each archetype converted from /markers carries its /tf frame (a child entity does not inherit its parent's
    CoordinateFrame: geometry without one is drawn nowhere), and contacts gone are cleared."""
    from analysis import view

    path = tmp_path / "r.mcap"
    with RunWriter(path, {"run_id": "r", "slug": "demo"}) as w:
        w.log_transforms(np.zeros(1), "world", ["pad"], np.eye(4)[None, None])
        w.log_contacts(np.array([0.0, 0.1]), [np.zeros((1, 3)), np.zeros((0, 3))],
                       [np.array([[0.0, 0.0, 5.0]]), np.zeros((0, 3))], 0.01, frame="pad")
        w.close("ok")
    printed = subprocess.run(["rerun", "rrd", "print", str(view.convert(path, tmp_path / "r.rrd"))], check=True,
                             env=ENV, capture_output=True, text=True, timeout=120).stdout
    geometry = [line for line in printed.splitlines() if "/markers/" in line and ("Arrows3D" in line or
                                                                                 "Ellipsoids3D" in line)]
    assert {"/markers/contacts/arrows", "/markers/contacts/spheres"} <= {line.split(" - ")[1] for line in geometry}
    assert all("CoordinateFrame:frame" in line for line in geometry)
    cleared = {line.split(" - ")[1] for line in printed.splitlines() if "Clear:is_recursive" in line}
    assert cleared == {"/markers/contacts/arrows", "/markers/contacts/spheres"}   # the second instant has none


def test_one_pose_composed_on_floats_equals_the_batched_arithmetic():
    rng = np.random.default_rng(8)
    for _ in range(500):
        a, b = (Pose(rng.standard_normal(3), rng.standard_normal(4)) for _ in range(2))
        c = a @ b
        assert np.array_equal(c.p, a.p + _rotate(a.q, b.p)) and np.array_equal(c.q, _quat_mul(a.q, b.q))


@pytest.mark.parametrize("sequence", ["xyz", "XYZ"])
def test_euler_angles_give_back_the_rotation(sequence):
    """URDF rpy and the moving-axis triple of a ball joint: the angles rebuild each quaternion's rotation, at
    random rotations and at gimbal lock (middle angle ±π/2), and equal SciPy's away from it."""
    from scipy.spatial.transform import Rotation

    rotations = Rotation.concatenate([Rotation.random(2000, random_state=3)] + [
        Rotation.from_euler(sequence, [[0.3, s * np.pi / 2, 0.2], [-2.0, s * np.pi / 2, 0.0]]) for s in (1, -1)])
    quats = rotations.as_quat(scalar_first=True)
    angles = _euler(quats, sequence)
    assert np.abs(Rotation.from_euler(sequence, angles).as_matrix() - rotations.as_matrix()).max() < 1e-13
    assert np.abs(angles[:2000] - rotations[:2000].as_euler(sequence)).max() < 1e-12
    with pytest.raises(ValueError, match="Euler sequence"):
        _euler(quats, "zyx")
