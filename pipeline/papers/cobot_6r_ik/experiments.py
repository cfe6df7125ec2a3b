"""Simulate stage of `cobot-6r-ik`: the numerical example (Tables 2–3), completeness on random poses,
compute time beside the peers, and Cartesian paths executed by a MuJoCo CRX generated from Table 1."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import time_calls
from pipeline.papers.cobot_6r_ik import ik, peers, reference
from pipeline.papers.cobot_6r_ik import resultant as rs
from pipeline.papers.cobot_6r_ik.kinematics import JOINT_LIMITS, Geometry, cayley, cayley_params, fk, twin, wrap
from pipeline.robotics import dh as dhk
from pipeline.robotics.transforms import rotation_angle

JOINTS = [f"joint{i}" for i in range(1, 7)]

Candidate = schemas.define(
    "CobotIkCandidate", "One real root of Λ (eq. 25) taken through back-substitution and the FK filter. Lengths "
    "in m, angles in rad; errors are the algebraic candidate's, before any polishing; accepted: 0 rejected, "
    "1 a new solution, 2 a duplicate. c2_eq29 is eq. (29)'s c2 at the same c1; the *_paper fields take c3 from "
    "X4 and X6 (the pair Table 2's c3 imply), then P4 from eq. (18).",
    c1="double 1", c1_imag="double 1", c2="double 1", c2_eq29="double 1", c3="double 1", c3_pairs="double[] 1",
    p4="double[] m", q_a="double[] rad", q_b="double[] rad", pos_err="double[] m", rot_err="double[] rad",
    accepted="double[] 1", lambda_residual="double 1",
    c3_paper="double 1", p4_paper="double[] m", q_paper_a="double[] rad", q_paper_b="double[] rad",
    pos_err_paper="double[] m",
)
IkSample = schemas.define(
    "CobotIkSample", "Every IK solution of one flange pose (count × 6 joint angles in rad, row-major) and the one "
    "the branch follows; jump = largest joint step from the previous sample (rad); FK error of the "
    "followed solution (m, rad).",
    count="uint32 1", solutions="double[] rad", name="string[]", followed="double[] rad", jump="double rad",
    fk_error_position="double m", fk_error_rotation="double rad",
)


def geometry(cfg: DictConfig) -> Geometry:
    return Geometry(**cfg.system.geometry)


def tolerances(cfg: DictConfig) -> ik.Tolerances:
    return ik.Tolerances(**OmegaConf.to_container(cfg.system.tolerances))


def random_joints(rng: np.random.Generator, n: int) -> np.ndarray:
    """Uniform within Table 1's motion ranges."""
    return rng.uniform(-JOINT_LIMITS, JOINT_LIMITS, (n, 6))


# -- E1: Tables 2-3 ---------------------------------------------------------------------------------


def _c2_eq29(w1: np.ndarray, w2: np.ndarray) -> float:
    """c2 as eq. (29) solves for it (unknowns c2⁶ … c2², c2; erratum: printed c3⁶ … c3²)."""
    A = np.zeros((6, 6))
    b = np.zeros(6)
    for desc, row in ((w1[::-1], 0), (w2[::-1], 3)):   # ω_{h,4} … ω_{h,0}
        A[row] = np.r_[desc, 0.0]
        A[row + 1] = np.r_[0.0, desc]
        A[row + 2] = np.r_[0.0, 0.0, desc[:4]]
        b[row + 2] = -desc[4]
    return float(np.linalg.solve(A, b)[5])


def _c3_pairs(f: np.ndarray, c1: float, c2: float) -> list[float]:
    """c3 from each pair of X4, X5, X6 (eq. 30 picks X4, X5): (45, 46, 56)."""
    x = [rs.chi(f, h, c1, c2) for h in range(3)]
    out = []
    for a, b in ((0, 1), (0, 2), (1, 2)):
        det = x[a][0] * x[b][1] - x[b][0] * x[a][1]
        out.append(float((x[a][0] * -x[b][2] - x[b][0] * -x[a][2]) / det))
    return out


