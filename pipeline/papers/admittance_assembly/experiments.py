"""Simulate stage of `admittance-assembly`: condition (2) over the two-point contact state, quasi-static
insertions, and the MuJoCo cross-check. Every run logs what the analysis needs; the admittance used is
attached as `admittance.yaml`."""

from __future__ import annotations

from functools import cache

import numpy as np
import yaml
from omegaconf import DictConfig, OmegaConf

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import time_calls
from pipeline.papers.admittance_assembly import design, geometry, insertion, quasistatic
from pipeline.papers.admittance_assembly.geometry import PegInHole
from pipeline.robotics.mjcf import qpos_units

TWIST_NAMES = np.array(["v_x", "v_y", "v_z", "w_x", "w_y", "w_z"])
ERROR_NAMES = ["x", "y", "z"]
CHART_UNITS = {True: ("rad", "m"), False: ("rad", "rad", "rad", "m", "m")}   # geometry.CHART's coordinates
TWIST_NORM = "m/s & rad/s"   # the norm of a twist that mixes translation and rotation rates


def twist_units(dofs: list[str]) -> list[str]:
    """The coordinate of each twist entry: v_* translate (m), w_* turn (rad); the twist itself is per second."""
    return ["m" if d.startswith("v") else "rad" for d in dofs]
SAMPLE_DT = 1e-3  # s: samples that are not a trajectory (configurations, admittances) are logged 1 ms apart
NEAR_GAP = 1e-4   # m: a MuJoCo contact is attributed to the nearest candidate within this gap
CONTACT_SCALE = 0.005  # m/N, contact forces drawn 5 mm per newton beside the 5 cm peg, one scale for both models
                       # (MuJoCo's and the quasi-static: the two-point state squeezes the peg with 5-45 N a side)


# -- configuration -> model -----------------------------------------------------------------------------


def peg_in_hole(cfg: DictConfig, case: str) -> PegInHole:
    s = cfg.system
    return PegInHole(planar=case == "planar", half_width=tuple(s.peg.half_width), length=s.peg.length,
                     ref_height=s.peg.ref_height, clearance=tuple(s.hole.clearance), depth=s.hole.depth,
                     selected_height=s.selected_height)


def state_box(cfg: DictConfig, case: str) -> np.ndarray:
    """(m, 2) bounds of the chart coordinates, in `geometry.CHART` order."""
    box = cfg.system.state[case]
    return np.array([list(box[name]) for name in geometry.CHART[case == "planar"]], dtype=float)


@cache
def _design(config_yaml: str, case: str) -> tuple[design.Design, design.StateSamples]:
    cfg = OmegaConf.create(config_yaml)
    g = peg_in_hole(cfg, case)
    corners = design.state_samples(g, geometry.box_corners(state_box(cfg, case)), cfg.system.nominal_speed)
    if not corners.valid.all():
        bad = corners.coords[~corners.valid][0]
        raise SimulationFailed(f"corner {np.round(bad, 6).tolist()} of system.state.{case} is not a valid "
                               "two-point contact of this peg and hole: narrow the box")
    a = cfg.system.admittance
    return design.design_admittance(g, corners, cfg.system.nominal_speed, min_eigenvalue=a.min_eigenvalue,
                                    restarts=a.restarts, seed=cfg.seed), corners


def designed(cfg: DictConfig, case: str) -> tuple[design.Design, design.StateSamples]:
    """The admittance of the case (computed once per process and config) and the corner samples."""
    return _design(OmegaConf.to_yaml({"system": cfg.system, "seed": cfg.seed}), case)


def admittance(cfg: DictConfig, case: str, kind: str) -> np.ndarray:
    """A in SI units: `designed` (max-min margin at the corners) or `isotropic` (Â = I)."""
    g = peg_in_hole(cfg, case)
    A_hat = designed(cfg, case)[0].A_hat if kind == "designed" else np.eye(g.n)
    return design.physical(g, A_hat, cfg.system.admittance.translational)


