"""The servo drive of Sect. 4: set value generator, differentiator, the M1 grasp-current loop with its two
feed-forwards and the P-P-PI rotation cascade of M2, eqs. (10)-(18), at 50 / 200 / 400 µs; and the motor
windings it drives.

Everything that does not depend on the plant's state (the set value generator, the differentiator, the
lookup of the grasp current) is computed for the whole run at once (`Schedule`). What is left per 50 µs
tick is a few dozen multiplications, written with `+ - * / abs` only so that one `Drive` runs a single
simulation on Python floats (fast) or a batch of them on NumPy arrays (the Monte-Carlo grasps).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pipeline.papers.gripper_force_control.model import Gripper


def trapezoid(distance: float, omega_max: float, epsilon_max: float, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Set value generator (eq. 10): (φ, ω) at times t ≥ 0 of a move by `distance` (rad) with a trapezoidal
    (or triangular, for short moves) speed profile limited by ω_max and ε_max."""
    d = abs(distance)
    t_acc = omega_max / epsilon_max
    if d < omega_max * t_acc:                       # never reaches ω_max
        t_acc = math.sqrt(d / epsilon_max)
    peak = epsilon_max * t_acc
    t_end = 2 * t_acc + (d - peak * t_acc) / peak if d > 0 else 0.0
    t = np.clip(t, 0.0, t_end)
    t_dec = t_end - t_acc
    rest = np.maximum(t_end - t, 0.0)
    omega = np.where(t < t_acc, epsilon_max * t, np.where(t < t_dec, peak, epsilon_max * rest))
    phi = np.where(t < t_acc, 0.5 * epsilon_max * t * t,
                   np.where(t < t_dec, 0.5 * peak * t_acc + peak * (t - t_acc), d - 0.5 * epsilon_max * rest * rest))
    sign = math.copysign(1.0, distance)
    return sign * phi, sign * omega


def move_duration(distance: float, omega_max: float, epsilon_max: float) -> float:
    """Minimum time of a trapezoidal move (spec §8.8)."""
    d = abs(distance)
    if d < omega_max ** 2 / epsilon_max:
        return 2 * math.sqrt(d / epsilon_max)
    return d / omega_max + omega_max / epsilon_max


def differentiate(omega: np.ndarray, T: float, dt: float) -> np.ndarray:
    """Eqs. (11)-(12), forward Euler at the tick: ε_sr = ω_sr/T − A_v, dA_v/dt = ε_sr/T (= s/(Ts+1)),
    starting at rest (A_v = ω_sr(0)/T)."""
    epsilon = np.empty_like(omega)
    A_v, gain = omega[0] / T, dt / T
    for k, w in enumerate(omega.tolist()):   # a first-order recursion: a plain loop (scipy.signal costs 2 s to import)
        epsilon[k] = e = w / T - A_v
        A_v += gain * e
    return epsilon


@dataclass(frozen=True)
class Schedule:
    """What the robot asks of the gripper, at every current-loop tick k (time k·dt)."""

    t: np.ndarray           # s
    force: np.ndarray       # N, the commanded grasp force F_set (0 while opening); (ticks, batch) for a batch
    current: np.ndarray     # A, L(F_set) for the grasp; −L(F_open) while opening; same shape as force
    phi_sr: np.ndarray      # rad, gripper angle set point
    omega_sr: np.ndarray    # rad/s
    epsilon_sr: np.ndarray  # rad/s², from the differentiator

    @property
    def ticks(self) -> int:
        return len(self.t)


def schedule(p: Gripper, duration: float, force: float | np.ndarray, moves: Sequence[tuple[float, float]] = (),
             omega_max: float | None = None, epsilon_max: float | None = None,
             opening: tuple[float, float] | None = None) -> Schedule:
    """Hold F_set = `force` from t = 0 (an array: one set point per run of a batch); rotate by each (start
    time, angle) move in turn with the given limits (default: the drive's ω_max, ε_max); from `opening` =
    (time, force) on, open with the current of that force."""
    omega_max = p.omega_max if omega_max is None else omega_max
    epsilon_max = p.epsilon_max if epsilon_max is None else epsilon_max
    t = np.arange(round(duration / p.dt) + 1) * p.dt
    phi = np.zeros_like(t)
    omega = np.zeros_like(t)
    for start, angle in moves:
        dphi, domega = trapezoid(angle, omega_max, epsilon_max, t - start)
        after = t >= start
        phi += np.where(after, dphi, 0.0)
        omega += np.where(after, domega, 0.0)
    f = np.array(np.broadcast_to(force, (len(t), *np.shape(force))), dtype=float)
    current = p.lookup(f)
    if opening is not None:
        at, f_open = opening
        f[t >= at] = 0.0
        current[t >= at] = -p.lookup(f_open)
    return Schedule(t, f, current, phi, omega, differentiate(omega, p.T, p.dt))


def _rows(a: np.ndarray) -> list:
    """Per-tick values: Python floats for one run, one array per tick for a batch."""
    return a.tolist() if a.ndim == 1 else list(a)


def _clip(x, limit):
    """clip(x, −limit, limit) for floats and arrays alike."""
    return 0.5 * (abs(x + limit) - abs(x - limit))


