"""Path tracking of Sec. 5 (modified pure pursuit, eqs. 53-58) for a batch of robots of mixed classes,
integrated together (one NumPy pass per step for the whole batch).

Each robot's control law is one row of a gain table: the four laws (55)-(58) are the same expression
with different coefficients,

    roll rate  θ̇ (α̇ for RS) = (k_roll_g g + k_roll_0) cos ζ + feedforward · ‖ṗ_d‖ / R
    tilt rate  φ̇            = −(k_lat_g g + k_lat_0) sin ζ + k_tilt ζ
    turn rate  ψ̇            = k_turn ζ          (RS: −α̇ sin φ, eq. 44)

with g = ‖e_t‖ / (k_e + ‖e_t‖), e_t = p_d − P0 (eq. 53) and ζ the signed angle from ĥ to e_t about n̂
(eq. 54 gives an unsigned angle; the sign is assumption A2: counter-clockwise positive).

State per robot: [x0, y0, z0, ψ, φ, θ] (θ is α for RS).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from pipeline.papers.spherical_terrain.kinematics import CosineTerrain, local_components
from pipeline.papers.spherical_terrain.paths import reference

CLASSES = ("3r", "2r", "rt", "rs")
# eq. (58) as printed: φ̇ = +k_φ ζ. With the corrected ψ of eq. (25) a tilt φ > 0 turns the robot clockwise
# (eq. 44), so the tilt must oppose ζ: φ̇ = −k_φ ζ (erratum 3).
TILT_SIGN = {"corrected": -1.0, "printed": 1.0}


@dataclass(frozen=True)
class GainTable:
    """One entry per robot (arrays of shape (K,))."""

    roll_g: np.ndarray
    roll_0: np.ndarray
    feedforward: np.ndarray
    lat_g: np.ndarray
    lat_0: np.ndarray
    tilt: np.ndarray
    turn: np.ndarray
    steering: np.ndarray      # bool: RS-SR (cone kinematics, tilt limit)

    @classmethod
    def build(cls, classes: Sequence[str], gains: Mapping, scale: float = 1.0, eq58: str = "corrected"):
        """Rows for `classes` from the config's per-class gains; `scale` multiplies every feedback gain."""
        rows = []
        for robot in classes:
            if robot not in CLASSES:
                raise ValueError(f"unknown robot class {robot!r}: one of {', '.join(CLASSES)}")
            k = gains[f"class_{robot}"]
            row = {"roll_g": 0.0, "roll_0": 0.0, "feedforward": 0.0, "lat_g": 0.0, "lat_0": 0.0, "tilt": 0.0,
                   "turn": 0.0, "steering": False}
            if robot == "3r":    # eq. (55)
                row |= {"roll_g": k.k_theta, "feedforward": 1.0, "lat_g": k.k_phi1, "lat_0": k.k_phi2,
                        "turn": k.k_psi}
            elif robot == "2r":  # eq. (56): no feed-forward, ψ̇ = 0
                row |= {"roll_g": k.k_theta1, "roll_0": k.k_theta2, "lat_g": k.k_phi1, "lat_0": k.k_phi2}
            elif robot == "rt":  # eq. (57): φ̇ = 0
                row |= {"roll_g": k.k_theta, "feedforward": 1.0, "turn": k.k_psi}
            elif robot == "rs":  # eq. (58); ψ̇ from eq. (44)
                row |= {"roll_g": k.k_alpha, "feedforward": 1.0, "tilt": TILT_SIGN[eq58] * k.k_phi,
                        "steering": True}
            for key in ("roll_g", "roll_0", "lat_g", "lat_0", "tilt", "turn"):
                row[key] = float(row[key]) * scale
            rows.append(row)
        return cls(**{f: np.array([r[f] for r in rows], dtype=bool if f == "steering" else float)
                      for f in cls.__dataclass_fields__})


@dataclass(frozen=True)
class Model:
    terrain: CosineTerrain
    radius: float
    k_e: float
    tilt_limit: float
    gains: GainTable
    heading: str = "corrected"   # eq. (25): corrected | printed


