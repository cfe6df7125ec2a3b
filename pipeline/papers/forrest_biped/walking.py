"""The walking run in MuJoCo: FORREST of Table 4 on four corner contacts per foot, the Sec. 6 controller every
1 ms on a 0.1 ms simulation (Sec. 6.3), following one generator's pattern.

Per cycle: `mj_step1` (the simulated robot's kinematics and contacts at t_i: its CoM and soles for the log), the
controller on its own model at the measured joint state, `mj_step2` (the constraint solve at t_i: the measured
contact forces belong to t_i), then the remaining physics steps of the cycle. A fall (CoM too low, base tilted,
non-finite state) ends the walk early; the caller logs what was recorded and marks the run failed with the reason.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pipeline.core.runlog import SimulationFailed
from pipeline.papers.forrest_biped.controller import WalkingController, orientation_error
from pipeline.papers.forrest_biped.generator import Pattern
from pipeline.papers.forrest_biped.model import CORNERS, JOINTS, Biped
from pipeline.papers.forrest_biped.support import support_polygons

XYZ = np.arange(3)
MAX_CONTACTS = 8        # the four corners of each plate; nothing else collides with the floor


def standing_pose(model, data, com: np.ndarray, soles: np.ndarray, iterations: int = 50) -> np.ndarray:
    """qpos with the base upright, the CoM at `com` and both soles flat at `soles` (2, 3): Newton steps on the base
    position and the 12 joints, from bent knees (the knee-forward branch)."""
    import mujoco

    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    sites = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{s}_sole") for s in ("l", "r")]
    q = model.qpos0.copy()
    q[2] = com[2] + 0.15
    bend = {"hip_pitch": -0.3, "knee": 0.6, "ankle_pitch": -0.3}
    for j, name in enumerate(JOINTS):
        q[7 + j] = bend.get(name[2:], 0.0)
    cols = np.r_[0:3, 6:18]
    J = np.zeros((15, model.nv))
    for _ in range(iterations):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        err = [com - data.subtree_com[base]]
        mujoco.mj_jacSubtreeCom(model, data, J[0:3], base)
        for k, site in enumerate(sites):
            err += [soles[k] - data.site_xpos[site], orientation_error(data.site_xmat[site].reshape(3, 3))]
            mujoco.mj_jacSite(model, data, J[3 + 6 * k:6 + 6 * k], J[6 + 6 * k:9 + 6 * k], site)
        e = np.concatenate(err)
        if np.abs(e).max() < 1e-12:
            return q
        dq = np.linalg.lstsq(J[:, cols], e, rcond=None)[0]
        step = np.zeros(model.nv)
        step[cols] = dq
        mujoco.mj_integratePos(model, q, step, 1.0)
    raise SimulationFailed(f"no standing pose with the CoM at {np.round(com, 3).tolist()} m over soles "
                           f"{np.round(soles, 3).tolist()} (residual {np.abs(e).max():.2g} m): legs too short?")


@dataclass
class WalkLog:
    """Everything a walk records, one row per controller cycle (time i·dt); /tf at a lower rate."""

    t: np.ndarray
    q: np.ndarray                # (n, 12) joint positions, rad
    qd: np.ndarray               # (n, 12) rad/s
    tau: np.ndarray              # (n, 12) commanded (= applied) joint torques, N m
    com: np.ndarray              # (n, 3) measured CoM, m
    com_vel: np.ndarray          # (n, 3) m/s
    cp: np.ndarray               # (n, 3) measured CP ξ = x_c + ẋ_c/ω
    zmp_cmd: np.ndarray          # (n, 3) p^c of eq. (50), clamped
    zmp: np.ndarray              # (n, 2) measured ZMP (CoP of all contact forces), NaN without contact
    feet: np.ndarray             # (n, 2, 3) sole centres
    wrench_cmd: np.ndarray       # (n, 2, 6) QP foot wrenches [f τ], world axes, at the sole centres
    wrench: np.ndarray           # (n, 2, 6) measured foot wrenches from the contacts, same point and axes
    corner_force: np.ndarray     # (n, 2, 4, 3) contact force at each plate corner (world), N
    F_d: np.ndarray              # (n, 6) desired CoM wrench
    F_opt: np.ndarray            # (n, 6) optimized CoM wrench
    qp_flag: np.ndarray          # (n,) DAQP exit flag (1 = optimal)
    qp_iterations: np.ndarray
    compute: np.ndarray          # (n, 3) wall time s: controller cycle; in it, the QP and the model update
    tf_t: np.ndarray             # (m,) times of the body poses
    tf: np.ndarray               # (m, bodies, 4, 4)
    failure: str | None = None
    warnings: dict[str, int] = field(default_factory=dict)

    def cut(self, n: int) -> WalkLog:
        """The first n cycles (a fall ends the walk early)."""
        keep = {k: v[:n] for k, v in vars(self).items() if isinstance(v, np.ndarray) and not k.startswith("tf")}
        m = int(np.searchsorted(self.tf_t, self.t[n - 1], side="right")) if n else 0
        return WalkLog(**keep, tf_t=self.tf_t[:m], tf=self.tf[:m], failure=self.failure, warnings=self.warnings)


def contact_wrenches(log: WalkLog, geom: np.ndarray, pos: np.ndarray, frame: np.ndarray, force: np.ndarray,
                     corner_index: np.ndarray, floor: int) -> None:
    """Per cycle from the raw contacts (n, MAX_CONTACTS, ·): the force at each plate corner (world), each foot's
    wrench about its sole centre, and the measured ZMP (CoP of all contact forces)."""
    valid = geom[..., 0] >= 0
    foot_geom = np.where(geom[..., 0] == floor, geom[..., 1], geom[..., 0])
    where = np.where(valid, corner_index[np.where(valid, foot_geom, 0)], -1)
    hit = where >= 0
    sign = np.where(geom[..., 0] == floor, 1.0, -1.0)                 # MuJoCo's force acts on geom2
    f = np.einsum("cnji,cnj->cni", frame.reshape(*frame.shape[:2], 3, 3), force) * (sign * hit)[..., None]
    cycle, slot = np.nonzero(hit)
    foot, corner = np.divmod(where[cycle, slot], 4)
    log.corner_force[cycle, foot, corner] = f[cycle, slot]
    arm = pos[cycle, slot] - log.feet[cycle, foot]
    fc = f[cycle, slot]
    np.add.at(log.wrench, (cycle, foot), np.hstack([fc, np.cross(arm, fc)]))
    fz = f[..., 2].sum(axis=1)
    touching = fz > 1e-6
    log.zmp[touching] = np.einsum("cn,cnk->ck", f[touching, :, 2], pos[touching, :, :2]) / fz[touching, None]


def walk(biped: Biped, control_model: Biped, pattern: Pattern, system: Mapping[str, Any],
         tf_every: int = 10) -> WalkLog:
    """Run the walk of `pattern` on the simulated robot `biped` under the controller built on `control_model`;
    stops early at a fall (`failure` says why)."""
    import mujoco

    c, mdl = system["controller"], system["model"]
    model = mujoco.MjModel.from_xml_string(biped.xml)
    data = mujoco.MjData(model)
    dt = float(c["dt"])
    substeps = round(dt / model.opt.timestep)
    data.qpos[:] = standing_pose(model, data, pattern.com[0], pattern.feet[:, 0])   # the plant's CoM
    mujoco.mj_forward(model, data)
    polygons = support_polygons(pattern, biped.foot_half, float(c["polygon_margin"]))
    ctl = WalkingController(control_model, c, pattern.omega, float(system["gravity"]), float(mdl["friction"]),
                            polygons)
    ctl.start(data.qpos)
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")

    n = len(pattern.t)
    bodies = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in biped.body_names]
    sites = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{s}_sole") for s in ("l", "r")]
    corner_geoms = np.array([[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{s}_{k}") for k in CORNERS]
                             for s in ("l", "r")])
    corner_index = np.full(model.ngeom, -1)      # geom id -> 4·foot + corner
    corner_index[corner_geoms.ravel()] = np.arange(8)
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    log = WalkLog(
        t=pattern.t.copy(), q=np.empty((n, 12)), qd=np.empty((n, 12)), tau=np.empty((n, 12)), com=np.empty((n, 3)),
        com_vel=np.empty((n, 3)), cp=np.empty((n, 3)), zmp_cmd=np.empty((n, 3)), zmp=np.full((n, 2), np.nan),
        feet=np.empty((n, 2, 3)), wrench_cmd=np.empty((n, 12)), wrench=np.zeros((n, 2, 6)),
        corner_force=np.zeros((n, 2, 4, 3)), F_d=np.empty((n, 6)), F_opt=np.empty((n, 6)),
        qp_flag=np.empty(n, dtype=np.int64), qp_iterations=np.empty(n, dtype=np.int64), compute=np.empty((n, 3)),
        tf_t=pattern.t[::tf_every].copy(), tf=np.tile(np.eye(4), (len(pattern.t[::tf_every]), len(bodies), 1, 1)))
    fall_z, fall_tilt = float(c["fall_height"]), np.cos(float(c["fall_tilt"]))
    jac_com = np.zeros((3, model.nv))
    # the contacts of each solve, raw (at most the eight corners touch the floor); wrenches are computed after
    raw_geom, raw_pos = np.full((n, MAX_CONTACTS, 2), -1), np.zeros((n, MAX_CONTACTS, 3))
    raw_frame, raw_force = np.zeros((n, MAX_CONTACTS, 9)), np.zeros((n, MAX_CONTACTS, 3))
    clock = time.perf_counter_ns
    step1, step2, step = mujoco.mj_step1, mujoco.mj_step2, mujoco.mj_step
    for i in range(n):
        step1(model, data)
        t1 = clock()
        out = ctl.cycle(data.qpos, data.qvel, pattern, i, int(pattern.support[i]))
        t2 = clock()
        data.ctrl[:] = out.tau
        log.compute[i] = (t2 - t1) * 1e-9, ctl.qp.seconds, ctl.model_seconds
        # the measured state at t_i: the simulated robot's own CoM and soles (mj_step1 computed them)
        log.q[i], log.qd[i], log.tau[i] = data.qpos[7:], data.qvel[6:], out.tau
        com = log.com[i] = data.subtree_com[base]
        mujoco.mj_jacSubtreeCom(model, data, jac_com, base)
        log.com_vel[i] = jac_com @ data.qvel
        log.zmp_cmd[i], log.F_d[i], log.F_opt[i], log.wrench_cmd[i] = out.zmp_cmd, out.F_d, out.F_opt, out.wrench
        log.qp_flag[i], log.qp_iterations[i] = out.qp_flag, out.qp_iterations
        log.feet[i] = data.site_xpos[sites]
        if i % tf_every == 0:
            pose = log.tf[i // tf_every]
            pose[:, :3, :3] = data.xmat[bodies].reshape(-1, 3, 3)
            pose[:, :3, 3] = data.xpos[bodies]
        step2(model, data)
        k = data.ncon
        if k:                        # the contacts of the solve at t_i (elliptic cones: efc_force is the force)
            contact = data.contact
            k = min(k, MAX_CONTACTS)
            raw_geom[i, :k], raw_pos[i, :k], raw_frame[i, :k] = contact.geom[:k], contact.pos[:k], contact.frame[:k]
            raw_force[i, :k] = data.efc_force[contact.efc_address[:k, None] + XYZ]
        step(model, data, substeps - 1)
        if not np.isfinite(data.qvel).all():
            log.failure = f"state not finite at t = {pattern.t[i]:.3f} s"
        elif com[2] < fall_z:
            log.failure = f"fell at t = {pattern.t[i]:.3f} s: CoM height {com[2]:.3f} m < {fall_z:g} m"
        elif data.xmat[base, 8] < fall_tilt:
            log.failure = (f"fell at t = {pattern.t[i]:.3f} s: base tilted more than "
                           f"{np.degrees(np.arccos(fall_tilt)):.0f}°")
        if log.failure:
            log = log.cut(i + 1)
            n = i + 1
            break
    log.cp = log.com + log.com_vel / pattern.omega
    log.wrench_cmd = log.wrench_cmd.reshape(n, 2, 6)
    contact_wrenches(log, raw_geom[:n], raw_pos[:n], raw_frame[:n], raw_force[:n], corner_index, floor)
    log.warnings = {w.name: int(data.warning[int(w)].number) for w in
                    (mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADQVEL)
                    if data.warning[int(w)].number}
    if log.warnings and log.failure is None:
        log.failure = "MuJoCo reported an unstable simulation: " + ", ".join(f"{k} ({v}x)" for k, v in
                                                                          log.warnings.items())
    return log
