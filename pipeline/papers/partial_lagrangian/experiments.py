"""Simulate stage of `partial-lagrangian`: the chains of Figs. 1-5a, the slider reconstruction of Fig. 4,
the compute time of Fig. 5b, the symbolic term counts of eqs. (28)-(29), and the checks of the AD dynamics
against MuJoCo and closed forms."""

from __future__ import annotations

import time
from functools import partial

import numpy as np
from omegaconf import DictConfig

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import time_interleaved
from pipeline.papers.partial_lagrangian import chain as ch
from pipeline.papers.partial_lagrangian import lagrangian as lg
from pipeline.papers.partial_lagrangian.mujoco_chain import MujocoChain, chain_model
from pipeline.papers.partial_lagrangian.rollout import Gains, Trajectory, simulate, simulate_listing_a1

ENERGY_TERMS = ["kinetic", "potential", "total", "dissipation", "input_power"]


def chain_of(cfg: DictConfig, n: int, joints=None, angle=None) -> ch.Chain:
    """The first n links of the configured parameters (Sect. 3; links 3-10 assumed)."""
    return ch.from_config(cfg.system, n, joints, angle)


def _run(cfg: DictConfig, chain: ch.Chain, q0, gains: Gains, duration: float, listing: bool) -> Trajectory:
    sim = cfg.system.simulation
    qd0 = np.zeros(chain.n)
    if listing:
        traj = simulate_listing_a1(chain, q0, qd0, gains, sim.dt, duration)
    else:
        traj = simulate(chain, q0, qd0, gains, sim.dt, duration, form=sim.formulation, integrator=sim.integrator)
    bad = ~np.isfinite(traj.q).all(axis=1) | (np.abs(traj.qd) > 1e6).any(axis=1)
    if bad.any():
        raise SimulationFailed(f"state diverged at t = {traj.t[np.argmax(bad)]:.4g} s (time step too large?)")
    return traj


def joint_units(chain: ch.Chain) -> list[str]:
    """rad for a revolute joint's coordinate, m for a prismatic one's (the slider's length)."""
    return ["rad" if kind == ch.REVOLUTE else "m" for kind in chain.joints]


def every(cfg: DictConfig, period: float) -> slice:
    """Every sample `period` s apart, of a series stepped at the simulation's dt."""
    return slice(None, None, max(1, round(period / cfg.system.simulation.dt)))


def log_trajectory(log: RunWriter, cfg: DictConfig, chain: ch.Chain, traj: Trajectory, gains: Gains) -> None:
    """Every `logging.log_dt`: joint state, command, energies; with a controller, reference and error;
    every `logging.tf_dt`: the link tips as frames."""
    every_log = every(cfg, cfg.system.logging.log_dt)
    t, q, qd, tau = traj.t[every_log], traj.q[every_log], traj.qd[every_log], traj.tau[every_log]
    names, units = chain.joint_names(), joint_units(chain)
    log.log_series("/joint_state", t, units=units, name=names, position=q, velocity=qd, effort=tau)
    log.log_series("/command", t, units=units, kind="torque/force", name=names, value=tau)
    e = ch.energies(chain, q, qd)
    log.log_series("/energy", t, schemas.Scalars, name=ENERGY_TERMS, units=["J", "J", "J", "W", "W"],
                   value=np.column_stack([e["kinetic"], e["potential"], e["total"], 2 * e["rayleigh"],
                                          (tau * qd).sum(axis=1)]))
    if gains.controlled.any():
        idx = np.flatnonzero(gains.controlled)
        controlled, units = [names[i] for i in idx], [units[i] for i in idx]
        ref = np.tile(gains.reference[idx], (len(t), 1))
        log.log_series("/reference", t, units=units, name=controlled, position=ref)
        err = ref - q[:, idx]
        log.log_series("/tracking_error", t, units=units, name=controlled, error=err, norm=np.linalg.norm(err, axis=1),
                       field_units={"norm": " & ".join(sorted(set(units)))})
    tf = every(cfg, cfg.system.logging.tf_dt)
    log.log_transforms(traj.t[tf], "world", [f"tip{i + 1}" for i in range(chain.n)],
                       ch.pose_matrices(chain, traj.q[tf]))
    log.log_robot(traj.t[tf], traj.q[tf])  # the attached MuJoCo chain: its qpos are the paper's q