def tables(cfg: DictConfig) -> list[Case]:
    sc, tol = cfg.scenario, tolerances(cfg)
    q31 = np.deg2rad(np.asarray(sc.q_deg, dtype=float))

    def simulate(log: RunWriter, g: Geometry) -> None:
        T = fk(q31, g)
        F = dhk.frames(dhk.DH.from_config(g.dh), q31)
        log.log("/example/pose", 0.0, schemas.Scalars,
                units=["m" if c == 3 else "1" for r in range(3) for c in range(4)],
                name=[f"T{r + 1}{c + 1}" for r in range(3) for c in range(4)],
                value=T[:3].ravel().tolist())
        points = {"P1": F[1], "P3": F[3], "P4": F[4], "P5": F[5], "P6": F[6]}
        log.log("/example/points", 0.0, schemas.Scalars, units="m", name=[f"{k}.{a}" for k in points for a in "xyz"],
                value=np.concatenate([M[:3, 3] for M in points.values()]).tolist())
        d = ik.diagnose(T, g, tol)
        order = np.lexsort((-d.roots.imag, d.roots.real))   # Table 2's order: by real part, +imag first
        roots = d.roots[order]
        log.log("/ik/roots", 0.0, schemas.Scalars, units="1",
                name=[f"root{k + 1:02d}.{p}" for k in range(len(roots)) for p in ("re", "im")],
                value=np.column_stack([roots.real, roots.imag]).ravel().tolist())
        log.log("/ik/lambda", 0.0, schemas.Scalars, units="1", name=[f"lambda{i:02d}" for i in range(17)],
                value=d.lam.tolist())
        octic = ik.diagnose(T, g, tol, "octic").roots   # ours: the roots of Λ's genuine factor alone
        octic = octic[np.lexsort((-octic.imag, octic.real))]
        log.log("/ik/octic_roots", 0.0, schemas.Scalars, units="1",
                name=[f"root{k + 1:02d}.{p}" for k in range(len(octic)) for p in ("re", "im")],
                value=np.column_stack([octic.real, octic.imag]).ravel().tolist())
        f, psi1, psi2, _ = rs.system(T, g.array)
        recs = d.records[np.argsort(d.records[:, ik.R_C1])]
        for k, rec in enumerate(recs):
            c1, c2, c3 = rec[ik.R_C1], rec[ik.R_C2], rec[ik.R_C3]
            q_ab = ik.candidate_joints(T, g, np.array([c1, c2, c3]))
            c2_29 = _c2_eq29(rs.omegas(psi1, c1), rs.omegas(psi2, c1))
            c3_46 = _c3_pairs(f, c1, c2)[1]
            paper = np.array([c1, c2, c3_46])
            q_paper = ik.candidate_joints(T, g, paper)
            p4_paper = T[:3, 3] - g.d6 * T[:3, 2] - g.d5 * cayley(paper)[:, 2]     # eq. (18)
            log.log("/ik/candidates", float(k), Candidate, c1=c1, c1_imag=rec[ik.R_IM], c2=c2, c2_eq29=c2_29, c3=c3,
                    c3_pairs=_c3_pairs(f, c1, c2), p4=rec[ik.R_P4:ik.R_P4 + 3].tolist(), q_a=q_ab[0].tolist(),
                    q_b=q_ab[1].tolist(), pos_err=[rec[ik.R_EP], rec[ik.R_EP + 2]],
                    rot_err=[rec[ik.R_ER], rec[ik.R_ER + 2]], accepted=[rec[ik.R_OK], rec[ik.R_OK + 1]],
                    lambda_residual=rec[ik.R_RES], c3_paper=c3_46, p4_paper=p4_paper.tolist(),
                    q_paper_a=q_paper[0].tolist(), q_paper_b=q_paper[1].tolist(),
                    pos_err_paper=[float(np.linalg.norm(fk(x, g)[:3, 3] - T[:3, 3])) for x in q_paper])
        # the solutions, one per second: a replay of the paper's Fig. 3 (Foxglove / Rerun draw /tf)
        t = 1.0 + np.arange(len(d.q))
        log.log_series("/ik/solutions", t, schemas.Reference, units="rad", name=JOINTS, position=d.q)
        log.log_series("/joint_state", t, units="rad", name=JOINTS, position=d.q)
        frames = dhk.frames(dhk.DH.from_config(g.dh), d.q)[:, 1:]
        log.log_transforms(t, "base", [f"link{i}" for i in range(1, 7)], frames)
        ref = reference.multistart(T, int(sc.reference_starts), np.random.default_rng(cfg.seed), g)
        log.log_series("/ik/reference", np.arange(len(ref), dtype=float), schemas.Reference, units="rad", name=JOINTS,
                       position=ref)
        log.attach("model.xml", arm_model(cfg, g, q31), "application/xml")

    g = geometry(cfg)
    example = dataclasses.replace(g, d1=float(sc.d1_example))
    return [Case("table1-d1", lambda log: simulate(log, g)), Case("example-d1", lambda log: simulate(log, example))]


# -- E2: completeness -----------------------------------------------------------------------------------


