"""The lumped plant: two motor inertias coupled by the gearbox, a soft pad between finger and object, and
Coulomb + viscous friction on M1's shaft and the gripper axis (spec §3, "recommended simulation model").

In motor coordinates the kinetic energy is ½ J_M1 ω_1² + ½ J_M2 g_c² ω_g² (the paper lumps every inertia
into J_M1 and J_M2), so the mass matrix is diagonal and the gearbox only enters through the contact force
F at the finger end. With φ_f = (φ_1 − k_g φ_g)/g_f and virtual work F l_f δφ_f:

    J_M1 ω̇_1        = τ_1 − F l_f / g_f            − τ_fr,1
    J_M2 g_c² ω̇_g   = g_c τ_2 + k_g F l_f / g_f    − τ_fr,g
    F = max(0, k_c δ + c_c δ̇) while δ = l_f φ_f > 0 (the pad touches the object at φ_f = 0)

Integration: semi-implicit Euler at the current-loop tick; friction is solved implicitly per axis (stick if
the friction cone can stop the axis within the tick, else slide), which gives true stiction without a
regularising velocity. Works on floats (one run) or arrays (a batch).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.gripper_force_control.drive import Drive, Schedule, _clip
from pipeline.papers.gripper_force_control.model import Gripper

TRACE_FIELDS = ("phi_1", "omega_1", "phi_g", "omega_g", "phi_f", "omega_f", "force", "I_1", "I_2",
                "I_ref_1", "I_ref_2", "U_1", "U_2")


@dataclass
class Trace:
    """A run sampled every `log_every` ticks: one array per field, shape (samples,) or (samples, batch)."""

    t: np.ndarray
    fields: dict[str, np.ndarray]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.fields[name]


@dataclass(frozen=True)
class Start:
    """Initial state: positions at rest, and the drive's currents (A) and gripper set point."""

    phi_f: float | np.ndarray = 0.0
    phi_g: float = 0.0
    I_1: float = 0.0
    I_2: float = 0.0


def static_grasp(p: Gripper, force: float) -> Start:
    """The equilibrium of a held grasp without friction: I_1 = L(F_set), the pad compressed by the force that
    current makes (eq. 8), M2 holding the reaction k_g F l_f/g_f of the gearbox on the gripper."""
    I_1 = p.lookup(force)
    f = I_1 * p.force_per_amp
    I_2 = -p.gear.k_g * f * p.l_f / (p.gear.g_f * p.gear.g_c * p.K_t)
    return Start(phi_f=f / (p.k_c * p.l_f), phi_g=-I_2 / (p.K_v * p.K_p), I_1=I_1, I_2=I_2)


def contact_force(p: Gripper, phi_f, omega_f):
    """Pad force at the finger end: spring-damper, pushing only, only while touching."""
    d = p.l_f * phi_f
    f = p.k_c * d + p.c_c * p.l_f * omega_f
    return 0.5 * (f + abs(f)) * (d > 0)


def accelerations(p: Gripper, tau_1, tau_2, phi_1, omega_1, phi_g, omega_g, tau_fr_1=0.0, tau_fr_g=0.0):
    """(ω̇_1, ω̇_g, F): the continuous model above, for given motor torques and friction torques (`simulate`
    passes none and solves the friction per tick)."""
    kg, n = p.gear.k_g, p.gear.g_f
    F = contact_force(p, (phi_1 - kg * phi_g) / n, (omega_1 - kg * omega_g) / n)
    return ((tau_1 - F * p.l_f / n - tau_fr_1) / p.J_1,
            (p.gear.g_c * tau_2 + kg * F * p.l_f / n - tau_fr_g) / p.J_g, F)


def simulate(p: Gripper, s: Schedule, start: Start, log_every: int) -> Trace:
    """Run the drive and the lumped plant over the schedule; sample every `log_every` ticks."""
    kg, n, h = p.gear.k_g, p.gear.g_f, p.dt
    hold_1, hold_g = p.J_1 / h, p.J_g / h        # friction torque that stops the axis within one tick
    visc_1, visc_g = 1.0 + h * p.b_1 / p.J_1, 1.0 + h * p.b_g / p.J_g
    tau_c1, tau_cg = p.tau_c1, p.tau_cg
    zero = np.zeros_like(np.asarray(start.phi_f, dtype=float))
    phi_g = start.phi_g + zero
    phi_1 = kg * phi_g + n * (start.phi_f + zero)
    omega_1 = omega_g = zero + 0.0
    if zero.ndim == 0:                           # one run: plain floats are 5x faster than 0-d arrays
        phi_1, phi_g, omega_1, omega_g = float(phi_1), float(phi_g), 0.0, 0.0
    drive = Drive(p, s, start.I_1, start.I_2, start.phi_g)
    samples = range(0, s.ticks, log_every)
    rec = np.empty((len(samples), len(TRACE_FIELDS), *zero.shape))
    j = 0
    for k in range(s.ticks):
        I_1, I_2 = drive.I_1, drive.I_2
        tau_1, tau_2 = drive.step(k, omega_1, phi_g, omega_g)
        a_1, a_g, F = accelerations(p, tau_1, tau_2, phi_1, omega_1, phi_g, omega_g)
        if k % log_every == 0:
            phi_f, omega_f = (phi_1 - kg * phi_g) / n, (omega_1 - kg * omega_g) / n
            for i, value in enumerate((phi_1, omega_1, phi_g, omega_g, phi_f, omega_f, F, I_1, I_2, drive.I_ref_1,
                                       drive.I_ref_2, drive.U_1, drive.U_2)):
                rec[j, i] = value
            j += 1
        free_1, free_g = omega_1 + h * a_1, omega_g + h * a_g
        omega_1 = (free_1 - _clip(free_1 * hold_1, tau_c1) / hold_1) / visc_1
        omega_g = (free_g - _clip(free_g * hold_g, tau_cg) / hold_g) / visc_g
        phi_1 = phi_1 + h * omega_1
        phi_g = phi_g + h * omega_g
    return Trace(s.t[::log_every], {name: rec[:, i] for i, name in enumerate(TRACE_FIELDS)})