def _pd_gains(spec: DictConfig, n: int) -> Gains:
    return Gains(np.radians(np.asarray(spec.reference_deg, dtype=float)), np.asarray(spec.kp, dtype=float),
                 np.zeros(n), np.asarray(spec.kd, dtype=float))


# -- Figs. 1, 2, 3, 5a: free damped chains and PD control --------------------------------------------------


def pendulum(cfg: DictConfig) -> list[Case]:
    """One run per entry of `scenario.cases` (free: damped oscillation; pd: PD control to the references);
    with `scenario.listing_a1`, each again stepped as the paper's Listing A1 does."""
    sc = cfg.scenario
    chain = chain_of(cfg, sc.links)
    q0 = np.asarray(sc.initial, dtype=float)
    if q0.shape != (chain.n,):
        raise ValueError(f"scenario.initial needs {chain.n} values")

    def simulate_case(log: RunWriter, name: str, listing: bool) -> None:
        gains = _pd_gains(sc[name], chain.n) if name == "pd" else Gains.free(chain.n)
        log.attach("model.xml", chain_model(chain, cfg.system.simulation.dt), "application/xml")
        log_trajectory(log, cfg, chain, _run(cfg, chain, q0, gains, sc[name].duration, listing), gains)

    forms = [False, True] if sc.get("listing_a1", False) else [False]
    return [Case(f"{name}-listing" if listing else name,
                 lambda log, c=name, x=listing: simulate_case(log, c, x)) for name in sc.cases for listing in forms]


# -- Fig. 4: joint 2 becomes a slider under PID ----------------------------------------------------------


