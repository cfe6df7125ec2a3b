"""Simulate stage of `gripper-force-control`: Fig. 8 (force sag in three cases, on both plants), Fig. 9 (one
point of the max-force-error surface per run: a Hydra sweep over ω × ε), the pick-and-place cycle (Tables
3 and 5, the tomato timings), a Monte-Carlo stand-in for Fig. 7, and Tables 2-5 with the model's constants.

Every run logs the measured grasp force on `/wrench` and the commanded one (F_set) on `/wrench/commanded`,
both Wrench records named `grasp` with the force along the pad normal in `force_x`; the force error is
their difference, computed by the analysis (analysis.core.errors.force_error_stats).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import markers, robot, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed, seconds_to_ns
from pipeline.papers.gripper_force_control import lumped
from pipeline.papers.gripper_force_control.drive import Schedule, move_duration, schedule
from pipeline.papers.gripper_force_control.lumped import Start, Trace, static_grasp
from pipeline.papers.gripper_force_control.model import Gripper, gripper
from pipeline.papers.gripper_force_control.mujoco_plant import FRAMES, MujocoGripper

JOINTS = ["m1", "m2", "gripper", "finger"]
FORCE_RGBA, FORCE_SCALE = (0.95, 0.5, 0.1, 1.0), 0.005  # the grasp force drawn at 5 mm/N
PLANTS = ("mujoco", "lumped")

TableRow = schemas.define(
    "GripperTableRow", "One row of a comparison table of the gripper paper (datasheet values as printed).",
    table="string", gripper="string", name="string[]", value="double[] q",
)
# the units of the tables' columns (and of the Sect. 5 text's rows), as the paper prints them
TABLE_UNITS = {"peak_force": "N", "flange_mass": "kg", "frame_mass": "kg", "total_mass": "kg", "finger_speed": "m/s",
               "printed_ratio": "1", "max_force_error": "N", "time_min": "s", "time_max": "s", "travel": "m",
               "min_force": "N", "damage_force_min": "N", "safety_factor": "1", "force_error": "N",
               "open_close_time": "s", "lift_rotate_time": "s", "cycle_time": "s", "rate": "1/min"}
MODEL_UNITS = {"l_a": "m", "h_g": "m", "force_per_amp": "N/A", "K_eps": "A/(rad/s^2)", "K_omega": "V/(rad/s)",
               "K_eps_printed": "A/(rad/s^2)", "K_omega_printed": "V/(rad/s)", "current_pole": "1/s",
               "current_zero": "1/s", "current_bandwidth": "1/s", "velocity_crossover": "rad/s",
               "position_bandwidth": "1/s", "move_40deg": "s", "move_45deg": "s", "voltage_limited_finger_speed": "m/s"}
GraspSample = schemas.define(
    "GripperGraspSample", "The random draws of Monte-Carlo grasps: approach gap (m) and M1 Coulomb friction (N m).",
    name="string[]", force_set="double[] N", gap="double[] m", m1_coulomb="double[] N*m",
)


# -- running a case on a plant ------------------------------------------------------------------------


def run_plant(log: RunWriter, cfg: DictConfig, p: Gripper, s: Schedule, start: Start, plant: str,
              open_stop: float | None = None) -> None:
    """Simulate one run on `plant` and log it, with the generated MuJoCo model drawn: the plant itself, or
    the lumped plant's state shown on it (MujocoGripper.configuration says which coordinate drives which
    joint). `open_stop`: MuJoCo's finger stops there when opening (the lumped plant has no stops)."""
    if plant not in PLANTS:
        raise ValueError(f"plant={plant!r}: one of {PLANTS}")
    log_every, tf_every = max(1, round(cfg.log_dt / p.dt)), max(1, round(cfg.tf_dt / p.dt))
    sim = MujocoGripper(p, cfg.system.contact, open_stop if plant == "mujoco" else None)
    log.attach("model.xml", sim.xml, "application/xml")
    t_tf = s.t[::tf_every]
    if plant == "mujoco":
        trace, poses = sim.simulate(s, start, log_every, settle=cfg.mujoco.settle, tf_every=tf_every)
        states = np.array(sim.states)
    else:
        trace = lumped.simulate(p, s, start, log_every)
        # drawn: φ_g (rad) turns hinge `gripper`, φ_f (rad) hinge `finger`, δ = l_f·φ_f ≥ 0 (m) slides `pad`
        states, poses = sim.drawn(*(np.interp(t_tf, trace.t, trace[x]) for x in ("phi_g", "phi_f")))
    if not np.isfinite(trace["force"]).all():
        raise SimulationFailed("grasp force not finite")
    draw_grasp(log, s, trace, t_tf, states, poses)
    log_trace(log, p, s, trace, log_every)