def completeness(cfg: DictConfig) -> list[Case]:
    sc, g, tol = cfg.scenario, geometry(cfg), tolerances(cfg)

    def simulate(log: RunWriter) -> None:
        rng = np.random.default_rng(cfg.seed)
        q = random_joints(rng, int(sc.poses))
        poses = fk(q, g)
        c_gen = np.linalg.norm(cayley_params(dhk.frames(dhk.DH.from_config(g.dh), q)[:, 4, :3, :3]), axis=1)
        t = np.arange(len(q)) * 1e-3   # one sample per pose, 1 ms apart on the log's time axis
        log.log_series("/completeness/generating", t, schemas.Reference, units="rad", name=JOINTS, position=q)
        solutions = {}
        for method in ik.METHODS:
            rows = np.zeros((len(q), 7))
            found_sets = []
            for k, T in enumerate(poses):
                d = ik.diagnose(T, g, tol, method)
                found_sets.append(d.q)
                hit = np.abs(wrap(d.q - q[k])).max(axis=1) < tol.duplicate if len(d.q) else np.zeros(0, bool)
                twin_hit = np.abs(wrap(d.q - twin(q[k]))).max(axis=1) < tol.duplicate if len(d.q) else hit
                acc = d.records[:, ik.R_OK:ik.R_OK + 2]
                rows[k] = (len(d.q), float(hit.any()), float(twin_hit.any()), len(d.roots),
                           int(np.sum(np.abs(d.roots.imag) <= 1e-9 * np.maximum(1, np.abs(d.roots.real)))),
                           int((acc == 0).all(axis=1).sum()), c_gen[k])
            solutions[method] = found_sets
            log.log_series(f"/completeness/{method}", t, schemas.Scalars, units="1", value=rows,
                           name=["solutions", "generating_found", "twin_found", "roots", "real_roots",
                                 "rejected_roots", "c_generating"])
        n_ref = min(int(sc.reference_poses), len(q))
        ref_rows = np.zeros((n_ref, 7))
        ref_rng = np.random.default_rng(cfg.seed + 1)
        for k in range(n_ref):
            ref = reference.multistart(poses[k], int(sc.reference_starts), ref_rng, g)
            ref_rows[k, 0] = len(ref)
            for m, method in enumerate(ik.METHODS):
                ref_rows[k, 1 + 3 * m:4 + 3 * m] = peers.compare(solutions[method][k], ref, 1e-6)
        log.log_series("/completeness/reference", t[:n_ref], schemas.Scalars, units="1", value=ref_rows,
                       name=["reference", *(f"{m}.{k}" for m in ik.METHODS
                                            for k in ("common", "ours_only", "reference_only"))])

    return [Case("random-poses", simulate)]


# -- E3: compute time ------------------------------------------------------------------------------------


def compute_time(cfg: DictConfig) -> list[Case]:
    sc, g, tol = cfg.scenario, geometry(cfg), tolerances(cfg)

    def simulate(log: RunWriter) -> None:
        rng = np.random.default_rng(cfg.seed)
        poses = fk(random_joints(rng, int(sc.poses)), g)
        # batched in chunks, so that the median per pose is not the mean of a long call that the other jobs
        # of a shared machine interrupt
        chunk = int(sc.batch_chunk)
        chunks = [(poses[i:i + chunk],) for i in range(0, len(poses) - chunk + 1, chunk)]
        timings = []
        for method in ik.METHODS:
            timings.append(time_calls(method, lambda T, m=method: ik.solve(T, g, tol, m), [(T,) for T in poses],
                                      warmup=int(sc.warmup)))
            timings.append(time_calls(f"{method}_batch", lambda P, m=method: ik.solve_batch(P, g, tol, m), chunks,
                                      warmup=1, repeats=int(sc.batch_repeats), items_per_call=chunk))
        ours = [ik.solve(T, g, tol) for T in poses]
        octic = [ik.solve(T, g, tol, "octic") for T in poses]
        status = {}
        for peer in peers.all_peers(g, int(sc.peer_starts), int(cfg.seed)):
            status[peer.name] = {"label": peer.label, "available": peer.available, "reason": peer.reason,
                                 "all_solutions": peer.all_solutions}
            if not peer.available:
                continue
            n = len(poses) if peer.name == "crx" else min(int(sc.peer_poses), len(poses))
            inputs = [(peer.prepare(T),) for T in poses[:n]]
            timings.append(time_calls(peer.name, peer.call, inputs, warmup=min(int(sc.warmup), n)))
            theirs = [peer.convert(peer.call(x)) for (x,) in inputs]
            rows = np.array([(len(s), *peers.compare(a, s, peer.match_tol), *peers.compare(b, s, peer.match_tol))
                             for a, b, s in zip(ours[:n], octic[:n], theirs, strict=True)])
            log.log_series(f"/peers/{peer.name}", np.arange(n) * 1e-3, schemas.Scalars, units="1",
                           value=rows.astype(float),
                           name=["solutions", *(f"{m}.{k}" for m in ik.METHODS
                                                for k in ("common", "ours_only", "peer_only"))])
        log.metadata["peers"] = json.dumps(status)
        t = 0.0
        for timing in timings:
            times = t + np.arange(len(timing.seconds)) * 1e-3
            log.log_series("/compute_time", times, name=[timing.name], calls=[timing.items_per_call],
                           seconds=timing.seconds[:, None])
            t = float(times[-1]) + 1e-3
        log.log_series("/ik/solutions", np.arange(len(poses)) * 1e-3, schemas.Scalars, units="1",
                       name=["lambda16", "octic"],
                       value=np.column_stack([[len(o) for o in ours], [len(o) for o in octic]]).astype(float))
        log.log_series("/ik/octic_vs_lambda16", np.arange(len(poses)) * 1e-3, schemas.Scalars, units="1",
                       name=["common", "lambda16_only", "octic_only"],
                       value=np.array([peers.compare(a, b, tol.duplicate) for a, b in zip(ours, octic, strict=True)],
                                      dtype=float))

    return [Case("random-poses", simulate)]