def slider(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    joints = list(sc.joints)
    slide = joints.index(ch.PRISMATIC)
    angle = [np.radians(sc.slider_angle_deg) if j == ch.PRISMATIC else 0.0 for j in joints]
    chain = chain_of(cfg, len(joints), joints, angle)
    n = chain.n

    def gain(value: float) -> np.ndarray:
        g = np.zeros(n)
        g[slide] = value
        return g

    gains = Gains(gain(sc.pid.reference), gain(sc.pid.kp), gain(sc.pid.ki), gain(sc.pid.kd))

    def simulate_case(log: RunWriter) -> None:
        log.attach("model.xml", chain_model(chain, cfg.system.simulation.dt), "application/xml")
        log_trajectory(log, cfg, chain, _run(cfg, chain, np.asarray(sc.initial, dtype=float), gains, sc.duration,
                                             listing=False), gains)

    return [Case("pid", simulate_case)]


# -- Fig. 5b: compute time ---------------------------------------------------------------------------------


def random_states(rng: np.random.Generator, n: int, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, q̇, τ), each (count, n): angles over a full turn, rates and torques of the runs' size."""
    return rng.uniform(-np.pi, np.pi, (count, n)), rng.uniform(-3, 3, (count, n)), rng.uniform(-50, 50, (count, n))


LinkTermsRow = schemas.define(
    "PartialLagrangianTerms", "Terms of link i's expanded symbolic partial Lagrangian L_i and of its derivatives "
    "(k = 1..i): ∂L_i/∂θ_k, ∂L_i/∂θ̇_k, τ_ki = D_k L_i; and the wall time of counting them (s).",
    link="int64 1", lagrangian="int64 1", d_angle="int64[] 1", d_rate="int64[] 1", tau="int64[] 1", seconds="double s",
)


def term_counts(cfg: DictConfig) -> list[Case]:
    """Eqs. (28)-(29) and 'about half' count symbolic terms: count them, link by link (a chain of n links is
    links 1..n; the counts of a link do not depend on the links after it), with SymPy (symbolic.py)."""
    from pipeline.papers.partial_lagrangian.symbolic import link_counts

    def simulate_case(log: RunWriter) -> None:
        for link in range(1, max(cfg.scenario.links) + 1):
            start = time.perf_counter()
            terms = link_counts(link - 1)
            log.log("/symbolic/terms", float(link), LinkTermsRow, link=link, lagrangian=terms.lagrangian,
                    d_angle=terms.d_angle, d_rate=terms.d_rate, tau=terms.tau, seconds=time.perf_counter() - start)

    return [Case("chains", simulate_case)]


def compute_time(cfg: DictConfig) -> list[Case]:
    """Per chain of n links, timed on one thread:

    - eval: one dynamics evaluation q̈(q, q̇, τ) by AD of the full Lagrangian, of the summed partial
      Lagrangians, and by MuJoCo's mj_step of the same chain (our extension);
    - terms: the coefficients of the equations of motion (M, b) of the full Lagrangian, of the summed partial
      Lagrangians, and of column n alone: the share of the slowest thread if the n columns of Table 1 ran in
      parallel (Sect. 4.1, eq. 29);
    - build: generating the graph of those terms and differentiating it, what the paper's define-by-run
      PyTorch code does every step.

    Evaluations are timed in batches of random states (one call each, inputs converted beforehand), sized
    to about `batch_instructions` CasADi instructions so that a batch is short next to a scheduler time
    slice on a shared machine yet long next to the call overhead. Every (method, n) is timed in interleaved
    rounds, so load changes fall on all of them alike."""
    import casadi as ca

    sc = cfg.scenario

    def simulate_case(log: RunWriter) -> None:
        import mujoco
        from mujoco import rollout

        rng = np.random.default_rng(cfg.seed)
        builds, evaluations, sizes = {}, {}, []

        def add_evaluation(name: str, fn: ca.Function, states: tuple[np.ndarray, ...]) -> None:
            batch = int(np.clip(round(sc.batch_instructions / fn.n_instructions()), 1, len(states[0])))
            evaluations[name] = (fn.map(batch), tuple(ca.DM(x[:batch].T) for x in states), batch)

        for n in sc.links:
            chain = chain_of(cfg, n)
            q, qd, tau = random_states(rng, n, sc.states)
            dyn = {form: lg.dynamics(chain, form) for form in lg.FORMS}
            last_column = lg.column_mass_bias(chain, n - 1)
            for form in lg.FORMS:
                add_evaluation(f"eval.{form}.n{n}", dyn[form].forward, (q, qd, tau))
                add_evaluation(f"terms.{form}.n{n}", dyn[form].mass_bias, (q, qd))
                builds[f"build.{form}.n{n}"] = (lg.equations_of_motion, (chain, form), 1)
            add_evaluation(f"terms.column.n{n}", last_column, (q, qd))
            builds[f"build.column.n{n}"] = (lg.column_mass_bias, (chain, n - 1), 1)
            model = mujoco.MjModel.from_xml_string(chain_model(chain, cfg.system.simulation.dt))
            batch = min(sc.mujoco_batch, sc.states)
            state = np.zeros((batch, mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)))
            state[:, 1:1 + n], state[:, 1 + n:1 + 2 * n] = q[:batch], qd[:batch]
            evaluations[f"eval.mujoco.n{n}"] = (partial(rollout.rollout, nstep=1),
                                                (model, mujoco.MjData(model), state), batch)
            sizes.append([n, dyn["full"].mass_bias.n_instructions(), dyn["partial"].mass_bias.n_instructions(),
                          last_column.n_instructions(), dyn["full"].inverse.n_instructions(),
                          dyn["partial"].inverse.n_instructions()])
        timings = {**time_interleaved(builds, warmup=sc.warmup, repeats=sc.build_repeats),
                   **time_interleaved(evaluations, warmup=sc.warmup, repeats=sc.eval_repeats)}
        t_log = 0.0
        for timing in timings.values():
            times = t_log + np.arange(len(timing.seconds)) * 1e-3
            log.log_series("/compute_time", times, name=[timing.name], calls=[timing.items_per_call],
                           seconds=timing.seconds[:, None])
            t_log = times[-1] + 1e-3
        sizes = np.array(sizes, dtype=float)
        log.log_series("/graph_size", sizes[:, 0], schemas.Scalars, value=sizes[:, 1:], units="1",
                       name=["terms.full", "terms.partial", "terms.column", "inverse.full", "inverse.partial"])

    return [Case("chains", simulate_case)]


# -- checks: AD against MuJoCo, full against partial, closed form, energy ------------------------------------


CHECK_TERMS = ["mass_matrix", "bias", "qdd_mujoco", "qdd_full_partial", "closed_form"]