def draw_grasp(log: RunWriter, s: Schedule, trace: Trace, t_tf: np.ndarray, states: np.ndarray,
               poses: np.ndarray) -> None:
    """The gripper at times `t_tf` (s): its bodies on `/tf`, its robot (qpos `states` of the attached model),
    and on `/markers` the grasp force as an arrow on the pad with the force error F_set − F in red from the
    arrow's tip."""
    log.log_transforms(t_tf, "world", list(FRAMES), poses)
    log.log_robot(t_tf, states)
    force = np.interp(t_tf, trace.t, trace["force"])  # along the pad's x (/wrench frame)
    error = np.interp(t_tf, s.t, s.force) - force
    keep = robot.thinned(t_tf)
    for t_k, f_k, e_k in zip(t_tf[keep], force[keep], error[keep], strict=True):
        log.write("/markers", seconds_to_ns(t_k), schemas.SceneUpdate(entities=[
            markers.arrow("grasp_force", "pad", [f_k, 0.0, 0.0], FORCE_RGBA, scale=FORCE_SCALE),
            markers.contacts("force_error", [[FORCE_SCALE * f_k, 0.0, 0.0]], [[e_k, 0.0, 0.0]], FORCE_SCALE,
                             frame="pad", diameter=0.002)]))


def log_trace(log: RunWriter, p: Gripper, s: Schedule, trace: Trace, log_every: int) -> None:
    """The common topics of one run (a batch: one Wrench entry per grasp)."""
    t, g = trace.t, p.gear
    force, commanded = trace["force"], s.force[::log_every]
    if force.ndim == 1:
        force, commanded = force[:, None], commanded[:, None]
        names = ["grasp"]
    else:
        names = [f"grasp{i:03d}" for i in range(force.shape[1])]
    zero = np.zeros_like(force)
    for topic, value in (("/wrench", force), ("/wrench/commanded", commanded)):
        log.log_series(topic, t, frame_id="pad", name=names, force_x=value, force_y=zero, force_z=zero,
                       torque_x=zero, torque_y=zero, torque_z=zero)
    if trace["phi_g"].ndim > 1:
        return
    phi_g, omega_g = trace["phi_g"], trace["omega_g"]
    position = np.column_stack([trace["phi_1"], -g.g_c * phi_g, phi_g, trace["phi_f"]])
    velocity = np.column_stack([trace["omega_1"], -g.g_c * omega_g, omega_g, trace["omega_f"]])
    effort = np.column_stack([p.K_t * trace["I_1"], -p.K_t * trace["I_2"], g.g_c * p.K_t * trace["I_2"],
                              trace["force"] * p.l_f])   # motor torques; M2's at the gripper; the fingers' load
    log.log_series("/joint_state", t, units="rad", name=JOINTS, position=position, velocity=velocity, effort=effort)
    phi_sr = s.phi_sr[::log_every]
    log.log_series("/reference", t, units="rad", name=["gripper"], position=phi_sr[:, None],
                   velocity=s.omega_sr[::log_every, None], acceleration=s.epsilon_sr[::log_every, None])
    log.log_series("/command", t, kind="voltage", name=["m1", "m2"],
                   value=np.column_stack([trace["U_1"], trace["U_2"]]))
    log.log_series("/drive/current", t, schemas.Scalars, units="A", name=["i_ref_m1", "i_m1", "i_ref_m2", "i_m2"],
                   value=np.column_stack([trace["I_ref_1"], trace["I_1"], trace["I_ref_2"], trace["I_2"]]))
    error = phi_sr - phi_g
    log.log_series("/tracking_error", t, units="rad", name=["gripper"], error=error[:, None], norm=np.abs(error))


def _case_gripper(cfg: DictConfig, friction: bool, feedforward: bool = True, **system_overrides) -> Gripper:
    system = cfg.system
    if system_overrides:
        system = OmegaConf.merge(system, OmegaConf.create(system_overrides))
    return gripper(system).with_case(friction=friction, feedforward=feedforward)


# -- X4 / Fig. 8: force sag during a 40° rotation ------------------------------------------------------