class Drive:
    """The drive's state and one tick of eqs. (13)-(18) plus the windings.

    M2's direction is inverted in the drive (ψ_2 = −φ_2 = g_c φ_g), so that eq. (14) is negative feedback
    with eq. (7) (erratum: as printed the loop would push the gripper away from its set point).
    """

    __slots__ = ("A_1", "A_2", "I_1", "I_2", "I_max", "I_ref_1", "I_ref_2", "K_c1", "K_c2", "K_e_1", "K_e_2", "K_t",
                 "U_1", "U_2", "U_max", "current_abs", "current_ff", "decay", "direction", "g_1", "g_2", "g_s", "gain",
                 "limit_A", "limit_I", "omega_1_limit", "omega_ref", "p", "phi_sr", "voltage_ff")

    def __init__(self, p: Gripper, s: Schedule, I_1=0.0, I_2=0.0, phi_g=0.0):
        self.p = p
        # per-tick inputs as Python floats, or rows of a batch (list indexing is the fastest per-step access)
        eps = s.epsilon_sr if s.current.ndim == 1 else s.epsilon_sr[:, None]
        self.current_ff = _rows(s.current + p.K_eps * eps)                # eq. (13): L(F_set) + K_ε ε_sr
        self.voltage_ff = _rows(p.K_omega * s.omega_sr)                   # eq. (17): K_ω ω_sr
        self.phi_sr = _rows(s.phi_sr)
        self.direction = _rows(np.sign(s.current))                        # of the grasp current: + closes
        self.current_abs = _rows(np.abs(s.current))
        # constants of the 50 µs tick, as attributes of the drive (one lookup each)
        self.K_c1, self.K_c2, self.K_t, self.U_max, self.I_max = p.K_c1, p.K_c2, p.K_t, p.U_max, p.I_max
        self.K_e_1, self.K_e_2 = p.K_e, p.K_e * p.gear.g_c               # M2 turns at g_c ω_g (drive's direction)
        # exact solution of the winding L dI/dt = U − R I − K_e ω over one tick at constant U, ω
        self.decay = math.exp(-p.dt * p.R / p.L)
        self.gain = (1.0 - self.decay) / p.R
        self.g_1 = p.dt * p.K_c1 / p.T_c1                                   # eq. (15), forward Euler
        self.g_2 = p.dt * p.K_c2 / p.T_c2                                   # eq. (16)
        self.omega_1_limit = p.gear.g_f * p.speed_limit / p.l_f             # finger speed limit on M1's side
        self.g_s = p.dt * p.velocity_every / p.speed_integral_time
        # state: currents, integrators, the held outputs of the slower loops
        self.I_1, self.I_2 = I_1, I_2
        self.A_1, self.A_2 = p.R * I_1, p.R * I_2                          # at rest U = R I
        self.omega_ref = p.K_p * (self.phi_sr[0] - phi_g)                  # position loop output (rad/s)
        self.I_ref_2 = I_2
        self.I_ref_1 = I_1
        self.limit_A = self.current_abs[0]                                 # speed limiter's integrator
        self.limit_I = self.current_abs[0]
        self.U_1 = self.U_2 = 0.0

    def step(self, k: int, omega_1, phi_g, omega_g):
        """Tick k: measure (M1 speed, gripper angle and speed from M2's encoder), control, drive the windings
        for dt. Returns the motor torques (M1, M2 in the drive's direction) to apply over the tick."""
        p = self.p
        if k % p.velocity_every == 0:
            if k % p.position_every == 0:
                self.omega_ref = p.K_p * (self.phi_sr[k] - phi_g)                        # eq. (14), outer P
            self.I_ref_2 = _clip(p.K_v * (self.omega_ref - omega_g), p.I_max)           # eq. (14), inner P
            # M1's torque mode with a finger-speed limit: a PI on the overspeed that can only lower |I|
            e = self.omega_1_limit - self.direction[k] * (omega_1 - p.gear.k_g * omega_g)
            A = self.limit_A + self.g_s * e
            cap = self.current_abs[k]
            self.limit_A = 0.5 * (A + cap - abs(A - cap))                               # min(A, |I_cmd|)
            u = p.speed_gain * e + self.limit_A
            self.limit_I = 0.5 * (u + cap - abs(u - cap))                               # min(u, |I_cmd|)
        # the 50 µs part, _clip written out (a call per clip costs as much as the arithmetic)
        I_max, U_max = self.I_max, self.U_max
        I_cmd = self.current_ff[k] - self.direction[k] * (self.current_abs[k] - self.limit_I)
        self.I_ref_1 = I_ref_1 = 0.5 * (abs(I_cmd + I_max) - abs(I_cmd - I_max))
        # eqs. (13), (15), (17): PI with the back-EMF feed-forward; the integrator stops while U saturates
        e_1 = I_ref_1 - self.I_1
        u_1 = self.K_c1 * e_1 + self.A_1 + self.voltage_ff[k]
        self.U_1 = U_1 = 0.5 * (abs(u_1 + U_max) - abs(u_1 - U_max))
        self.A_1 += self.g_1 * e_1 * (abs(u_1) <= U_max)
        # eqs. (14), (16), (18)
        e_2 = self.I_ref_2 - self.I_2
        u_2 = self.K_c2 * e_2 + self.A_2
        self.U_2 = U_2 = 0.5 * (abs(u_2 + U_max) - abs(u_2 - U_max))
        self.A_2 += self.g_2 * e_2 * (abs(u_2) <= U_max)
        # windings over the tick
        decay, gain = self.decay, self.gain
        self.I_1 = I_1 = decay * self.I_1 + gain * (U_1 - self.K_e_1 * omega_1)
        self.I_2 = I_2 = decay * self.I_2 + gain * (U_2 - self.K_e_2 * omega_g)
        return self.K_t * I_1, self.K_t * I_2