def admittance_yaml(g: PegInHole, A: np.ndarray, kind: str, info: design.Design | None = None) -> str:
    """The admittance of a run: A (SI) and Â (length-scaled, trace n) with its eigenvalues."""
    s = design.scaling(g)
    A_hat = A / np.outer(s, s)
    A_hat *= g.n / np.trace(A_hat)
    record = {"kind": kind, "dofs": TWIST_NAMES[g.dofs].tolist(), "A": A.tolist(), "A_hat": A_hat.tolist(),
              "A_hat_eigenvalues": np.linalg.eigvalsh(A_hat).tolist()}
    if info is not None:
        record |= {"corner_margin": info.corner_margin, "starts": info.starts, "iterations": info.iterations}
    return yaml.safe_dump(record, sort_keys=False)


def start_coords(cfg: DictConfig, case: str, trials: int) -> np.ndarray:
    """Starts in the real hole: the box centre, then uniform random points of the box, all at the hole's own
    x clearance."""
    bounds = state_box(cfg, case)
    rng = np.random.default_rng(cfg.seed)
    coords = np.vstack([bounds.mean(axis=1), bounds[:, 0] + rng.random((trials - 1, len(bounds))) * np.ptp(bounds, 1)])
    coords[:, -1] = cfg.system.hole.clearance[0]
    return coords


# -- logging helpers ------------------------------------------------------------------------------------


def to_six(g: PegInHole, x: np.ndarray) -> np.ndarray:
    """Reduced vectors (..., n) as spatial 6-vectors (..., 6)."""
    out = np.zeros((*np.shape(x)[:-1], 6))
    out[..., g.dofs] = x
    return out


def log_wrench(log: RunWriter, topic: str, t: np.ndarray, frame: str, names: list[str], wrench: np.ndarray) -> None:
    """`wrench` (N, k, 6) = [force; torque] of k named contacts or points."""
    wrench = np.asarray(wrench, float).reshape(len(t), len(names), 6)
    log.log_series(topic, t, frame_id=frame, name=names, **{  # Wrench: N and N*m
        f: wrench[..., i] for i, f in enumerate(("force_x", "force_y", "force_z", "torque_x", "torque_y", "torque_z"))})


def log_pose(log: RunWriter, t: np.ndarray, R: np.ndarray, p: np.ndarray, dt: float, tf_dt: float) -> None:
    every = max(1, round(tf_dt / dt))
    T = np.zeros((len(t), 1, 4, 4))
    T[:, 0, :3, :3], T[:, 0, :3, 3], T[:, 0, 3, 3] = R, p, 1.0
    log.log_transforms(t[::every], "world", ["peg"], T[::every])


# -- E1: condition (2) over the two-point state -------------------------------------------------------------