def force_sag(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario

    def simulate(log: RunWriter, p: Gripper, plant: str) -> None:
        duration = sc.start + move_duration(sc.angle, p.omega_max, p.epsilon_max) + sc.after
        s = schedule(p, duration, sc.force, [(sc.start, sc.angle)])
        run_plant(log, cfg, p, s, static_grasp(p, sc.force), plant)

    cases = []
    for name, case in sc.cases.items():
        if case is None:   # dropped by an override (a band sweeps only the cases its parameter acts on)
            continue
        p = _case_gripper(cfg, case.friction, case.feedforward)
        cases += [Case(f"{name}-{plant}", lambda log, p=p, plant=plant: simulate(log, p, plant)) for plant in sc.plants]
    for form in sc.forms:   # the printed coupling factor / eq. (9) gains, ideal case
        p = _case_gripper(cfg, False, True, gearbox={"coupling": form.coupling},
                          controller={"feedforward": form.feedforward})
        cases.append(Case(f"ideal-{form.plant}-coupling_{form.coupling}-ff_{form.feedforward}",
                          lambda log, p=p, plant=form.plant: simulate(log, p, plant)))
    return cases


# -- X5 / Fig. 9: one point of the max-force-error surface --------------------------------------------


def force_error_surface(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    p = _case_gripper(cfg, sc.friction)

    def simulate(log: RunWriter) -> None:
        move = move_duration(sc.angle, sc.omega, sc.epsilon)
        back = sc.start + move + sc.pause
        s = schedule(p, back + move + sc.after, sc.force, [(sc.start, sc.angle), (back, -sc.angle)],
                     omega_max=sc.omega, epsilon_max=sc.epsilon)
        run_plant(log, cfg, p, s, static_grasp(p, sc.force), sc.plant)

    return [Case("rotations", simulate)]


# -- pick and place: closing, 45° rotation, opening (Tables 3 and 5, the tomato timings) ----------------


def pick_and_place(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario

    def simulate(log: RunWriter, p: Gripper) -> None:
        s = schedule(p, sc.duration, sc.force, [(sc.rotate_at, sc.angle)], opening=(sc.open_at, sc.force))
        open_angle = -sc.stroke / p.l_f
        run_plant(log, cfg, p, s, Start(phi_f=open_angle), sc.plant, open_stop=open_angle - sc.stop_margin)

    cases = []
    for name, case in sc.cases.items():
        p = replace(_case_gripper(cfg, sc.friction), speed_limit=case.speed_limit)
        cases.append(Case(name, lambda log, p=p: simulate(log, p)))
    return cases


# -- Fig. 7 stand-in: Monte-Carlo steady-state errors ---------------------------------------------------


def steady_state(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario

    def simulate(log: RunWriter) -> None:
        rng = np.random.default_rng(cfg.seed)
        forces = np.repeat(np.asarray(sc.forces, dtype=float), sc.grasps)
        gap = rng.uniform(*sc.gap, forces.size)
        base = _case_gripper(cfg, True)
        coulomb = base.tau_c1 * rng.uniform(*sc.friction_scale, forces.size)
        p = replace(base, tau_c1=coulomb)
        s = schedule(p, sc.duration, forces)
        names = [f"grasp{i:03d}" for i in range(forces.size)]
        log.log("/montecarlo", 0.0, GraspSample, name=names, force_set=forces.tolist(), gap=gap.tolist(),
                m1_coulomb=coulomb.tolist())
        log_every = max(1, round(cfg.log_dt / p.dt))
        trace = lumped.simulate(p, s, Start(phi_f=-gap / p.l_f), log_every)
        log_trace(log, p, s, trace, log_every)

    return [Case("grasps", simulate)]


# -- Tables 2-5 as data, and the model's constants -------------------------------------------------------


def tables(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario

    def simulate(log: RunWriter) -> None:
        t = 0.0
        for table, rows in sc.tables.items():
            columns = list(rows.columns)
            for gripper_name, values in rows.rows.items():
                # a column holds one quantity; the text's one `value` column holds one per row: named by its row
                names = [gripper_name] if columns == ["value"] else columns
                log.log("/tables", t, TableRow, units=[TABLE_UNITS.get(c, "") for c in names], table=table,
                        gripper=gripper_name, name=names, value=[float(v) for v in values])
                t += 1e-3   # one row per millisecond: a table is a sequence of records, not a trajectory
        p = gripper(cfg.system)
        printed_ff = gripper(OmegaConf.merge(cfg.system, {"controller": {"feedforward": "printed"}}))
        g = p.gear
        constants = {
            "l_a": g.l_a, "g_c": g.g_c, "h_g": g.h_g, "g_ps": g.g_ps, "g_pf": g.g_pf, "g_f": g.g_f, "k_g": g.k_g,
            "force_per_amp": p.force_per_amp, "K_eps": p.K_eps, "K_omega": p.K_omega,
            "K_eps_printed": printed_ff.K_eps, "K_omega_printed": printed_ff.K_omega,
            "current_pole": p.R / p.L, "current_zero": 1 / p.T_c1, "current_bandwidth": p.K_c1 / p.L,
            "velocity_crossover": p.K_v * p.K_t * g.g_c / (p.J_g + p.J_1 * g.k_g ** 2),
            "position_bandwidth": p.K_p,
            "move_40deg": move_duration(np.deg2rad(40), p.omega_max, p.epsilon_max),
            "move_45deg": move_duration(np.deg2rad(45), p.omega_max, p.epsilon_max),
            "voltage_limited_finger_speed": p.l_f * (p.U_max - p.R * p.lookup(sc.tomato_force)) / p.K_e / g.g_f,
        }
        log.log("/model", 0.0, schemas.Scalars, name=list(constants), value=list(constants.values()),
                units=[MODEL_UNITS.get(name, "1") for name in constants])   # the rest are gear ratios

    return [Case("paper-data", simulate)]