# -- E4: Cartesian paths executed in MuJoCo --------------------------------------------------------------


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def flange_path(spec: DictConfig, T0: np.ndarray, times: np.ndarray, duration: float) -> np.ndarray:
    """(N, 4, 4) flange poses at constant orientation, min-jerk timed: a line from T0 along `direction`, or
    a full circle through T0 whose centre lies `radius` along `center_direction`, starting along `tangent`."""
    s = times / duration
    s = s ** 3 * (10 - 15 * s + 6 * s * s)
    poses = np.tile(T0, (len(times), 1, 1))
    if spec.kind == "line":
        poses[:, :3, 3] += (s * spec.length)[:, None] * _unit(spec.direction)
    else:
        w = _unit(spec.center_direction)
        t = np.asarray(spec.tangent, dtype=float)
        t = _unit(t - t.dot(w) * w)
        theta = 2 * np.pi * s
        poses[:, :3, 3] = T0[:3, 3] + spec.radius * ((1 - np.cos(theta))[:, None] * w + np.sin(theta)[:, None] * t)
    return poses


def follow_branch(solutions: np.ndarray, counts: np.ndarray, q_start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At each sample the solution nearest (max joint step, mod 2π) to the previous one, unwrapped into a
    continuous joint path: (q (N, 6), index of the followed solution (N,), −1 where there is none)."""
    q = np.empty((len(counts), 6))
    idx = np.full(len(counts), -1)
    prev = np.asarray(q_start, dtype=float)
    for k, n in enumerate(counts):
        if n == 0:
            q[k] = prev
            continue
        steps = wrap(solutions[k, :n] - prev)
        j = int(np.argmin(np.abs(steps).max(axis=1)))
        prev = prev + steps[j]
        q[k], idx[k] = prev, j
    return q, idx


def arm_model(cfg: DictConfig, g: Geometry, q0: np.ndarray) -> str:
    """MJCF of the CRX-10iA/L of Table 1 (DH frames as bodies, L-shaped links sized by the table) with the
    assumed dynamics and servo gains tuned at q0."""
    from pipeline.robotics.mjcf import ArmDynamics, serial_arm, with_servo_gains

    dyn_cfg = cfg.system.dynamics
    dyn = ArmDynamics(masses=list(dyn_cfg.masses), link_radius=dyn_cfg.link_radius, armature=list(dyn_cfg.armature),
                      damping=list(dyn_cfg.damping), torque_limit=list(dyn_cfg.torque_limit))
    dh = dhk.DH.from_config(g.dh)
    ex = cfg.get("execute") or {"dt": 0.001, "bandwidth_hz": 8.0, "damping_ratio": 1.0}

    def build(kp, kv) -> str:
        return serial_arm("crx10ial_paper_dh", dh, dyn, timestep=ex["dt"], kp=list(kp), kv=list(kv),
                          radii=list(dyn_cfg.radii), dh_segments=True,
                          world_xml='\n    <light pos="1 -1 3" dir="-0.3 0.3 -1" diffuse="0.8 0.8 0.8"/>')

    return with_servo_gains(build, q0, ex["bandwidth_hz"], ex["damping_ratio"])


def trajectory(cfg: DictConfig) -> list[Case]:
    sc, ex, g, tol = cfg.scenario, cfg.execute, geometry(cfg), tolerances(cfg)
    q_start = np.deg2rad(np.asarray(sc.q_start_deg, dtype=float))

    def simulate(log: RunWriter, name: str) -> None:
        from pipeline.robotics.mjcf import servo_rollout

        T0 = fk(q_start, g)
        ik_times = np.arange(round(sc.duration / sc.ik_dt) + 1) * sc.ik_dt
        poses = flange_path(sc.paths[name], T0, ik_times, sc.duration)
        solutions, counts = ik.solve_batch(poses, g, tol, cfg.system.method)
        if counts[0] == 0:
            raise SimulationFailed(f"no IK solution at the start of the {name} path")
        q_ik, _ = follow_branch(solutions, counts, q_start)
        jumps = np.r_[0.0, np.abs(np.diff(q_ik, axis=0)).max(axis=1)]
        T_ik = fk(wrap(q_ik), g)
        e_pos = np.linalg.norm(T_ik[:, :3, 3] - poses[:, :3, 3], axis=1)
        e_rot = rotation_angle(T_ik[:, :3, :3], poses[:, :3, :3])
        for k, t in enumerate(ik_times):
            log.log("/ik/samples", float(t), IkSample, count=int(counts[k]),
                    solutions=solutions[k, :counts[k]].ravel().tolist(), name=JOINTS, followed=q_ik[k].tolist(),
                    jump=float(jumps[k]), fk_error_position=float(e_pos[k]), fk_error_rotation=float(e_rot[k]))
        # servo references at every physics step; the end pose is held for `settle` s
        dt = ex.dt
        times = np.arange(round((sc.duration + ex.settle) / dt) + 1) * dt
        q_ref = np.stack([np.interp(times, ik_times, q_ik[:, j]) for j in range(6)], axis=1)
        qd_ref = np.clip(np.gradient(q_ref, dt, axis=0), -cfg.system.dynamics.velocity_limit,
                         cfg.system.dynamics.velocity_limit)
        xml = arm_model(cfg, g, q_ref[0])
        log.attach("model.xml", xml, "application/xml")
        states, sensors = servo_rollout(xml, q_ref, qd_ref, times)
        every = slice(None, None, max(1, round(ex.log_dt / dt)))
        t_state = (times + dt)[every]
        q, qd, tau = states[every, 1:7], states[every, 7:13], sensors[every, :6]
        log.log_series("/reference", times[every], units="rad", name=JOINTS, position=q_ref[every],
                       velocity=qd_ref[every])
        log.log_series("/joint_state", t_state, units="rad", name=JOINTS, position=q, velocity=qd, effort=tau)
        log.log_series("/command", t_state, units="rad", kind="torque", name=JOINTS, value=tau)
        err = q_ref[every] - q
        log.log_series("/tracking_error", t_state, units="rad", name=JOINTS, error=err,
                       norm=np.linalg.norm(err, axis=1))
        sample = np.minimum(np.searchsorted(ik_times, t_state), len(poses) - 1)
        T_act = fk(q, g)
        dp = poses[sample, :3, 3] - T_act[:, :3, 3]
        rot = rotation_angle(poses[sample, :3, :3], T_act[:, :3, :3])
        log.log_series("/tracking_error/flange", t_state, units=["m", "m", "m", "rad"], field_units={"norm": "m"},
                       name=["x", "y", "z", "rotation"],
                       error=np.column_stack([dp, rot]), norm=np.linalg.norm(dp, axis=1))
        tf = slice(None, None, max(1, round(ex.tf_dt / dt)))
        t_tf = (times + dt)[tf]
        frames = dhk.frames(dhk.DH.from_config(g.dh), states[tf, 1:7])[:, 1:]
        target = poses[np.minimum(np.searchsorted(ik_times, t_tf), len(poses) - 1)]
        log.log_transforms(t_tf, "base", [*(f"link{i}" for i in range(1, 7)), "target"],
                           np.concatenate([frames, target[:, None]], axis=1))

    unknown = sorted(set(sc.cases) - set(sc.paths))
    if unknown:
        raise ValueError(f"scenario.cases {unknown} are not in scenario.paths ({', '.join(sc.paths)})")
    return [Case(name, lambda log, n=name: simulate(log, n)) for name in sc.cases]
