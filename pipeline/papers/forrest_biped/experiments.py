"""Simulate stage of `forrest-biped`: the drive curves (Figs. 8, 10-12), the pattern generators (Figs. 14-16), the
walk in MuJoCo with both generators and the LIP check (Figs. 18-20), and the same walk for a robustness sweep.

Topics of a walking run (every 1 ms controller cycle unless said):
    /joint_state, /command           the 12 joints (rad, rad/s) and torques (N m, the applied = commanded)
    /reference/com, /cp, /zmp, /feet the generator's references (m, m/s, m/s²)
    /balance                         measured CoM, CP, ZMP and the commanded ZMP p^c (schema ForrestBalance)
    /tracking_error, /cp, /zmp       CoM, CP error (reference − measured), ZMP error (p^c − measured CoP, at the
                                     samples in contact), m
    /wrench/left_foot, /right_foot   measured (from the four corner contacts) and QP-commanded foot wrench
    /wrench/com                      desired (eq. 53) and optimized (eq. 56) CoM wrench
    /wrench/contacts                 the force at each plate corner (N)
    /compute_time                    per cycle: the controller, its QP, its model update (s)
    /tf, /markers                    body frames and the robot's geoms, CoM/CP/ZMP frames and spheres (/tf at
                                     `scenario.tf_rate_hz`)
"""

from __future__ import annotations

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.papers.forrest_biped import generator as gen
from pipeline.papers.forrest_biped import lipm, mechanisms, walking
from pipeline.papers.forrest_biped.model import CORNERS, JOINTS, build
from pipeline.papers.forrest_biped.support import support_polygons
from pipeline.robotics.transforms import quaternion_wxyz

XYZ = ["x", "y", "z"]
FORCE_SCALE = 1e-3   # m/N: a sole's share of the robot's weight drawn some 0.1-0.3 m long

Balance = schemas.define(
    "ForrestBalance",
    "Per controller cycle: measured CoM (m), CoM velocity (m/s), capture point ξ = x_c + ẋ_c/ω (m), measured ZMP = "
    "CoP of all contact forces (m; z = 0 on the ground, NaN without contact), commanded ZMP p^c of eq. (50) after "
    "the clamp (m; z: the virtual eZMP height), support (0 both feet, 1 left, 2 right), DAQP exit flag of the "
    "wrench QP (1 = optimal; NaN: no QP) and its iterations, and the measured sole centres (m). `name` labels x, y, z.",
    name="string[]", com="double[] m", com_vel="double[] m/s", cp="double[] m", zmp="double[] m",
    zmp_cmd="double[] m", support="double 1", qp_flag="double 1", qp_iterations="double 1", left_sole="double[] m",
    right_sole="double[] m",
)
Curve = schemas.define(
    "ForrestCurve", "One sample of a curve over a joint angle or a grid of two (log time = sample index in ms): "
    "`name` labels `value`, each name ending in its unit.",
    name="string[]", value="double[] q",
)
# a Curve's names end in their unit: name suffix -> unit (the longest suffixes first)
SUFFIX_UNITS = {"_Nm_per_rad": "N*m/rad", "_m_per_rad": "m/rad", "_rad_s": "rad/s", "_m_s": "m/s", "_Nm": "N*m",
                "_rad": "rad", "_kg": "kg", "_J": "J", "_m": "m"}


def suffix_units(names) -> list[str]:
    """The unit each name ends in (`torque_Nm` -> N*m)."""
    return [next(u for suffix, u in SUFFIX_UNITS.items() if n.endswith(suffix)) for n in names]


def system_dict(cfg: DictConfig) -> dict:
    return OmegaConf.to_container(cfg.system, resolve=True)


def omega(cfg: DictConfig) -> float:
    """ω = sqrt(g / z_c) of the LIP (eq. 39)."""
    return float(np.sqrt(cfg.system.gravity / cfg.system.walk.z_c))


def make_pattern(cfg: DictConfig, kind: str, eq48: str | None = None, dt: float | None = None) -> gen.Pattern:
    """The references of generator `kind` on the controller's grid (or every `dt`)."""
    walk = OmegaConf.to_container(cfg.system.walk, resolve=True)
    if eq48 is not None:
        walk["eq48"] = eq48
    return gen.pattern(walk, kind, omega(cfg), cfg.system.controller.dt if dt is None else dt)


# -- logging ------------------------------------------------------------------------------------------------


