"""Simulate stage of `quadruped-irondog`: the paper's tables as data, the kinematics of Secs. 3.1 and 3.3, and
the MuJoCo robot standing (Table 5), moving its body (Fig. 18), levelling itself on a tilting bench (Figs. 19-20)
and trotting (Sec. 4.3, Figs. 21-22). Every MuJoCo run logs the common topics (joints, references, servo
commands, tracking errors, foot contact forces on /wrench and as arrows on /markers, /tf of every body, the robot
drawn from its MuJoCo model: URDF, joint states, link frames) and the trunk's pose and IMU angles on /body."""

from __future__ import annotations

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import log_timings, time_calls
from pipeline.papers.quadruped_irondog import kinematics as kin
from pipeline.papers.quadruped_irondog.control import BodyPose, Levelling, PoseSchedule, TrotController, smoothstep
from pipeline.papers.quadruped_irondog.gait import Trot, bezier, de_casteljau
from pipeline.papers.quadruped_irondog.kinematics import JOINT_NAMES, LEGS, Leg
from pipeline.papers.quadruped_irondog.model import Robot, Scene
from pipeline.papers.quadruped_irondog.simulation import Fall, Plant, Trace, simulate
from pipeline.papers.quadruped_irondog.statics import static_torques

XYZ = ("x", "y", "z")
FEET_FIELDS = [f"{leg}.{a}" for leg in LEGS for a in XYZ]

TableRow = schemas.define(
    "IronDogTableRow", "One row of a table printed in the paper, as printed (units in the column names).",
    table="string", row="string", name="string[]", value="double[] q",
)
Trunk = schemas.define(
    "IronDogTrunk", "The trunk (its IMU frame, at the centre of the hips) in the world: x, y, z (m); roll, pitch, "
    "yaw (rad, R = Rz(yaw) Ry(pitch) Rx(roll)); linear velocity vx, vy, vz (m/s).",
    x="double m", y="double m", z="double m", roll="double rad", pitch="double rad", yaw="double rad",
    vx="double m/s", vy="double m/s", vz="double m/s",
)
Feet = schemas.define(
    "IronDogFeet", "Foot positions (m) in each leg's frame (x lateral outward, y up, z forward, origin at the coxa "
    "joint), from the measured joint angles.", name="string[]", position="double[] m",
)
FeetInBody = schemas.define(
    "IronDogFeetInBody", "Foot positions (m) in the body frame (x forward, y left, z up, origin at the hips' centre).",
    name="string[]", position="double[] m",
)
Bench = schemas.define("IronDogBench", "The tilting bench's angles (rad).", pitch="double rad", roll="double rad")
Balance = schemas.define(
    "IronDogBalance", "The body rotation (rad) the levelling PID commands through body IK.", roll="double rad",
    pitch="double rad",
)
StaticTorque = schemas.define(
    "IronDogStaticTorque", "Hand statics of a standing pose: servo torque (N·m) per joint, at the commanded pose "
    "and at the pose MuJoCo settled in.", name="string[]", commanded="double[] N*m", settled="double[] N*m",
)
StaticLoad = schemas.define(
    "IronDogStaticLoad", "Hand statics of a standing pose: vertical load (N) per foot, at the commanded pose and at "
    "the pose MuJoCo settled in.", name="string[]", commanded="double[] N", settled="double[] N",
)
GaitTiming = schemas.define(
    "IronDogGaitTiming", "A trot run's timing (s): step cycle, swing, when the trot starts, when the steady window "
    "starts.", cycle_time="double s", swing_time="double s", trot_start="double s",
    steady_start="double s",
)
# the paper's printed tables and numbers keep their units, which their names end in
PRINTED_UNITS = {"_g": "g", "_kg": "kg", "_usd": "USD", "_mm": "mm", "_n": "N", "_mpa": "MPa"}


def printed_units(names) -> list[str]:
    """The unit each printed column's name ends in (`total_g` -> g); counts and ratios are pure numbers."""
    return [next((u for suffix, u in PRINTED_UNITS.items() if n.endswith(suffix)), "1") for n in names]


# -- config -> objects -----------------------------------------------------------------------------------------


def robot_of(cfg: DictConfig) -> Robot:
    return Robot.from_config(OmegaConf.to_container(cfg.system, resolve=True))