def checks(cfg: DictConfig) -> list[Case]:
    """Per chain (n = 1..10 links, and the slider of Fig. 4): relative errors of M, b and q̈ of the AD
    dynamics against MuJoCo's at random states; full vs partial q̈; the closed-form double pendulum; the
    free damped motion from the paper's start beside MuJoCo's; the energy of the undamped chain."""
    sc = cfg.scenario
    chains = {f"n{n}": chain_of(cfg, n) for n in sc.links}
    if sc.slider:
        joints = [ch.REVOLUTE, ch.PRISMATIC, ch.REVOLUTE]
        chains["slider"] = chain_of(cfg, 3, joints, [0.0, 0.0, 0.0])

    def relative(a, b) -> float:
        return float(np.abs(np.asarray(a) - b).max() / max(np.abs(b).max(), 1e-300))

    def simulate_case(log: RunWriter, key: str, index: int) -> None:
        chain, dt = chains[key], cfg.system.simulation.dt
        rng = np.random.default_rng([cfg.seed, index])
        q, qd, tau = random_states(rng, chain.n, sc.states)
        q0 = np.zeros(chain.n)
        if key == "slider":
            q[:, 1] = rng.uniform(0.1, 1.5, sc.states)   # a slider length, not an angle
            q0[1] = chain.length[1]
        ad = {form: lg.dynamics(chain, form) for form in lg.FORMS}
        mj = MujocoChain(chain, dt)
        closed = lg.dynamics(chain.undamped()) if chain.n == 2 else None
        errors = np.full((sc.states, len(CHECK_TERMS)), np.nan)
        for k in range(sc.states):
            M, b = (np.array(x) for x in ad["partial"].mass_bias(q[k], qd[k]))
            M_mj, b_mj = mj.mass_bias(q[k], qd[k])
            qdd = {form: np.array(d.forward(q[k], qd[k], tau[k])).ravel() for form, d in ad.items()}
            errors[k, :4] = (relative(M, M_mj), relative(b.ravel(), b_mj),
                             relative(qdd["partial"], mj.forward(q[k], qd[k], tau[k])),
                             relative(qdd["partial"], qdd["full"]))
            if closed is not None:
                M2, b2 = (np.array(x) for x in closed.mass_bias(q[k], qd[k]))
                M_c, b_c = ch.double_pendulum(chain, q[k], qd[k])
                errors[k, 4] = max(relative(M2, M_c), relative(b2.ravel(), b_c))
        log.log_series("/check/random_states", np.arange(sc.states) * 1e-3, schemas.Scalars, name=CHECK_TERMS,
                       value=errors, units="1")   # relative errors
        log.attach("model.xml", mj.xml, "application/xml")
        # free damped motion from the paper's start (at rest, straight), both integrated by the same Euler step
        traj = simulate(chain, q0, np.zeros(chain.n), Gains.free(chain.n), dt, sc.trajectory_duration)
        q_mj, qd_mj = mj.rollout(q0, np.zeros(chain.n), len(traj.t) - 1)
        q_mj, qd_mj = np.vstack([q0, q_mj]), np.vstack([np.zeros(chain.n), qd_mj])
        names, logged, units = chain.joint_names(), every(cfg, cfg.system.logging.log_dt), joint_units(chain)
        log.log_series("/joint_state", traj.t[logged], units=units, name=names, position=traj.q[logged],
                       velocity=traj.qd[logged])
        log.log_series("/joint_state/mujoco", traj.t[logged], schemas.JointState, units=units, name=names,
                       position=q_mj[logged], velocity=qd_mj[logged])
        log.log_robot(traj.t[logged], q_mj[logged])
        for integrator in sc.energy_integrators:
            free = simulate(chain.undamped(), q0, np.zeros(chain.n), Gains.free(chain.n), dt, sc.energy_duration,
                            integrator=integrator)
            e = ch.energies(chain.undamped(), free.q[logged], free.qd[logged])
            log.log_series(f"/energy/{integrator}", free.t[logged], schemas.Scalars, name=["total"], value=e["total"],
                           units="J")

    return [Case(key, lambda log, k=key, i=i: simulate_case(log, k, i)) for i, key in enumerate(chains)]