def log_pattern(log: RunWriter, p: gen.Pattern, n: int | None = None) -> None:
    """The references on /reference/* (the first n cycles)."""
    n = len(p.t) if n is None else n
    t = p.t[:n]
    log.log_series("/reference/com", t, units="m", name=XYZ, position=p.com[:n], velocity=p.com_vel[:n],
                   acceleration=p.com_acc[:n])
    log.log_series("/reference/cp", t, units="m", name=XYZ, position=p.cp[:n])
    log.log_series("/reference/zmp", t, units="m", name=XYZ, position=p.zmp[:n])
    feet = [f"{side}.{a}" for side in ("left", "right") for a in XYZ]
    log.log_series("/reference/feet", t, units="m", name=feet, position=p.feet[:, :n].transpose(1, 0, 2).reshape(n, 6),
                   velocity=p.feet_vel[:, :n].transpose(1, 0, 2).reshape(n, 6),
                   acceleration=p.feet_acc[:, :n].transpose(1, 0, 2).reshape(n, 6))
    log.log_series("/pattern/support", t, schemas.Scalars, units="1", name=["support"], value=p.support[:n, None] * 1.0)


def log_steps(log: RunWriter, p: gen.Pattern) -> None:
    """One /pattern/steps record per step at its start: P0, P1 (NaN for the traditional), P2, and the CP's miss of
    P2 at the step end (eq. 47: zero for the extended generator)."""
    s, seg = p.steps, p.segments
    names = [f"{k}.{a}" for k in ("P0", "P1", "P2", "cp_end_miss") for a in XYZ]
    rows = []
    for i, t0 in enumerate(s.t0):
        j = int(np.searchsorted(seg.t, t0 + 1e-9) - 1)
        P1 = seg.p0[j + 1] if p.name == "extended" else np.full(3, np.nan)
        end = round((t0 + s.T) / (p.t[1] - p.t[0]))
        miss = (p.cp[end] - s.P2[i]) if end < len(p.t) else np.full(3, np.nan)
        rows.append(np.concatenate([s.P0[i], P1, s.P2[i], miss]))
    log.log_series("/pattern/steps", s.t0, schemas.Scalars, units="m", name=names, value=np.array(rows))


def log_errors(log: RunWriter, t: np.ndarray, p: gen.Pattern, com: np.ndarray, cp: np.ndarray) -> None:
    n = len(t)
    for topic, err in (("/tracking_error", p.com[:n] - com), ("/tracking_error/cp", p.cp[:n] - cp)):
        log.log_series(topic, t, units="m", name=XYZ, error=err, norm=np.linalg.norm(err, axis=1))


def log_walk(log: RunWriter, p: gen.Pattern, w: walking.WalkLog, biped, tf_every: int) -> None:
    t, n = w.t, len(w.t)
    log_pattern(log, p, n)
    log.log_series("/joint_state", t, units="rad", name=list(JOINTS), position=w.q, velocity=w.qd, effort=w.tau)
    log.log_series("/command", t, units="rad", kind="torque", name=list(JOINTS), value=w.tau)
    zmp = np.column_stack([w.zmp, np.where(np.isnan(w.zmp[:, 0]), np.nan, 0.0)])
    log.log_series("/balance", t, Balance, name=XYZ, com=w.com, com_vel=w.com_vel, cp=w.cp, zmp=zmp,
                   zmp_cmd=w.zmp_cmd, support=p.support[:n] * 1.0, qp_flag=w.qp_flag * 1.0,
                   qp_iterations=w.qp_iterations * 1.0, left_sole=w.feet[:, 0], right_sole=w.feet[:, 1])
    log_errors(log, t, p, w.com, w.cp)
    # the measured ZMP exists only in contact: its error is logged at those samples (a NaN there would read as a
    # diverged state to the watchdog)
    contact = np.isfinite(w.zmp[:, 0])
    zerr = w.zmp_cmd[contact, :2] - w.zmp[contact]
    log.log_series("/tracking_error/zmp", t[contact], units="m", name=XYZ[:2], error=zerr,
                   norm=np.linalg.norm(zerr, axis=1))
    both = ["measured", "commanded"]
    for f, side in enumerate(("left_foot", "right_foot")):
        pair = np.stack([w.wrench[:, f], w.wrench_cmd[:, f]], axis=1)         # (n, 2, 6)
        log.log_series(f"/wrench/{side}", t, frame_id="world (axes), at the sole centre", name=both,
                       **{k: pair[:, :, j] for j, k in enumerate(("force_x", "force_y", "force_z", "torque_x",
                                                                   "torque_y", "torque_z"))})
    com_w = np.stack([w.F_d, w.F_opt], axis=1)
    log.log_series("/wrench/com", t, frame_id="world (axes), about the CoM", name=["desired", "optimized"],
                   **{k: com_w[:, :, j] for j, k in enumerate(("force_x", "force_y", "force_z", "torque_x",
                                                                "torque_y", "torque_z"))})
    corners = w.corner_force.reshape(n, 8, 3)
    zeros = np.zeros((n, 8))
    log.log_series("/wrench/contacts", t, frame_id="world", name=[f"{s}_{c}" for s in ("l", "r") for c in CORNERS],
                   force_x=corners[..., 0], force_y=corners[..., 1], force_z=corners[..., 2], torque_x=zeros,
                   torque_y=zeros, torque_z=zeros)
    log.log_series("/compute_time", t, name=["controller", "qp", "model_update"], calls=[1, 1, 1],
                   seconds=w.compute)
    # the 3-D replay: body frames, CoM (red), CP (blue), measured ZMP (green, as in Fig. 18)
    m = len(w.tf_t)
    points = np.tile(np.eye(4), (m, 3, 1, 1))
    rows = np.arange(m) * tf_every
    points[:, 0, :3, 3], points[:, 1, :3, 3] = w.com[rows], w.cp[rows]
    points[:, 2, :3, 3] = np.nan_to_num(zmp[rows])
    log.log_transforms(w.tf_t, "world", [*biped.body_names, "com", "cp", "zmp"], np.concatenate([w.tf, points], 1))
    log.log_robot(w.tf_t, robot_qpos(biped, w.q[rows], w.tf[:, 0]))
    loaded = w.wrench[rows, :, 2] > 0   # the soles' measured contact forces, at the sole centres
    log.log_contacts(w.tf_t, [f[c] for f, c in zip(w.feet[rows], loaded, strict=True)],
                     [f[c, :3] for f, c in zip(w.wrench[rows], loaded, strict=True)], FORCE_SCALE)
    points = markers.spheres(["com", "cp", "zmp"], [0.03, 0.02, 0.02],
                             [(0.9, 0.1, 0.1, 1), (0.1, 0.3, 0.9, 1), (0.1, 0.7, 0.2, 1)])
    log.write("/markers", 0, schemas.SceneUpdate(entities=points))