def _dot(a: tuple, b: tuple):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def controls(model: Model, state: np.ndarray, p_d: np.ndarray, v_d: np.ndarray) -> dict:
    """The pursuit law and the rates it produces for states (..., K, 6), broadcast over leading axes.

    Returns roll (θ̇ / α̇), tilt_command (φ̇ asked for), tilt (φ̇ applied: 0 when the RS tilt is at its limit
    and the command pushes beyond), turn (ψ̇), zeta, g, ^L V = (u, v), and as component triples the error
    e_t, the velocity (ẋ, ẏ, ż) and the frame (h, l, n)."""
    k = model.gains
    x, y, z, psi, phi = (state[..., i] for i in range(5))
    fx, fy = model.terrain.gradient(x, y)
    h, lat, n = local_components(fx, fy, psi, model.heading)
    e = (p_d[..., 0] - x, p_d[..., 1] - y, p_d[..., 2] - z)                 # eq. (53)
    zeta = np.arctan2(_dot(e, lat), _dot(e, h))                              # eq. (54), signed about n̂
    norm = np.sqrt(_dot(e, e))
    g = norm / (model.k_e + norm)
    roll = (k.roll_g * g + k.roll_0) * np.cos(zeta) + k.feedforward * v_d / model.radius
    tilt_command = -(k.lat_g * g + k.lat_0) * np.sin(zeta) + k.tilt * zeta
    at_limit = k.steering & (((phi >= model.tilt_limit) & (tilt_command > 0))
                             | ((phi <= -model.tilt_limit) & (tilt_command < 0)))
    tilt = np.where(at_limit, 0.0, tilt_command)
    turn = np.where(k.steering, -roll * np.sin(phi), k.turn * zeta)         # eq. (44) for RS
    u = model.radius * roll * np.where(k.steering, np.cos(phi), 1.0)        # eqs. (33), (38), (48)
    v = -model.radius * tilt
    velocity = tuple(u * hi + v * li for hi, li in zip(h, lat, strict=True))   # eq. (31)
    return {"roll": roll, "tilt_command": tilt_command, "tilt": tilt, "turn": turn, "zeta": zeta, "g": g,
            "error": e, "u": u, "v": v, "velocity": velocity, "h": h, "l": lat, "n": n}


def _derivative(model: Model, state: np.ndarray, p_d, v_d, out: np.ndarray) -> np.ndarray:
    c = controls(model, state, p_d, v_d)
    out[..., 0], out[..., 1], out[..., 2] = c["velocity"]
    out[..., 3], out[..., 4], out[..., 5] = c["turn"], c["tilt"], c["roll"]
    return out


@dataclass(frozen=True)
class Trajectory:
    """Integrated batch, sampled every `log_every` steps: t (N,), state (N, K, 6), p_d, p_d_dot (N, K, 3)."""

    t: np.ndarray
    state: np.ndarray
    p_d: np.ndarray
    p_d_dot: np.ndarray


def references(model: Model, paths: Sequence[str], t: np.ndarray, paths_cfg, circle_form: str):
    """(p_d, ṗ_d), each (len(t), K, 3), for robots following the named paths of Sec. 6."""
    cache = {name: reference(model.terrain, name, t, paths_cfg, circle_form) for name in set(paths)}
    return (np.stack([cache[p][0] for p in paths], axis=1), np.stack([cache[p][1] for p in paths], axis=1))


def simulate(model: Model, dt: float, p_d: np.ndarray, p_d_dot: np.ndarray, start: np.ndarray,
             log_every: int = 1) -> Trajectory:
    """Forward Euler with step dt for the whole batch: p_d, ṗ_d (N+1, K, 3) at t = i·dt, `start` (K, 6);
    the result is sampled every `log_every` steps.

    Why not RK4: the pursuit law is discontinuous where the target is passed (ζ jumps by π), so near the
    target the robots chatter; RK4's intermediate stages then straddle the jump and settle in a limit cycle
    several times larger than one step, while an explicit step chatters within ‖V‖·dt. Each step is also
    what a controller sampled at 1/dt would do. The RS tilt is clipped to ±tilt_limit after each step (a
    saturating integrator, assumption A5); z0 is set to f(x0, y0), which eq. (31)'s ż = f_x ẋ + f_y ẏ keeps
    exactly, while integrating it would drift with the chattering."""
    steps = len(p_d) - 1
    v_d = np.linalg.norm(p_d_dot, axis=-1)
    state = np.array(start, dtype=float)
    logged = [state.copy()]
    steering = model.gains.steering
    rate = np.empty_like(state)
    for i in range(steps):
        state += dt * _derivative(model, state, p_d[i], v_d[i], rate)
        state[steering, 4] = np.clip(state[steering, 4], -model.tilt_limit, model.tilt_limit)
        state[:, 2] = model.terrain.height(state[:, 0], state[:, 1])
        if (i + 1) % log_every == 0:
            logged.append(state.copy())
    samples = slice(None, None, log_every)
    return Trajectory(np.arange(steps + 1)[samples] * dt, np.array(logged), p_d[samples], p_d_dot[samples])


def start_states(terrain: CosineTerrain, k: int, x: float, y: float, heading: float) -> np.ndarray:
    """(K, 6): every robot at contact point (x, y, f(x, y)), turning angle ψ0 = heading, φ = θ = 0."""
    return np.tile([x, y, float(terrain.height(x, y)), heading, 0.0, 0.0], (k, 1))
