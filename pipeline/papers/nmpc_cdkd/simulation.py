"""One point-to-point move in closed loop, in the order of spec §3.6: every `dt` the robot is read; every
`control_steps` updates an OCP is solved from the measured joints; the buffered inputs are integrated to joint
position commands; the decomposed NMPC's wrist motion is followed by the Jacobian-transpose orientation
controller (13) on q4..q6; the plant executes the command."""

from __future__ import annotations

import time
from collections.abc import Generator
from dataclasses import dataclass, field

import numpy as np

from pipeline.core.runlog import SimulationFailed
from pipeline.papers.nmpc_cdkd import kinematics as kin
from pipeline.papers.nmpc_cdkd import planning
from pipeline.papers.nmpc_cdkd.kinematics import Arm
from pipeline.papers.nmpc_cdkd.nmpc import Nmpc, Solution


@dataclass(frozen=True)
class Obstacles:
    """ν spheres moving with constant velocity from t = 0."""

    centres: np.ndarray     # (ν, 3) m at t = 0
    velocities: np.ndarray  # (ν, 3) m/s
    radii: np.ndarray       # (ν,) m

    @classmethod
    def none(cls) -> Obstacles:
        return cls(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0))

    def __len__(self) -> int:
        return len(self.radii)

    def at(self, t: np.ndarray) -> np.ndarray:
        """(..., ν, 3) centres at times t."""
        return self.centres + np.multiply.outer(np.asarray(t, dtype=float), self.velocities)


@dataclass(frozen=True)
class Move:
    T_start: np.ndarray                  # (4, 4) tool pose at rest before t0
    T_goal: np.ndarray                   # (4, 4) desired tool pose at t1 = t0 + T
    t0: float
    T: float
    duration: float
    obstacles: Obstacles = field(default_factory=Obstacles.none)
    band: tuple[float, float] | None = None   # wrist height bounds (10g), m; None: no row


@dataclass(frozen=True)
class Controller:
    """The settings of one closed loop, from the config."""

    dt: float
    control_steps: int
    gain: np.ndarray                     # K of (13)
    desired_from: str                    # command | measured: q_m of R_w^m in (3)
    warm_start: str                      # reference | shift
    obstacle_prediction: str             # constant_velocity | frozen
    on_failure: str                      # previous_plan | solver_iterate: what a failed solve executes
    initial_state: str                   # command | measured: the joints an OCP starts from
    sample_dt: float                     # t_γ
    wrist_band: float                    # rad, undefined wrist flag near q5 = 0 (jump check)


@dataclass(frozen=True)
class Start:
    """A closed loop that begins inside a move rather than at rest before it: at robot update `tick`, in joint
    state `q` (ideal plant: measured = commanded), with the two inputs applied before and a guess for the first
    OCP. Table 3's statistic is taken this way, on states sampled along the moves (experiments.py)."""

    tick: int
    q: np.ndarray            # (6,) rad
    u_prev: np.ndarray       # (2, 6) rad/s: [u_{-1}, u_{-2}]
    guess_q: np.ndarray      # (k+1, 6) rad: joints over the first OCP's horizon (nodes 0..k)
    guess_u: np.ndarray      # (k, 6) rad/s


@dataclass
class Trajectory:
    """Everything one run logs, sampled every dt (index j = time j·dt) and per OCP solve."""

    t: np.ndarray
    q: np.ndarray                 # measured joints
    qd: np.ndarray
    effort: np.ndarray            # joint torques (NaN on the kinematic plant)
    q_cmd: np.ndarray
    qd_cmd: np.ndarray
    q_ref: np.ndarray             # γ(t)
    qd_ref: np.ndarray
    orientation_error: np.ndarray  # ẽ of (11) as the controller used it (decomposed), or in {w} (full)
    centres: np.ndarray           # (n, ν, 3)
    tool_distance: np.ndarray | None   # (n, ν) MuJoCo tool-obstacle distance
    solve_t: np.ndarray
    solves: list[Solution]
    selection: planning.Selection
    planning_seconds: float       # cold, once (NaN if the caller planned); the warm timing is the experiments'


def _horizon_guess(nmpc: Nmpc, previous: Solution | None, shift: int, x_ref: np.ndarray,
                   u_ref: np.ndarray, mode: str) -> tuple[np.ndarray, np.ndarray]:
    """Initial guess: the polynomial reference (the paper, Sec. 3.2) or the previous solution shifted."""
    if mode == "reference" or previous is None:
        return x_ref, u_ref
    x = np.concatenate([previous.x[shift:], np.repeat(previous.x[-1:], shift, axis=0)])
    u = np.concatenate([previous.u[shift:], np.repeat(previous.u[-1:], shift, axis=0)])
    return x, u


def run(arm: Arm, nmpc: Nmpc, ctl: Controller, move: Move, make_plant,
        selection: planning.Selection | None = None, start: Start | None = None,
        solves: int | None = None) -> Trajectory:
    """Plan the move (Sec. 3.1) unless `selection` is given, then run it in closed loop; `make_plant(q0)`
    builds the plant at the start. With `start`, the loop begins there; with `solves`, it ends after that
    many OCPs."""
    loop = closed_loop(arm, nmpc, ctl, move, make_plant, selection, start, solves)
    while True:
        try:
            next(loop)
        except StopIteration as done:
            return done.value