def table5_pose(cfg: DictConfig, state: str = "standing") -> np.ndarray:
    """(4, 3) Table 5 pose in the joint convention of eqs. (38)-(40) (the paper's URDF mirrors the left femurs)."""
    t5 = cfg.system.table5[f"{state}_deg"]
    sign = np.asarray(cfg.system.table5.femur_sign, dtype=float)
    return np.radians(np.column_stack([t5.coxa, np.asarray(t5.femur, dtype=float) * sign, t5.tibia]))


def trot_of(cfg: DictConfig, robot: Robot, cycle_time: float | None = None) -> Trot:
    g = cfg.system.gait
    cycle = g.cycle_time if cycle_time is None else cycle_time
    return Trot(np.asarray(g.control_points_mm, dtype=float) * 1e-3, swing_time=cycle * (1 - g.duty_factor),
                stance_time=cycle * g.duty_factor, a_sign=-1.0 if g.a_points == "backward" else 1.0,
                lateral=robot.leg.L1)


def fall_of(cfg: DictConfig) -> Fall:
    return Fall(cfg.system.fall.min_height, np.radians(cfg.system.fall.max_tilt_deg))


def _periods(cfg: DictConfig) -> tuple[float, float]:
    return 1.0 / cfg.system.control.rate_hz, 1.0 / cfg.system.log.rate_hz


# -- logging ---------------------------------------------------------------------------------------------------


FORCE_SCALE = 0.01   # m/N: the standing robot's 4-9 N per foot drawn 4-9 cm long


def log_model(log: RunWriter, plant: Plant) -> None:
    log.attach("model.xml", plant.xml, "application/xml")


def log_trace(log: RunWriter, plant: Plant, trace: Trace, cfg: DictConfig, q_ref: np.ndarray | None = None,
              feet_ref: np.ndarray | None = None) -> None:
    """The common topics of a MuJoCo run. `q_ref` (N, 12) and `feet_ref` (N, 4, 3, leg frames) are the continuous
    references where they differ from the servo commands (the trot's Bezier between control instants)."""
    t, leg = trace.t, plant.robot.leg
    log.log_series("/joint_state", t, units="rad", name=JOINT_NAMES, position=trace.q, velocity=trace.qd,
                   effort=trace.tau)
    log.log_series("/command", t, units="rad", kind="position", name=JOINT_NAMES, value=trace.q_cmd)
    reference = trace.q_cmd if q_ref is None else q_ref
    log.log_series("/reference", t, units="rad", name=JOINT_NAMES, position=reference)
    error = reference - trace.q
    log.log_series("/tracking_error", t, units="rad", name=JOINT_NAMES, error=error, norm=np.linalg.norm(error, axis=1))
    log.log_series("/joint_state/motor", t, units="rad", name=JOINT_NAMES,
                   effort=trace.tau_motor)   # the saturating part
    f = trace.contact_force
    log.log_series("/wrench", t, frame_id="world", name=list(LEGS), force_x=f[..., 0], force_y=f[..., 1],
                   force_z=f[..., 2], torque_x=np.zeros_like(f[..., 0]), torque_y=np.zeros_like(f[..., 0]),
                   torque_z=np.zeros_like(f[..., 0]))
    log.log_series("/contact", t, schemas.Scalars, units="1", name=list(LEGS), value=trace.contact)
    rpy, v = trace.rpy, trace.trunk_velocity
    log.log_series("/body", t, Trunk, x=trace.qpos[:, 0], y=trace.qpos[:, 1], z=trace.qpos[:, 2], roll=rpy[:, 0],
                   pitch=rpy[:, 1], yaw=rpy[:, 2], vx=v[:, 0], vy=v[:, 1], vz=v[:, 2])
    feet = kin.fk(leg, trace.q.reshape(-1, 4, 3))
    log.log_series("/feet", t, Feet, name=FEET_FIELDS, position=feet.reshape(len(t), -1))
    if feet_ref is not None:
        log.log_series("/reference/feet", t, units="m", name=FEET_FIELDS, position=feet_ref.reshape(len(t), -1))
        e = feet_ref - feet
        log.log_series("/tracking_error/feet", t, units="m", name=FEET_FIELDS, error=e.reshape(len(t), -1),
                       norm=np.linalg.norm(e.reshape(len(t), -1), axis=1))
    if len(plant.idx.platform_qpos):
        bench = trace.qpos[:, plant.idx.platform_qpos]
        log.log_series("/platform", t, Bench, pitch=bench[:, 0], roll=bench[:, 1])
    every = max(1, round(cfg.system.log.rate_hz / cfg.system.log.tf_rate_hz))
    poses = plant.poses(trace.qpos[::every])
    bodies = plant.idx.bodies
    tibia = [bodies.index(f"{name}_tibia") for name in LEGS]
    foot = poses[:, tibia].copy()
    foot[..., :3, 3] += np.einsum("nkij,j->nki", poses[:, tibia, :3, :3], [0.0, 0.0, -leg.L3])
    log.log_transforms(t[::every], "world", [*bodies, *(f"{name}_foot" for name in LEGS)],
                       np.concatenate([poses, foot], axis=1))
    log.log_robot(t[::every], trace.qpos[::every])   # the free trunk and the bench: the full MuJoCo state
    touching = trace.contact[::every] > 0
    log.log_contacts(t[::every], [p[c] for p, c in zip(foot[..., :3, 3], touching, strict=True)],
                     [f[c] for f, c in zip(trace.contact_force[::every], touching, strict=True)], FORCE_SCALE)
    log.log_series("/compute_time", trace.control_t, name=["control_step"], calls=[1],
                   seconds=trace.control_seconds[:, None])