def corner_conditions(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    speed = cfg.system.nominal_speed

    def simulate(log: RunWriter, case: str) -> None:
        from scipy.stats import qmc  # 0.3 s to import: only this experiment samples with it

        g = peg_in_hole(cfg, case)
        bounds = state_box(cfg, case)
        info, corners = designed(cfg, case)
        A_designed = design.physical(g, info.A_hat, cfg.system.admittance.translational)
        A_iso = design.physical(g, np.eye(g.n), cfg.system.admittance.translational)
        unit = qmc.Halton(d=len(bounds), scramble=True, seed=cfg.seed).random(sc.interior_samples)
        interior = design.state_samples(g, qmc.scale(unit, bounds[:, 0], bounds[:, 1]), speed)
        names = list(geometry.CHART[g.planar])
        for topic, samples in (("/conditions/corners", corners), ("/conditions/interior", interior)):
            lam = quasistatic.contact_response(A_designed, samples.W, samples.v0)[0]
            columns = np.column_stack([samples.coords, samples.margin(A_designed, speed),
                                       samples.margin(A_iso, speed), lam, samples.error, samples.valid])
            log.log_series(topic, np.arange(len(columns)) * SAMPLE_DT, schemas.Scalars, value=columns,
                           name=[*names, "margin_designed", "margin_isotropic", "force_1", "force_2", "error", "valid"],
                           units=[*CHART_UNITS[g.planar], "1", "1", "N", "N", "m", "1"])

        # many admittances: corners vs interior, and the two-PC model vs each contact alone (single PC)
        rng = np.random.default_rng(cfg.seed + 1)
        A_random = design.physical(g, design.random_admittances(g.n, sc.random_admittances,
                                                                cfg.system.admittance.min_eigenvalue, rng), 1.0)
        subset = interior.valid.copy()
        subset[sc.random_interior_samples:] = False
        keep = np.flatnonzero(subset)
        sample = design.StateSamples(interior.coords[keep], interior.W[keep], interior.d[keep], interior.v0[keep],
                                     interior.error[keep], interior.valid[keep])
        rows = np.empty((len(A_random), 4))
        for k, A in enumerate(A_random):
            rows[k] = (corners.margin(A, speed).min(), sample.margin(A, speed).min(),
                       min(sample.margin(A, speed, slice(0, 1)).min(), corners.margin(A, speed, slice(0, 1)).min()),
                       min(sample.margin(A, speed, slice(1, 2)).min(), corners.margin(A, speed, slice(1, 2)).min()))
        log.log_series("/conditions/random", np.arange(len(rows)) * SAMPLE_DT, schemas.Scalars, value=rows,
                       name=["corner_min", "interior_min", "single_1_min", "single_2_min"], units="1")  # margins

        # compute time: one configuration per call, and one batched pass over the interior sample
        one = [(interior.W[i:i + 1], interior.d[i:i + 1], interior.v0[i:i + 1], interior.error[i:i + 1])
               for i in range(min(sc.timing_repeats, len(interior.error)))]

        def check(W, d, v0, error):
            v = quasistatic.contact_response(A_designed, W, v0)[2]
            return quasistatic.closing_rate(d, v, error) > 0

        single = time_calls("condition_check", check, one, warmup=20)
        batch = time_calls("condition_check_batch", check, [(interior.W, interior.d, interior.v0, interior.error)],
                           warmup=1, repeats=5, items_per_call=len(interior.error))
        t_single = np.arange(len(single.seconds)) * SAMPLE_DT
        log.log_series("/compute_time", t_single, name=["condition_check"], calls=[1], seconds=single.seconds[:, None])
        log.log_series("/compute_time", t_single[-1] + SAMPLE_DT * (1 + np.arange(len(batch.seconds))),
                       name=["condition_check_batch"], calls=[len(interior.error)], seconds=batch.seconds[:, None])
        log.attach("admittance.yaml", admittance_yaml(g, A_designed, "designed", info), "application/yaml")

    return [Case(case, lambda log, c=case: simulate(log, c)) for case in sc.cases]


# -- E2: quasi-static insertions --------------------------------------------------------------------------------


def log_trajectory(log: RunWriter, g: PegInHole, tr: insertion.Trajectory, speed: float, every: int) -> None:
    """The common topics of one quasi-static trajectory, every `every`-th sample (and the last); /assembly
    holds what condition (2) is judged on along the way (dᵀv, and whether the two-point state is on)."""
    keep = np.unique(np.r_[np.arange(0, len(tr.t), every), len(tr.t) - 1])
    t = tr.t[keep]
    dofs = TWIST_NAMES[g.dofs].tolist()
    v0 = geometry.nominal_twist(g, tr.R[keep], speed)
    log.log_series("/reference", t, units=twist_units(dofs), name=dofs, velocity=v0)
    log.log_series("/command", t, units=twist_units(dofs), kind="twist", name=dofs, value=tr.v[keep])
    log.log_series("/tracking_error", t, units="m", name=ERROR_NAMES, error=tr.delta[keep],
                   norm=np.linalg.norm(tr.delta[keep], axis=1))
    log_wrench(log, "/wrench", t, "peg", ["peg"], to_six(g, tr.w[keep]))
    pair = list(geometry.designated_pair(g))
    c = geometry.contacts(g, tr.R[keep], tr.p[keep])
    names, forces = geometry.forces_by_feature(g, tr.lam[keep][..., None] * c.normal, pair)
    log_wrench(log, "/wrench/contacts", t, "world", names, np.concatenate([forces, np.zeros_like(forces)], axis=-1))
    two_point = (tr.lam[keep][:, pair] > 0).all(axis=1)
    error = np.linalg.norm(tr.delta[keep], axis=1)
    log.log_series("/assembly", t, schemas.Scalars,
                   name=["error", "d_dot_v", "closing_rate", "active_contacts", "two_point_state", "min_gap"],
                   units=["m", "m^2/s", "m/s", "1", "1", "m"],
                   value=np.column_stack([error, tr.d_dot_v[keep], -tr.d_dot_v[keep] / error,
                                          (tr.lam[keep] > 0).sum(axis=1), two_point, tr.gap[keep].min(axis=1)]))


def log_scene(log: RunWriter, g: PegInHole, A: np.ndarray, tr: insertion.Trajectory, dt: float, tf_dt: float) -> None:
    """The scene of a quasi-static run on /markers: the peg and the hole (the cross-check's model), and at the
    instants of the peg's /tf (log_pose) each loaded candidate's point with its constraint force λ·n (N, on the
    peg) as an arrow, as the MuJoCo runs draw theirs."""
    from pipeline.papers.admittance_assembly import mujoco_peg

    log.write("/markers", 0, schemas.SceneUpdate(entities=mujoco_peg.drawing(g, A)))
    every = max(1, round(tf_dt / dt))
    lam = tr.lam[::every]
    c = geometry.contacts(g, tr.R[::every], tr.p[::every])
    loaded = lam > 0
    log.log_contacts(tr.t[::every], [c.point[i, on] for i, on in enumerate(loaded)],
                     [lam[i, on, None] * c.normal[i, on] for i, on in enumerate(loaded)], CONTACT_SCALE,
                     diameter=0.0008)


def insertion_runs(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario

    def simulate(log: RunWriter, case: str, kind: str, trial: int) -> None:
        g = peg_in_hole(cfg, case)
        A = admittance(cfg, case, kind)
        R, p, _ = geometry.chart_poses(g, start_coords(cfg, case, sc.trials)[trial])
        tr = insertion.insert(g, A, R[0], p[0], speed=cfg.system.nominal_speed, dt=sc.dt, duration=sc.duration,
                              active_gap=sc.active_gap)
        log.metadata["outcome"] = tr.outcome
        log_trajectory(log, g, tr, cfg.system.nominal_speed, max(1, round(sc.log_dt / sc.dt)))
        log_pose(log, tr.t, tr.R, tr.p, sc.dt, sc.tf_dt)
        log_scene(log, g, A, tr, sc.dt, sc.tf_dt)
        log.attach("admittance.yaml", admittance_yaml(g, A, kind), "application/yaml")

    return [Case(f"{case}-{kind}-{trial}", lambda log, c=case, k=kind, i=trial: simulate(log, c, k, i))
            for case in sc.cases for kind in sc.admittances for trial in range(sc.trials)]


# -- E3: MuJoCo cross-check ---------------------------------------------------------------------------------------


def mujoco_crosscheck(cfg: DictConfig) -> list[Case]:
    from pipeline.papers.admittance_assembly import mujoco_peg
    from pipeline.robotics.mjcf import check_mujoco

    sc, mj = cfg.scenario, cfg.mujoco
    speed = cfg.system.nominal_speed
    settings = mujoco_peg.MujocoSettings(mj.timestep, mj.mass, tuple(mj.solref), tuple(mj.solimp), mj.integrator)

    def simulate(log: RunWriter, case: str, run: str) -> None:
        g = peg_in_hole(cfg, case)
        A = admittance(cfg, case, sc.admittance)
        R0, p0, _ = geometry.chart_poses(g, start_coords(cfg, case, 1)[0])
        R0, p0 = R0[0], p0[0]
        sim = mujoco_peg.PegSim(g, A, settings)
        sim.set_pose(R0, p0)
        log.attach("model.xml", sim.xml, "application/xml")
        log.attach("admittance.yaml", admittance_yaml(g, A, sc.admittance), "application/yaml")
        pair = list(geometry.designated_pair(g))
        static = run == "static"
        if static:  # push into both contacts: the rigid answer is λ = λ*, v = 0
            c = geometry.contacts(g, R0, p0)
            W = geometry.unit_wrenches(g, R0, p0, c.point[:, pair], c.normal[:, pair])[0]
            v0_static = -A @ W @ np.asarray(sc.static_forces, float)
            sim.set_nominal(v0_static)
        duration = sc.static_duration if static else sc.duration
        steps = round(duration / settings.timestep)
        every = max(1, round(sc.log_dt / settings.timestep))
        rows = []
        for k in range(steps + 1):
            R, p = sim.pose()
            v0 = v0_static if static else geometry.nominal_twist(g, R, speed)[0]
            if k % every == 0 or k == steps:
                rows.append(_mujoco_sample(sim, g, A, R, p, v0, k * settings.timestep, sc.predict_gap))
                if not static and (R @ g.selected_point + p)[2] <= g.mated_point[2]:
                    break
            if k < steps:
                if not static:
                    sim.set_nominal(v0)
                sim.step()
        t = np.array([r["t"] for r in rows])
        qpos = np.array([r["qpos"] for r in rows])
        check_mujoco(sim.data, np.column_stack([qpos, [r["v"] for r in rows]]), t)
        log.metadata["outcome"] = "static" if static else "inserted" if rows[-1]["delta"][2] <= 0 else "timeout"
        _log_mujoco(log, g, sim, rows, t, sc.tf_dt)
        if not static:  # the quasi-static twin from the same start
            twin = insertion.insert(g, A, R0, p0, speed=speed, dt=sc.insertion_dt, duration=sc.duration,
                                    active_gap=sc.active_gap)
            keep = np.unique(np.r_[np.arange(0, len(twin.t), max(1, round(sc.log_dt / sc.insertion_dt))),
                                   len(twin.t) - 1])
            log.log_series("/tracking_error/quasi_static", twin.t[keep], units="m", name=ERROR_NAMES,
                           error=twin.delta[keep],
                           norm=np.linalg.norm(twin.delta[keep], axis=1))
            log_wrench(log, "/wrench/quasi_static", twin.t[keep], "peg", ["peg"], to_six(g, twin.w[keep]))
            log.metadata["quasi_static_outcome"] = twin.outcome

    return [Case(f"{case}-{run}", lambda log, c=case, r=run: simulate(log, c, r))
            for case in sc.cases for run in sc.runs]


def _mujoco_sample(sim, g: PegInHole, A: np.ndarray, R, p, v0, t: float, predict_gap: float) -> dict:
    """One logged instant of the MuJoCo run: measured and predicted wrenches, and per candidate contact the
    measured force (MuJoCo's contacts attributed to the nearest candidate that is within NEAR_GAP) and the
    predicted one (the rigid problem of the candidates within `predict_gap` at MuJoCo's pose)."""
    lam, w_pred, v_pred, c = insertion.predicted_response(g, A, R, p, 0.0, predict_gap, v0=v0)
    points, forces = sim.contact_forces()
    near = np.flatnonzero(c.valid[0] & (c.gap[0] < NEAR_GAP))
    measured = np.zeros((len(g.names), 3))
    if len(points) and len(near):
        owner = near[np.linalg.norm(points[:, None] - c.point[0, near][None], axis=2).argmin(axis=1)]
        np.add.at(measured, owner, forces)
    dist = min((con.dist for con in sim.data.contact[:sim.data.ncon]), default=0.0)
    w_meas = sim.contact_wrench()
    return {"t": t, "qpos": sim.data.qpos.copy(), "v": sim.twist(), "R": R, "p": p,
            "delta": geometry.error_vector(g, R, p)[0], "w_meas": w_meas, "w_pred": w_pred,
            "v_pred": v_pred, "law": v0 + A @ w_meas, "contacts_meas": measured, "points": points, "forces": forces,
            "contacts_pred": lam[:, None] * c.normal[0], "mujoco_contacts": len(points),
            "predicted_contacts": int((lam > 0).sum()), "penetration": -min(dist, 0.0)}


def _log_mujoco(log: RunWriter, g: PegInHole, sim, rows: list[dict], t: np.ndarray, tf_dt: float) -> None:
    col = {k: np.array([r[k] for r in rows]) for k in rows[0] if k not in ("t", "points", "forces")}
    qpos_names = [sim.model.joint(i).name for i in range(sim.model.njnt)] if g.planar else \
        ["x", "y", "z", "qw", "qx", "qy", "qz"]
    log.log_series("/joint_state", t, units=qpos_units(sim.model), name=qpos_names, position=col["qpos"])
    dofs = TWIST_NAMES[g.dofs].tolist()
    log.log_series("/command", t, units=twist_units(dofs), kind="twist", name=dofs, value=col["law"])
    log.log_series("/tracking_error", t, units="m", name=ERROR_NAMES, error=col["delta"],
                   norm=np.linalg.norm(col["delta"], axis=1))
    log_wrench(log, "/wrench", t, "peg", ["peg"], to_six(g, col["w_meas"]))
    log_wrench(log, "/wrench/predicted", t, "peg", ["peg"], to_six(g, col["w_pred"]))
    # one feature list on both topics: the designated pair's, then every feature loaded in either model
    loaded = np.abs(col["contacts_meas"]).sum(axis=(0, 2)) + np.abs(col["contacts_pred"]).sum(axis=(0, 2)) > 0
    order = list(geometry.designated_pair(g)) + list(np.flatnonzero(loaded))
    for topic, forces in (("/wrench/contacts", col["contacts_meas"]),
                          ("/wrench/contacts/predicted", col["contacts_pred"])):
        names, grouped = geometry.forces_by_feature(g, forces, order)
        log_wrench(log, topic, t, "world", names, np.concatenate([grouped, np.zeros_like(grouped)], -1))
    error = np.linalg.norm(col["delta"], axis=1)
    log.log_series("/assembly", t, schemas.Scalars,
                   name=["error", "twist_error", "law_residual", "mujoco_contacts", "predicted_contacts",
                         "penetration"],
                   units=["m", TWIST_NORM, TWIST_NORM, "1", "1", "m"],
                   value=np.column_stack([error, np.linalg.norm(col["v"] - col["v_pred"], axis=1),
                                          np.linalg.norm(col["v"] - col["law"], axis=1), col["mujoco_contacts"],
                                          col["predicted_contacts"], col["penetration"]]))
    log_pose(log, t, col["R"], col["p"], t[1] - t[0] if len(t) > 1 else 1.0, tf_dt)
    every = max(1, round(tf_dt / (t[1] - t[0]))) if len(t) > 1 else 1
    log.log_robot(t[::every], col["qpos"][::every])
    log.log_contacts(t[::every], [r["points"] for r in rows[::every]], [r["forces"] for r in rows[::every]],
                     CONTACT_SCALE, diameter=0.0008)
