"""The FreeBOT manipulator in closed loop (Fig. 6): trolleys on the exact rolling plant, and the two ways the
paper drives it — position mode (IK, position planning, steer then forward; Sec. V-B) and velocity mode
(pose references through the damper QP, velocity planning, steer while forward; Sec. V-C).

Sensing is ideal: the controller reads the plant's joint configuration (FreeBOT-SIM's sensors) and the
trolleys' own encoders (φ, s); position mode can also steer by the encoders alone, as the physical FreeBOTs
do. The plant may differ from the controller's model by `Defects`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from pipeline.papers.src_joint import trolley as tr
from pipeline.papers.src_joint.ik import Bars, DamperQP, IkGains, pose_error, reference_twist
from pipeline.papers.src_joint.model import Chain, ModelForm
from pipeline.papers.src_joint.rolling import RollingChain, trolley_rates

SENSING = ("measured", "encoders")


@dataclass(frozen=True)
class Defects:
    """How the simulated FreeBOTs differ from the model (the stand-in for the paper's hardware error)."""

    radius_offset: float = 0.0   # m added to every sphere's effective radius (EVA foam compression < 0)
    slip: float = 0.0            # fraction of the trolley's forward travel the shell does not roll


@dataclass
class Trace:
    """Per controller tick (k samples) what the run logs."""

    times: list = field(default_factory=list)
    frames: list = field(default_factory=list)       # (n+1, 4, 4) body poses of the plant
    relative: list = field(default_factory=list)     # (n, 3, 3) ^{B_{i-1}}R_{B_i} of the plant
    tangent: list = field(default_factory=list)      # (n, 3, 3) ^{B_{i-1}}R_{P_i}; column 2 is the contact normal
    joint_velocity: list = field(default_factory=list)  # (n, 2) realised w
    heading: list = field(default_factory=list)      # (n,) φ
    arc: list = field(default_factory=list)          # (n,) s (encoder)
    u_forward: list = field(default_factory=list)
    u_steer: list = field(default_factory=list)
    wheels: list = field(default_factory=list)       # (n, 2) ω_r, ω_l
    reference: list = field(default_factory=list)    # per joint: (s^r − s, φ^r) in position mode, w^r in velocity
    qp_seconds: list = field(default_factory=list)
    model_seconds: list = field(default_factory=list)
    slack: list = field(default_factory=list)

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.asarray(v) for k, v in self.__dict__.items() if v}


class FreeBotArm:
    """n FreeBOTs in a chain on a fixed base FreeBOT, each joint driven by the trolley inside its upper sphere."""

    def __init__(self, n: int, bot: tr.FreeBot, radius: float, heading0, defects: Defects = Defects()):
        self.n, self.bot, self.defects = n, bot, defects
        self.plant = RollingChain(np.full(n + 1, radius + defects.radius_offset))
        self.heading = np.array(heading0[:n], dtype=float)
        self.arc = np.zeros(n)
        self.u_forward = np.zeros(n)   # the forward speed being held

    def drive(self, wheel_right: np.ndarray, wheel_left: np.ndarray, duration: float) -> None:
        """Hold the wheel speeds for `duration`: plant and trolleys move exactly (constant u_f, u_s)."""
        u_forward, u_steer = self.bot.trolley_speeds(wheel_right, wheel_left)   # eq. (64)
        self.u_forward = u_forward
        self.plant.roll(self.tangent_rates(), duration, u_steer)
        self.heading = self.heading + u_steer * duration    # eq. (49)
        self.arc = self.arc + u_forward * duration          # the encoders count the commanded travel

    def tangent_rates(self) -> np.ndarray:
        """Ω^B (n, 2) the shells turn at now: eq. (50) with the travel the contact does not slip."""
        return trolley_rates(self.u_forward * (1.0 - self.defects.slip), self.heading, self.bot.r_out)

    def sample(self, trace: Trace, t: float) -> None:
        """Record the plant and the trolleys at time t."""
        pos, rot = self.plant.frames()
        T = np.tile(np.eye(4), (self.n + 1, 1, 1))
        T[:, :3, :3], T[:, :3, 3] = rot, pos
        trace.times.append(t)
        trace.frames.append(T)
        trace.relative.append(self.plant.relative)     # the plant replaces, never mutates, these arrays
        trace.tangent.append(self.plant.tangent)
        trace.joint_velocity.append(np.einsum("nji,nj->ni", self.plant.tangent,
                                              self.plant.relative_velocity(self.tangent_rates()))[:, :2])
        trace.heading.append(self.heading.copy())
        trace.arc.append(self.arc.copy())