def closed_loop(arm: Arm, nmpc: Nmpc, ctl: Controller, move: Move, make_plant,
                selection: planning.Selection | None = None, start: Start | None = None,
                solves: int | None = None) -> Generator[None, None, Trajectory]:
    """`run` as a generator that pauses after every OCP solve, so several closed loops can be advanced in
    turn (their solve times then see the same machine load) and returns the Trajectory (from `start.tick`
    on, when a start is given)."""
    t_start = time.perf_counter()
    sel = selection or planning.select_configuration(arm, move.T_start, move.T_goal,
                                                     round(move.T / ctl.sample_dt) + 1, ctl.wrist_band)
    poly = planning.JointPolynomial(sel.q_start, sel.q_goal, move.t0, move.T)
    planning_seconds = time.perf_counter() - t_start if selection is None else float("nan")
    dt, k, cs = ctl.dt, nmpc.s.horizon_steps, ctl.control_steps
    total = round(move.duration / dt)
    t_all = np.arange(total + k + 1) * dt                   # the horizon looks k steps past the end
    q_ref_all, qd_ref_all = poly(t_all), poly(t_all, 1)
    decomposed = nmpc.s.model == "decomposed"
    joints = slice(0, nmpc.nu)
    R_des = kin.tool_pose(arm, q_ref_all)[:, :3, :3] @ arm.tool[:3, :3].T   # R_w^f of the reference

    first = start.tick if start is not None else 0
    last = total if solves is None else min(total, first + solves * cs)
    n = last - first                                        # local index i is robot update first + i
    plant = make_plant(start.q if start is not None else sel.q_start)
    t = t_all[first:last + 1]
    q, qd, effort = np.empty((n + 1, 6)), np.empty((n + 1, 6)), np.empty((n + 1, 6))
    q_cmd, qd_cmd = np.empty((n + 1, 6)), np.zeros((n + 1, 6))
    e_o = np.zeros((n + 1, 3))
    nu_obs = len(move.obstacles)
    centres = move.obstacles.at(t)
    tool_distance = np.empty((n + 1, nu_obs)) if plant.kind == "mujoco" and nu_obs else None
    cmd = (start.q if start is not None else sel.q_start).copy()
    u_applied = np.zeros((2, nmpc.nu)) if start is None else start.u_prev[:, joints].copy()   # [u_{-1}, u_{-2}]
    solved, solve_t = [], []
    plan: Solution | None = None
    plan_start = 0
    last_solution: Solution | None = None
    radii = move.obstacles.radii + arm.safety_radius
    for i in range(n + 1):
        j = first + i
        q[i], qd[i], effort[i] = plant.q, plant.qd, plant.effort
        if tool_distance is not None:
            tool_distance[i] = plant.tool_distances()
        q_cmd[i] = cmd
        if i == n:
            break
        if i % cs == 0:                                     # a new OCP every control horizon
            nodes = t_all[j + 1:j + k + 1]
            x0 = nmpc.state(cmd if ctl.initial_state == "command" else q[i])
            ref = nmpc.reference(q_ref_all[j + 1:j + k + 1], quat_sign_of=None if decomposed else x0[3:7])
            if start is not None and last_solution is None:
                guess = nmpc.state(start.guess_q), start.guess_u[:, joints]
            else:
                guess = _horizon_guess(nmpc, last_solution, cs, nmpc.state(q_ref_all[j:j + k + 1]),
                                       qd_ref_all[j:j + k, joints], ctl.warm_start)
            obstacle_t = nodes if ctl.obstacle_prediction == "constant_velocity" else np.full(k, t_all[j])
            sol = nmpc.solve(x0, ref, u_applied, *guess, centres=move.obstacles.at(obstacle_t), radii=radii,
                             band=move.band)
            solved.append(sol)
            solve_t.append(t_all[j])
            last_solution = sol
            if sol.success or ctl.on_failure == "solver_iterate":
                plan, plan_start = sol, i
            yield
        offset = i - plan_start
        u = plan.u[offset] if plan is not None and offset < k else np.zeros(nmpc.nu)
        u_applied = np.stack([u, u_applied[0]])
        qd_cmd[i, joints] = u
        cmd[joints] += u * dt
        if decomposed:                                      # Sec. 3.3, eqs. (3), (11), (13)
            q_m = cmd[:3] if ctl.desired_from == "command" else q[i, :3]
            desired = kin.quaternion(kin.elbow_rotation(arm, q_m).T @ R_des[j + 1])
            current = kin.quaternion(kin.hand_rotation(arm, q[i, 3:]))
            e_o[i] = kin.orientation_error(desired, current)
            qd_o = kin.hand_jacobian(arm, q[i, 3:]).T @ (ctl.gain * e_o[i])
            cmd[3:] = np.clip(cmd[3:] + qd_o * dt, arm.lower[3:], arm.upper[3:])
            qd_cmd[i, 3:] = qd_o
        else:
            current = kin.quaternion(kin.tool_pose(arm, q[i])[:3, :3])
            e_o[i] = kin.orientation_error(kin.quaternion(R_des[j] @ arm.tool[:3, :3]), current)
        plant.step(cmd, qd_cmd[i], centres[i + 1])
        if not np.isfinite(plant.q).all():
            raise SimulationFailed(f"joint state not finite at t = {t[i + 1]:.3f} s")
    e_o[n] = e_o[n - 1]
    plant.check(t, np.concatenate([q, qd], axis=1))
    return Trajectory(t=t, q=q, qd=qd, effort=effort, q_cmd=q_cmd, qd_cmd=qd_cmd, q_ref=q_ref_all[first:last + 1],
                      qd_ref=qd_ref_all[first:last + 1], orientation_error=e_o, centres=centres,
                      tool_distance=tool_distance, solve_t=np.asarray(solve_t), solves=solved, selection=sel,
                      planning_seconds=planning_seconds)
