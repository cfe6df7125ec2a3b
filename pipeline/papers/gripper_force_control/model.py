"""The gripper's parameters: gear ratios from the pitch diameters (eqs. 1-4), the coupling of the Torque
Distribution Gearbox, the motors, the controller gains of Sect. 5 and the feed-forward gains of eq. (9).

Kinematics used by both plants (spec §3; eq. 5 rewritten so that it agrees with eq. 8):

    φ_1 = k_g φ_g + g_f φ_f        M1 angle from the gripper angle φ_g and the Finger's-gear angle φ_f
    φ_2 = −g_c φ_g                 eq. (7)

so that with the gripper held the Finger's gear sees g_f times M1's torque (eq. 8), and with the fingers
held M1 must turn k_g times the gripper. The paper prints three different k_g (eqs. 5/6: 1 + 1/g_ps, eq. 9:
1 + g_ps, a bevel epicyclic: 1); `gearbox.coupling` selects one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from omegaconf import DictConfig


@dataclass(frozen=True)
class Gearbox:
    g_c: float     # Upper gear / Driver's gear, eq. (1)
    g_ps: float    # Sector (cone part) / Cone gear, eq. (3)
    g_pf: float    # Finger's gear / Sector (cylindrical part), eq. (3) as read (erratum)
    g_f: float     # M1 -> Finger's gear, eq. (4)
    k_g: float     # M1 turns per gripper turn at fixed fingers (eqs. 5-6 vs 9)
    l_a: float     # distance between the motor axes, eq. (1)
    h_g: float     # height of the lower part, eq. (2)


COUPLINGS = ("eq5", "eq9", "unity")
G_PF_FORMS = ("pf_over_ps2", "ps2_over_pf")


def gearbox(geometry: DictConfig, g_pf_form: str = "pf_over_ps2", coupling: str = "eq5") -> Gearbox:
    g = geometry
    g_ps = g.D_ps1 / g.D_pc
    if g_pf_form == "pf_over_ps2":      # eq. (3) garbled; D_pf/D_ps2 is the ratio between the two gears
        g_pf = g.D_pf / g.D_ps2
    elif g_pf_form == "ps2_over_pf":
        g_pf = g.D_ps2 / g.D_pf
    else:
        raise ValueError(f"gearbox.g_pf_form={g_pf_form!r}: one of {G_PF_FORMS}")
    k_g = {"eq5": 1.0 + 1.0 / g_ps, "eq9": 1.0 + g_ps, "unity": 1.0}.get(coupling)
    if k_g is None:
        raise ValueError(f"gearbox.coupling={coupling!r}: one of {COUPLINGS}")
    return Gearbox(g_c=g.D_pu / g.D_pd, g_ps=g_ps, g_pf=g_pf, g_f=g_ps * g_pf, k_g=k_g,
                   l_a=(g.D_pd + g.D_pu) / 2, h_g=(g.D_pf + g.D_ps1 + g.D_ps2) / 2 + g.h_pc)


@dataclass(frozen=True)
class Gripper:
    """Everything one simulation needs, in SI units. Friction and feed-forward are already switched on or
    off (`with_case`)."""

    gear: Gearbox
    l_f: float
    # motors (both alike, Sect. 5)
    R: float
    L: float
    K_t: float
    K_e: float          # the plant's back-EMF constant
    K_e_printed: float  # the drive's (eq. 9 as printed uses it)
    J_1: float
    J_2: float
    U_max: float
    I_max: float
    # controller, eqs. (10)-(18)
    dt: float
    velocity_every: int
    position_every: int
    K_c1: float
    K_c2: float
    T_c1: float
    T_c2: float
    K_v: float
    K_p: float
    T: float
    omega_max: float
    epsilon_max: float
    K_eps: float        # acceleration feed-forward gain, A/(rad/s²)
    K_omega: float      # back-EMF feed-forward gain, V/(rad/s)
    lookup_offset: float
    speed_limit: float  # finger-end m/s
    speed_gain: float
    speed_integral_time: float
    # contact and friction
    k_c: float
    c_c: float
    tau_c1: float
    b_1: float
    tau_cg: float
    b_g: float

    @property
    def force_per_amp(self) -> float:
        """Static force law, eq. (8): F_f / I_M1 = K_tM1 g_f / l_f."""
        return self.K_t * self.gear.g_f / self.l_f

    def lookup(self, force: float) -> float:
        """L(F_set): the M1 current for a grasp force, the inverse of eq. (8) plus the configured offset."""
        return force / self.force_per_amp + self.lookup_offset

    @property
    def J_g(self) -> float:
        """M2's inertia seen at the gripper axis, J_M2 g_c²."""
        return self.J_2 * self.gear.g_c ** 2

    def with_case(self, *, friction: bool, feedforward: bool) -> Gripper:
        """Fig. 8's cases: friction on or off, feed-forward on or off (K_ε = K_ω = 0)."""
        p = self
        if not friction:
            p = replace(p, tau_c1=0.0, b_1=0.0, tau_cg=0.0, b_g=0.0)
        if not feedforward:
            p = replace(p, K_eps=0.0, K_omega=0.0)
        return p