@dataclass(frozen=True)
class Controller:
    """What the controller knows: the paper's parameters and model form."""

    bot: tr.FreeBot
    radius: float
    form: ModelForm
    gains: tr.Gains
    ik: IkGains
    steer_tol: float
    azimuth: str
    min_rate: float
    min_arc: float
    dt: float

    def __post_init__(self) -> None:
        if self.azimuth not in tr.AZIMUTHS:
            raise ValueError(f"azimuth={self.azimuth!r}: must be one of {tr.AZIMUTHS}")

    def radii(self, n: int) -> np.ndarray:
        return np.full(n + 1, self.radius)


def _apply(arm: FreeBotArm, c: Controller, trace: Trace, u_forward: np.ndarray, u_steer: np.ndarray) -> None:
    right, left = c.bot.wheel_speeds(u_forward, u_steer)          # eq. (65)
    trace.u_forward.append(u_forward)
    trace.u_steer.append(u_steer)
    trace.wheels.append(np.stack([right, left], axis=-1))
    arm.drive(right, left, c.dt)


def position_mode(arm: FreeBotArm, c: Controller, tangent_ref: np.ndarray, duration: float,
                  sensing: str = "measured") -> Trace:
    """Sec. V-B: bring each joint's contact point to the IK's, eqs. (53)-(55), steering first, then forward.

    `measured` (FreeBOT-SIM, "calculated using (53)-(55)"): the arc left and its azimuth are recomputed every
    tick from the measured contact point. `encoders` (the physical FreeBOTs): they are planned once and the
    arc travelled is what the wheel encoders count, so the plant's defects go uncorrected."""
    if sensing not in SENSING:
        raise ValueError(f"sensing={sensing!r}: must be one of {SENSING}")
    lower = c.radii(arm.n)[:-1]
    arc_ref, heading_ref = tr.position_plan(arm.plant.tangent, tangent_ref, lower, c.azimuth)
    trace = Trace()
    forward = np.zeros(arm.n, dtype=bool)
    for k in range(round(duration / c.dt) + 1):
        arm.sample(trace, k * c.dt)
        if sensing == "measured":
            arc_left, heading_now = tr.position_plan(arm.plant.tangent, tangent_ref, lower, c.azimuth)
            # the azimuth of an arc that has (almost) been travelled is undefined: keep the last one
            heading_ref = np.where(arc_left > c.min_arc, heading_now, heading_ref)
            arc_error = arc_left
        else:
            arc_error = arc_ref - arm.arc
        trace.reference.append(np.stack([arc_error, heading_ref], axis=-1))
        u_forward, u_steer, forward = tr.steer_then_forward(arm.heading, heading_ref, arc_error, forward, c.gains,
                                                            c.steer_tol)
        _apply(arm, c, trace, u_forward, u_steer)
    return trace


def velocity_mode(arm: FreeBotArm, c: Controller, r_desired: np.ndarray, q_desired: np.ndarray, bars: Bars,
                  qp: DamperQP, duration: float, avoid: bool = True) -> Trace:
    """Sec. V-C: every tick, joint velocities from the damper QP, then (52) and (56)-(57)."""
    radii = c.radii(arm.n)
    radius_eq = tr.equivalent_radius(radii[:-1], radii[1:])
    trace = Trace()
    heading_ref_prev = heading_ref = arm.heading.copy()
    for k in range(round(duration / c.dt) + 1):
        arm.sample(trace, k * c.dt)
        start = time.perf_counter()
        chain = Chain(radii, c.form, *arm.plant.model_state())   # the model at the measured configuration
        Jv, Jw, pos, _ = chain.jacobians()
        e_p, delta = pose_error(pos[-1], chain.orientation(), r_desired, q_desired)
        clearance, normals = bars.clearance(pos[1:], radii[1:])
        A, b = qp.rows(Jv[1:], clearance, normals)
        mid = time.perf_counter()
        w_ref, slack = qp.solve(np.vstack([Jv[-1], Jw[-1]]), reference_twist(e_p, delta, c.ik), A,
                                b if avoid else np.full_like(b, np.inf))
        trace.qp_seconds.append(time.perf_counter() - mid)
        trace.model_seconds.append(mid - start)
        trace.slack.append(slack)
        w_ref = w_ref.reshape(arm.n, 2)
        trace.reference.append(w_ref)
        u_forward_ref, heading_new = tr.velocity_plan(w_ref, radius_eq)                  # eq. (52)
        moving = np.linalg.norm(w_ref, axis=-1) >= c.min_rate
        heading_ref = np.where(moving, heading_new, heading_ref)
        heading_rate = tr.wrap(heading_ref - heading_ref_prev) / c.dt if k else np.zeros(arm.n)  # φ̇^r of (56)
        heading_ref_prev = heading_ref
        u_forward, u_steer = tr.steer_while_forward(arm.heading, heading_ref, heading_rate, u_forward_ref, c.gains)
        _apply(arm, c, trace, u_forward, u_steer)
    return trace