def finish(trace: Trace) -> None:
    """A run that fell is a failed run: its reason goes into the run's status (the trace is already logged)."""
    if trace.failure:
        raise SimulationFailed(trace.failure)


# -- Tables 2, 4, 6 and Sec. 4.1's arithmetic, as printed -------------------------------------------------------


def tables(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario

    def simulate_(log: RunWriter) -> None:
        t = 0.0
        for table, spec in sc.tables.items():
            columns = list(spec.columns)
            for row, values in spec.rows.items():
                log.log("/tables", t, TableRow, units=printed_units(columns), table=table, row=row, name=columns,
                        value=[float(v) for v in values])
                t += 1e-3   # one row per millisecond: a table is a sequence of records, not a trajectory
        log.log("/text", 0.0, schemas.Scalars, units=printed_units(sc.text), name=list(sc.text),
                value=[float(v) for v in sc.text.values()])

    return [Case("paper-data", simulate_)]


# -- Secs. 3.1, 3.3: Bezier swing, IK round trips, Table 5 poses, compute time ------------------------------------


def kinematics(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    robot = robot_of(cfg)
    corrected = Leg(robot.leg.L1, robot.leg.L2, robot.leg.L3)
    printed = Leg(robot.leg.L1, robot.leg.L2, robot.leg.L3, printed=True)
    trot = trot_of(cfg, robot)

    def simulate_(log: RunWriter) -> None:
        P = trot.control_points
        s = np.linspace(0.0, 1.0, sc.bezier_samples)
        curve = bezier(P, s)
        casteljau = np.array([de_casteljau(P, x) for x in s])
        times = s * trot.swing_time
        log.log_series("/reference/bezier", times, units="m", name=["a", "d"], position=curve)
        log.log_series("/bezier/de_casteljau", times, schemas.Scalars, units="m", name=["a_m", "d_m"], value=casteljau)
        # the swing in the leg frame and its joint angles, with both forms of eq. (40)
        phase = s * trot.swing_fraction
        swing = np.stack([np.full_like(s, trot.lateral), trot.curve(phase)[:, 1],
                          trot.a_sign * trot.curve(phase)[:, 0]], axis=1)
        q = kin.ik(corrected, swing)
        log.log_series("/reference", times, units="rad", name=list(kin.JOINTS), position=q)
        for name, leg in (("corrected", corrected), ("printed", printed)):
            err = np.linalg.norm(kin.fk(corrected, kin.ik(leg, swing)) - swing, axis=1)
            log.log_series(f"/ik/bezier/{name}", times, schemas.Scalars, units="m", name=["fk_ik_error_m"],
                           value=err[:, None])
        # the workspace: random poses on the IK's branch (θ3 ∈ (0, π), foot below the femur joint)
        rng = np.random.default_rng(cfg.seed)
        lo, hi = robot.ranges[:, 0], robot.ranges[:, 1]
        q_ws = rng.uniform(np.maximum(lo, [-np.pi / 2, -np.pi / 2, 0.05]), np.minimum(hi, [np.pi / 2, np.pi / 2, 3.0]),
                           (sc.workspace_samples, 3))
        q_ws = q_ws[kin.fk(Leg(0.0, robot.leg.L2, robot.leg.L3), q_ws)[:, 1] < 0]
        p_ws = kin.fk(corrected, q_ws)
        sample_t = np.arange(len(q_ws)) * 1e-3
        values = [np.linalg.norm(kin.fk(corrected, kin.ik(corrected, p_ws)) - p_ws, axis=1),
                  np.abs(kin.ik(corrected, p_ws) - q_ws).max(axis=1),
                  np.linalg.norm(kin.fk(corrected, kin.ik(printed, p_ws)) - p_ws, axis=1)]
        log.log_series("/ik/workspace", sample_t, schemas.Scalars, units=["m", "rad", "m"],
                       name=["fk_ik_error_m", "ik_fk_error_rad", "printed_fk_ik_error_m"],
                       value=np.column_stack(values))
        # Table 5's feet in the body frame
        for state in ("ideal", "standing"):
            feet = kin.feet_in_body(corrected, robot.layout, table5_pose(cfg, state))
            log.log(f"/table5/{state}", 0.0, FeetInBody, name=FEET_FIELDS, position=feet.ravel().tolist())
        # per call: one leg's IK (scalar), a batch of 4 legs, the Bezier at one s
        point = swing[len(swing) // 2]
        feet4 = np.tile(point, (4, 1))
        timings = [time_calls("ik_leg", kin.ik, [(corrected, point)], warmup=200, repeats=sc.timing_calls),
                   time_calls("ik_4_legs", kin.ik, [(corrected, feet4)], warmup=200, repeats=sc.timing_calls,
                              items_per_call=4),
                   time_calls("bezier", bezier, [(P, 0.37)], warmup=200, repeats=sc.timing_calls)]
        log_timings(log, timings)

    return [Case("ik-bezier", simulate_)]


# -- Table 5 standing, Fig. 16 ------------------------------------------------------------------------------------


def stand(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    robot = robot_of(cfg)
    q_stand = table5_pose(cfg)
    control_dt, log_dt = _periods(cfg)

    def simulate_(log: RunWriter, payload: float) -> None:
        plant = Plant(robot, Scene(payload=payload))
        log_model(log, plant)
        plant.place(q_stand)
        trace = simulate(plant, lambda t, rpy: q_stand, sc.duration, control_dt, log_dt, fall_of(cfg))
        log_trace(log, plant, trace, cfg)
        # the hand statics at the commanded pose, and at the pose MuJoCo settled in
        tau_cmd, load_cmd = static_torques(robot, q_stand, payload)
        tau_set, load_set = static_torques(robot, trace.q[-1].reshape(4, 3), payload, trace.rpy[-1])
        end = float(trace.t[-1])
        log.log("/statics/torque", end, StaticTorque, name=JOINT_NAMES, commanded=tau_cmd.ravel().tolist(),
                settled=tau_set.ravel().tolist())
        log.log("/statics/load", end, StaticLoad, name=list(LEGS), commanded=load_cmd.tolist(),
                settled=load_set.tolist())
        finish(trace)

    return [Case("robot" if not p else f"payload-{p:g}kg", lambda log, p=float(p): simulate_(log, p))
            for p in sc.payloads]


# -- Fig. 18: body translations and rotations by body IK -----------------------------------------------------------

FIG18 = ("2 +x", "3 -x", "4 +y", "5 -y", "6 -z", "7 +pitch", "8 -pitch", "9 +roll", "10 -roll", "11 +yaw", "12 -yaw")


def fig18_offsets(translation: float, rotation: float) -> np.ndarray:
    """(11, 6) the trunk offsets (x, y, z m; roll, pitch, yaw rad) of Fig. 18's scenarios 2-12, in FIG18's order."""
    offsets = np.zeros((len(FIG18), 6))
    for k, name in enumerate(FIG18):
        axis = name.split()[1]
        sign = 1.0 if axis[0] == "+" else -1.0
        index = ["x", "y", "z", "roll", "pitch", "yaw"].index(axis[1:])
        offsets[k, index] = sign * (translation if index < 3 else rotation)
    return offsets



def body_poses(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    robot = robot_of(cfg)
    q_stand = table5_pose(cfg)
    control_dt, log_dt = _periods(cfg)
    schedule = PoseSchedule(fig18_offsets(sc.translation, np.radians(sc.rotation_deg)), sc.ramp, sc.hold,
                            start=sc.settle)

    def simulate_(log: RunWriter) -> None:
        plant = Plant(robot, Scene())
        log_model(log, plant)
        plant.place(q_stand)
        pose = BodyPose(robot.leg, robot.layout, q_stand)

        def controller(t: float, rpy: np.ndarray) -> np.ndarray:
            x = schedule(t)
            return pose(x[:3], x[3:])

        trace = simulate(plant, controller, schedule.duration + sc.settle, control_dt, log_dt, fall_of(cfg))
        log_trace(log, plant, trace, cfg)
        commanded = schedule(trace.t)
        scenario = schedule.holding(trace.t).astype(float)
        log.log_series("/reference/body", trace.t, units=["m", "m", "m", "rad", "rad", "rad"],
                       name=["x", "y", "z", "roll", "pitch", "yaw"], position=commanded)
        log.log_series("/scenario", trace.t, schemas.Scalars, units="1", name=["holding"],
                       value=(scenario + 1)[:, None])
        finish(trace)

    return [Case("fig18", simulate_)]


# -- Figs. 19-20: self-levelling on a tilting bench ----------------------------------------------------------------


def self_levelling(cfg: DictConfig) -> list[Case]:
    sc, bal = cfg.scenario, cfg.system.balance
    robot = robot_of(cfg)
    q_stand = table5_pose(cfg)
    control_dt, log_dt = _periods(cfg)
    tilt = np.radians(sc.tilt_deg)

    def simulate_(log: RunWriter, axis: str, enabled: bool) -> None:
        plant = Plant(robot, Scene(platform=True))
        log_model(log, plant)
        plant.place(q_stand)
        loop = Levelling(BodyPose(robot.leg, robot.layout, q_stand), bal.kp, bal.ki, bal.kd,
                         np.radians(bal.limit_deg), control_dt, enabled)
        outputs = []

        def controller(t: float, rpy: np.ndarray) -> np.ndarray:
            q = loop(t, rpy)
            outputs.append(loop.output.copy())
            return q

        def bench(t: float) -> np.ndarray:
            angle = tilt * smoothstep((t - sc.tilt_start) / sc.tilt_ramp)
            return np.array([angle, 0.0]) if axis == "pitch" else np.array([0.0, angle])

        trace = simulate(plant, controller, sc.duration, control_dt, log_dt, fall_of(cfg), platform=bench)
        log_trace(log, plant, trace, cfg)
        offsets = np.array(outputs)[:len(trace.control_t)]
        log.log_series("/balance", trace.control_t, Balance, roll=offsets[:, 0], pitch=offsets[:, 1])
        finish(trace)

    return [Case(f"{axis}-{'levelled' if enabled else 'open-loop'}",
                 lambda log, a=axis, e=enabled: simulate_(log, a, e))
            for axis in sc.axes for enabled in (True, False)]


# -- Sec. 4.3, Figs. 21-22: the trot on flat ground ----------------------------------------------------------------


def trot(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    robot = robot_of(cfg)
    q_stand = table5_pose(cfg)
    control_dt, log_dt = _periods(cfg)

    def simulate_(log: RunWriter, cycle_time: float) -> None:
        gait = trot_of(cfg, robot, cycle_time)
        controller = TrotController(robot.leg, gait, q_stand, sc.settle, sc.rise, sc.ramp_cycles * gait.period,
                                    cfg.system.gait.stride_scale)
        plant = Plant(robot, Scene())
        log_model(log, plant)
        plant.place(q_stand)
        duration = controller.start + sc.cycles * gait.period
        trace = simulate(plant, controller, duration, control_dt, log_dt, fall_of(cfg))
        feet_ref, swing = controller.feet(trace.t)
        q_ref = kin.ik(robot.leg, feet_ref).reshape(len(trace.t), -1)
        log_trace(log, plant, trace, cfg, q_ref=q_ref, feet_ref=feet_ref)
        steady = controller.start + (sc.ramp_cycles + sc.skip_cycles) * gait.period
        log.log("/gait/timing", 0.0, GaitTiming, cycle_time=gait.period, swing_time=gait.swing_time,
                trot_start=controller.start, steady_start=steady)
        log.log_series("/gait", trace.t, schemas.Scalars, units="1",
                       name=[*(f"swing.{leg}" for leg in LEGS), *(f"phase.{leg}" for leg in LEGS), "stride_scale"],
                       # swing: 1 in swing; phase: share of the cycle; stride_scale: share of the paper's stride
                       value=np.column_stack([swing, gait.phase(np.maximum(trace.t - controller.start, 0.0)),
                                              controller.stride(trace.t)]))
        finish(trace)

    return [Case(f"cycle-{c:g}s", lambda log, c=float(c): simulate_(log, c)) for c in sc.cycle_times]