FEEDFORWARD_FORMS = ("model", "printed")
BACK_EMF_FORMS = ("printed", "torque_constant")


def feedforward_gains(gear: Gearbox, J_1: float, K_t: float, K_e: float, K_e_printed: float,
                      form: str) -> tuple[float, float]:
    """(K_ε, K_ω) of eq. (9).

    model:   K_ε = k_g J_M1 / K_tM1, K_ω = k_g K_e: the current that accelerates M1 at k_g ε_g and the voltage
             that cancels its back-EMF at k_g ω_g (eqs. 5-6 with ω_f = ε_f = 0), for the plant's k_g.
    printed: K_ε = (1 + g_ps) J_M1 / K_eM1, K_ω = (1 + g_ps) K_eM1 as eq. (9) prints them (J/K_e is not even
             in A/(rad/s²); erratum)."""
    if form == "model":
        return gear.k_g * J_1 / K_t, gear.k_g * K_e
    if form == "printed":
        return (1 + gear.g_ps) * J_1 / K_e_printed, (1 + gear.g_ps) * K_e_printed
    raise ValueError(f"controller.feedforward={form!r}: one of {FEEDFORWARD_FORMS}")


def gripper(system: DictConfig) -> Gripper:
    """The gripper of a resolved `system` config (conf/system/gripper-force-control.yaml)."""
    gb, mo, co, ct, fr = system.gearbox, system.motors, system.controller, system.contact, system.friction
    gear = gearbox(system.geometry, gb.g_pf_form, gb.coupling)
    if mo.back_emf not in BACK_EMF_FORMS:
        raise ValueError(f"motors.back_emf={mo.back_emf!r}: one of {BACK_EMF_FORMS}")
    K_e = mo.K_e if mo.back_emf == "printed" else mo.K_t
    K_eps, K_omega = feedforward_gains(gear, mo.J_M1, mo.K_t, K_e, mo.K_e, co.feedforward)
    return Gripper(
        gear=gear, l_f=system.geometry.l_f, R=mo.R, L=mo.L, K_t=mo.K_t, K_e=K_e, K_e_printed=mo.K_e,
        J_1=mo.J_M1, J_2=mo.J_M2, U_max=mo.voltage_limit, I_max=mo.current_limit,
        dt=co.dt, velocity_every=_ticks(co.velocity_dt, co.dt, "velocity_dt"),
        position_every=_ticks(co.position_dt, co.dt, "position_dt"),
        K_c1=co.K_c1, K_c2=co.K_c2, T_c1=co.T_c1, T_c2=co.T_c2, K_v=co.K_v, K_p=co.K_p, T=co.T,
        omega_max=co.omega_max, epsilon_max=co.epsilon_max, K_eps=K_eps, K_omega=K_omega,
        lookup_offset=co.lookup_offset, speed_limit=co.speed_limit, speed_gain=co.speed_gain,
        speed_integral_time=co.speed_integral_time, k_c=ct.stiffness, c_c=ct.damping,
        tau_c1=fr.m1_coulomb, b_1=fr.m1_viscous, tau_cg=fr.rotation_coulomb, b_g=fr.rotation_viscous)


def _ticks(period: float, dt: float, name: str) -> int:
    """A slower loop's period as a whole number of current-loop ticks."""
    n = round(period / dt)
    if n < 1 or not math.isclose(n * dt, period, rel_tol=1e-9):
        raise ValueError(f"controller.{name}={period:g} must be a multiple of controller.dt={dt:g}")
    return n