def robot_qpos(biped, q: np.ndarray, base: np.ndarray) -> np.ndarray:
    """MuJoCo qpos (m, nq) of the walking model from the joint positions q (m, 12; JOINTS) and the base body's
    world poses (m, 4, 4): the free joint's position and attitude are the base's."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(biped.xml)
    qpos = np.tile(model.qpos0, (len(q), 1))
    for j in range(model.njnt):
        adr = model.jnt_qposadr[j]
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            qpos[:, adr:adr + 3], qpos[:, adr + 3:adr + 7] = base[:, :3, 3], quaternion_wxyz(base[:, :3, :3])
        else:
            qpos[:, adr] = q[:, JOINTS.index(model.joint(j).name)]
    return qpos


# -- experiments -------------------------------------------------------------------------------------------


def mechanism_curves(cfg: DictConfig) -> list[Case]:
    """Figs. 8, 10-12 and the spring claims of Secs. 3.2-3.3."""
    sc, s = cfg.scenario, cfg.system

    def simulate(log: RunWriter) -> None:
        knee = mechanisms.Knee.from_config(s.knee)
        theta = np.linspace(*sc.knee_range, sc.knee_samples)
        k = mechanisms.knee_curves(knee, theta)
        q19, q20 = mechanisms.knee_passive(knee, theta)
        cols = {"flexion_rad": theta, "arm_m": k["h"], "J_AB_m_per_rad": k["J_AB"], "speed_rad_s": k["speed"],
                "torque_Nm": k["torque"], "stiffness_Nm_per_rad": k["stiffness"], "q19_rad": q19, "q20_rad": q20,
                "screw_length_m": mechanisms.knee_screw_length(knee, theta)}
        log.log_series("/knee", np.arange(len(theta)) * 1e-3, Curve, units=suffix_units(cols), name=list(cols),
                       value=np.column_stack(list(cols.values())))
        ankle = mechanisms.Ankle.from_config(s.ankle)
        g11, g12 = np.meshgrid(np.linspace(*sc.ankle_q11, sc.ankle_samples),
                               np.linspace(*sc.ankle_q12, sc.ankle_samples), indexing="ij")
        q11, q12 = g11.ravel(), g12.ravel()
        a = mechanisms.ankle_curves(ankle, q11, q12)
        A, B = mechanisms.ankle_points(ankle, q11, q12)
        sliders = mechanisms.ankle_sliders(ankle, q11, q12)
        units = {"speed": "rad_s", "torque": "Nm", "stiffness": "Nm_per_rad"}
        cols = {"q11_rad": q11, "q12_rad": q12, "q25_m": sliders[:, 0], "q28_m": sliders[:, 1],
                "rod_error_m": np.abs(np.linalg.norm(B - A, axis=-1) - ankle.rod).max(axis=1),
                **{f"{name}_{units[name.split('_')[0]]}": v for name, v in a.items()}}
        log.log_series("/ankle", np.arange(len(q11)) * 1e-3, Curve, units=suffix_units(cols), name=list(cols),
                       value=np.column_stack(list(cols.values())))
        e_knee = mechanisms.spring_energy(s.knee.spring, s.knee.spring_max_force)
        claims = {"knee_spring_energy_J": e_knee,
                  "knee_spring_deflection_m": s.knee.spring_max_force / s.knee.spring,
                  "speed_for_33J_m_s": mechanisms.speed_for_energy(33.0, s.knee.upper_body_mass),
                  "speed_for_knee_spring_m_s": mechanisms.speed_for_energy(e_knee, s.knee.upper_body_mass),
                  "ankle_spring_energy_J": mechanisms.spring_energy(s.ankle.spring, s.ankle.spring_max_force),
                  "table1_mass_kg": float(np.sum(s.table1.mass[:1]) + 2 * np.sum(s.table1.mass[1:])),
                  "table1_height_m": float(np.sum(s.table1.height)),
                  "table4_mass_kg": build(system_dict(cfg), plant=False).mass}
        log.log("/claims", 0.0, Curve, units=suffix_units(claims), name=list(claims), value=list(claims.values()))

    return [Case("knee-ankle", simulate)]


def pattern_generator(cfg: DictConfig) -> list[Case]:
    """Figs. 14-16: the references of each generator (and eq. 48 as printed)."""
    sc = cfg.scenario
    variants = [(kind, kind, None) for kind in sc.generators]
    if sc.printed:
        variants.append(("extended-eq48-printed", "extended", "printed"))

    def case(kind: str, eq48: str | None):
        def simulate(log: RunWriter) -> None:
            p = make_pattern(cfg, kind, eq48, sc.dt)
            log_pattern(log, p)
            log_steps(log, p)
        return simulate

    return [Case(name, case(kind, eq48)) for name, kind, eq48 in variants]


def _walk_case(cfg: DictConfig, kind: str, stance_foot: str | None = None):
    """The MuJoCo walk of generator `kind` (under another `system.controller.stance_foot` if given)."""
    def simulate(log: RunWriter) -> None:
        system = system_dict(cfg)
        if stance_foot is not None:
            system["controller"]["stance_foot"] = stance_foot
        biped, control = build(system), build(system, plant=False)
        log.attach("model.xml", biped.xml, "application/xml")
        log.attach("control_model.xml", control.xml, "application/xml")
        p = make_pattern(cfg, kind)
        tf_every = max(1, round(1.0 / (cfg.scenario.tf_rate_hz * cfg.system.controller.dt)))
        w = walking.walk(biped, control, p, system, tf_every)
        log_walk(log, p, w, biped, tf_every)
        if w.failure:
            raise SimulationFailed(w.failure)
    return simulate


def _lipm_case(cfg: DictConfig, kind: str, lag: float):
    def simulate(log: RunWriter) -> None:
        p = make_pattern(cfg, kind)
        biped = build(system_dict(cfg), plant=False)
        polygons = (support_polygons(p, biped.foot_half, cfg.system.controller.polygon_margin)
                    if cfg.system.controller.clamp_zmp else None)
        r = lipm.simulate(p, cfg.system.controller.cp_gain, polygons, cfg.system.controller.dt, lag)
        log_pattern(log, p)
        nan = np.full(len(r.t), np.nan)
        log.log_series("/balance", r.t, Balance, name=XYZ, com=r.com, com_vel=r.com_vel, cp=r.cp, zmp=r.zmp,
                       zmp_cmd=r.zmp_cmd, support=p.support * 1.0, qp_flag=nan, qp_iterations=nan,
                       left_sole=p.feet[0], right_sole=p.feet[1])
        log_errors(log, r.t, p, r.com, r.cp)
        if not np.isfinite(r.com).all():
            raise SimulationFailed("the LIP state went non-finite")
    return simulate


def walking_runs(cfg: DictConfig) -> list[Case]:
    """Figs. 18-20: each generator walking in MuJoCo, again under each setting of `scenario.stance_foot_also`
    (cases `stance-<setting>-<generator>`: the Eq. (59) shares under another stance-foot control), and the LIP
    closed loop for each ZMP lag."""
    sc = cfg.scenario
    cases = [Case(kind, _walk_case(cfg, kind)) for kind in sc.generators]
    cases += [Case(f"stance-{setting}-{kind}", _walk_case(cfg, kind, setting))
              for setting in sc.stance_foot_also for kind in sc.generators]
    for lag in sc.lipm_zmp_lags:
        suffix = "" if lag == 0 else f"-lag{lag * 1e3:g}ms"
        cases += [Case(f"lipm{suffix}-{kind}", _lipm_case(cfg, kind, lag)) for kind in sc.generators]
    return cases
