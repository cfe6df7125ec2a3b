"""The gripper of Romanov et al.: gear geometry and eq. (8)/(9) against the paper's numbers (spec §8), power
balance of the lumped model, the static force law and the loop bandwidths through the full drive, stiction,
and the two independent plants (MuJoCo contact force, lumped pad force) against each other."""

from __future__ import annotations

import math

import numpy as np
import pytest
from omegaconf import OmegaConf

from pipeline.papers.gripper_force_control import (
    Drive,
    Start,
    gearbox,
    gripper,
    move_duration,
    schedule,
    simulate_lumped,
    static_grasp,
    trapezoid,
)
from pipeline.papers.gripper_force_control.drive import differentiate
from pipeline.papers.gripper_force_control.lumped import accelerations

from .conftest import ROOT, simulate_case

SYSTEM = OmegaConf.load(ROOT / "conf/system/gripper-force-control.yaml")
P = gripper(SYSTEM)
IDEAL = P.with_case(friction=False, feedforward=True)


def test_gear_geometry_eqs_1_to_4():
    g = gearbox(SYSTEM.geometry)
    assert g.l_a == pytest.approx(0.0405) and g.g_c == pytest.approx(2.682, abs=5e-4)
    assert g.h_g == pytest.approx(0.07065) and g.g_ps == pytest.approx(1.718, abs=5e-4)
    assert g.g_pf == pytest.approx(1.521, abs=5e-4) and g.g_f == pytest.approx(2.612, abs=5e-4)
    assert g.k_g == pytest.approx(1 + 1 / g.g_ps)
    assert gearbox(SYSTEM.geometry, coupling="eq9").k_g == pytest.approx(1 + g.g_ps)
    assert gearbox(SYSTEM.geometry, "ps2_over_pf").g_pf == pytest.approx(0.658, abs=5e-4)


def test_force_law_eq8_and_printed_gains_eq9():
    assert P.force_per_amp == pytest.approx(13.71, abs=0.01)          # N/A, spec §2
    assert 48.1 / P.force_per_amp == pytest.approx(3.51, abs=0.01)    # Table 2's peak force in A
    alt = gripper(OmegaConf.merge(SYSTEM, {"gearbox": {"g_pf_form": "ps2_over_pf"}}))
    assert alt.force_per_amp == pytest.approx(5.93, abs=0.01)
    printed = gripper(OmegaConf.merge(SYSTEM, {"controller": {"feedforward": "printed"}}))
    assert printed.K_eps == pytest.approx(7.93e-4, rel=1e-3) and printed.K_omega == pytest.approx(0.652, abs=1e-3)
    assert P.K_eps == pytest.approx(P.gear.k_g * P.J_1 / P.K_t)


def test_gears_do_no_work_power_balance():
    """Σ motor power = dT/dt + contact power + friction power, to round-off, at random states."""
    rng = np.random.default_rng(3)
    p, g = IDEAL, IDEAL.gear
    for _ in range(200):
        tau_1, tau_2, phi_g, omega_1, omega_g, fr_1, fr_g = rng.normal(size=7)
        phi_f = rng.uniform(-0.01, 0.02)        # with and without contact
        phi_1 = g.k_g * phi_g + g.g_f * phi_f
        a_1, a_g, F = accelerations(p, tau_1, tau_2, phi_1, omega_1, phi_g, omega_g, fr_1, fr_g)
        omega_f = (omega_1 - g.k_g * omega_g) / g.g_f
        motors = tau_1 * omega_1 + tau_2 * g.g_c * omega_g
        stored = p.J_1 * omega_1 * a_1 + p.J_g * omega_g * a_g
        assert motors == pytest.approx(stored + F * p.l_f * omega_f + fr_1 * omega_1 + fr_g * omega_g,
                                       rel=1e-12, abs=1e-12)


def test_trapezoid_times_and_limits():
    # spec §8.8
    assert move_duration(math.radians(40), 5.9, 73.3) == pytest.approx(0.199, abs=1e-3)
    assert move_duration(math.radians(40), 5.6, 73.3) == pytest.approx(0.201, abs=1e-3)
    assert move_duration(math.radians(40), 0.9, 17.5) == pytest.approx(0.827, abs=1e-3)
    assert move_duration(math.radians(45), 5.9, 73.3) == pytest.approx(0.214, abs=1e-3)
    for distance, w, e in ((0.7, 5.9, 73.3), (-0.2, 5.9, 73.3), (0.7, 0.9, 17.5)):
        t = np.linspace(0, move_duration(distance, w, e) + 0.1, 20001)
        phi, omega = trapezoid(distance, w, e, t)
        assert phi[-1] == pytest.approx(distance, abs=1e-12) and np.abs(omega).max() <= w + 1e-12
        assert np.abs(np.diff(omega) / np.diff(t)).max() <= e * (1 + 1e-9)
        assert np.allclose(np.gradient(phi, t), omega, atol=e * (t[1] - t[0]) * 2)


def test_differentiator_eqs_11_12_lags_a_ramp_by_T():
    dt, T, a = 5e-5, P.T, 73.3
    t = np.arange(4000) * dt
    eps = differentiate(a * t, T, dt)
    assert eps[-1] == pytest.approx(a, rel=1e-6)
    k = round(T / dt)
    assert eps[k] == pytest.approx(a * (1 - math.exp(-1)), rel=0.02)   # first order, time constant T


def _hold(p, duration, force, start):
    return simulate_lumped(p, schedule(p, duration, force), start, 1)


def test_static_force_law_through_the_drive():
    """Rotation held, no friction, current from the lookup: the steady force is eq. (8)'s, on both plants."""
    mujoco_plant = pytest.importorskip("pipeline.papers.gripper_force_control.mujoco_plant")
    start = Start(phi_f=-0.002 / P.l_f)       # 2 mm from the object
    for force in (3.0, 20.0):
        # (a slow mode, the gripper's position loop holding the gearbox's reaction, settles in ~0.2 s)
        trace = _hold(IDEAL, 0.6, force, start)
        assert trace["force"][-1] == pytest.approx(force, rel=2e-4)
        assert trace["I_1"][-1] * IDEAL.force_per_amp == pytest.approx(force, rel=2e-4)
        sim = mujoco_plant.MujocoGripper(IDEAL, SYSTEM.contact)
        trace, _ = sim.simulate(schedule(IDEAL, 0.6, force), start, 20)
        # the contact normal passes through the sphere's centre, so its lever about the finger's hinge is
        # l_f cos φ_f + x_hinge sin φ_f, not l_f: the MuJoCo force is smaller by ~0.6 % at 20 N
        phi = trace["phi_f"][-1]
        lever = IDEAL.l_f * math.cos(phi) + sim.layout.hinge_x * math.sin(phi)
        assert trace["force"][-1] * lever / IDEAL.l_f == pytest.approx(force, rel=1e-3)


def test_current_loop_step_response():
    """Locked rotor, 1 A step: first order with τ ≈ L/K_c ≈ 0.19 ms (spec §8.5), no steady error."""
    s = schedule(IDEAL, 0.04, 1.0 * IDEAL.force_per_amp)   # the current of a 1 A grasp
    drive = Drive(IDEAL, s)
    currents = []
    for k in range(s.ticks):
        drive.step(k, 0.0, 0.0, 0.0)
        currents.append(drive.I_1)
    currents = np.array(currents)
    tau = (np.argmax(currents >= 1 - math.exp(-1)) + 1) * IDEAL.dt
    assert 0.1e-3 < tau < 0.3e-3 and IDEAL.L / IDEAL.K_c1 == pytest.approx(0.185e-3, rel=0.01)
    assert currents[-1] == pytest.approx(1.0, abs=1e-5)


def test_position_loop_bandwidth_and_sign():
    """A 1 mrad step of the gripper set point, fingers free: eq. (14) must be negative feedback (M2's
    direction inverted) and the response about first order with 1/K_p (velocity loop ~1000 rad/s faster)."""
    p = IDEAL
    s = schedule(p, 0.05, 1e-9)
    s.phi_sr[:] = 1e-3
    trace = simulate_lumped(p, s, Start(phi_f=-0.5), 1)
    phi = trace["phi_g"]
    assert phi[-1] == pytest.approx(1e-3, rel=1e-3)
    t63 = trace.t[np.argmax(phi >= (1 - math.exp(-1)) * 1e-3)]
    assert t63 == pytest.approx(1 / p.K_p, rel=0.3)


def test_coulomb_friction_sticks_and_slides():
    """Fingers free: M1's torque below its Coulomb friction does not move it; above, it accelerates at
    (τ − τ_c)/J_M1 (lumped plant's implicit stick-slip)."""
    p = P.with_case(friction=True, feedforward=True)
    far = Start(phi_f=-0.5)
    stick_force = p.tau_c1 / p.K_t * p.force_per_amp          # F_set whose current just balances friction
    below = _hold(p, 0.02, 0.8 * stick_force, far)
    assert np.abs(below["omega_1"]).max() < 1e-12
    above = _hold(p, 0.02, 2.0 * stick_force, far)
    accel = np.gradient(above["omega_1"], above.t)[200:300].mean()
    assert accel == pytest.approx((p.K_t * above["I_1"][250] - p.tau_c1 - p.b_1 * above["omega_1"][250]) / p.J_1,
                                  rel=0.02)


def _sag_run(p, plant: str):
    s = schedule(p, 0.05 + move_duration(math.radians(40), p.omega_max, p.epsilon_max) + 0.15, 5.0,
                 [(0.05, math.radians(40))])
    start = static_grasp(p, 5.0)
    if plant == "lumped":
        return simulate_lumped(p, s, start, 20)
    mujoco_plant = pytest.importorskip("pipeline.papers.gripper_force_control.mujoco_plant")
    return mujoco_plant.MujocoGripper(p, SYSTEM.contact).simulate(s, start, 20, settle=0.03)[0]


def test_inertial_sag_without_feedforward():
    """Spec §8.4: with the current held, ε_g costs J_M1 k_g ε g_f / l_f of grasp force (0.27 N at 73.3 rad/s²)."""
    p = P.with_case(friction=False, feedforward=False)
    trace = _sag_run(p, "lumped")
    drop = p.J_1 * p.gear.k_g * p.epsilon_max * p.gear.g_f / p.l_f
    assert drop == pytest.approx(0.265, abs=0.005)
    # late in the acceleration phase (0.08 s long from t = 0.05), the resonance has decayed
    late = (trace.t > 0.10) & (trace.t < 0.128)
    assert 5.0 - trace["force"][late].mean() == pytest.approx(drop, rel=0.1)


def test_plants_agree_and_ideal_sag_below_5_percent():
    lumped, mujoco = _sag_run(IDEAL, "lumped"), _sag_run(IDEAL, "mujoco")
    assert np.abs(lumped["force"] - mujoco["force"]).max() < 0.05
    for trace in (lumped, mujoco):
        assert (5.0 - trace["force"].min()) / 5.0 < 0.05      # Fig. 8, ideal case
    with_friction = P.with_case(friction=True, feedforward=True)
    assert np.abs(_sag_run(with_friction, "lumped")["force"] - _sag_run(with_friction, "mujoco")["force"]).max() < 0.2


def test_batch_equals_single_runs():
    """The Monte-Carlo batch (arrays) and one-run (floats) paths of the drive and plant are the same model."""
    p = P.with_case(friction=True, feedforward=True)
    forces, gaps = np.array([3.0, 12.0]), np.array([0.004, 0.01])
    batch = simulate_lumped(p, schedule(p, 0.08, forces), Start(phi_f=-gaps / p.l_f), 10)
    for i in range(2):
        one = simulate_lumped(p, schedule(p, 0.08, float(forces[i])), Start(phi_f=-gaps[i] / p.l_f), 10)
        assert np.allclose(batch["force"][:, i], one["force"], rtol=1e-12, atol=1e-12)


def test_mujoco_mass_matrix_is_the_lumped_one():
    """The tendon armatures reproduce J_M1 ∇φ_1∇φ_1ᵀ + J_M2 ∇φ_2∇φ_2ᵀ in (φ_g, φ_f)."""
    mujoco = pytest.importorskip("mujoco")
    from pipeline.papers.gripper_force_control.mujoco_plant import PAD_THICKNESS, MujocoGripper

    sim = MujocoGripper(P, SYSTEM.contact)
    sim.place(static_grasp(P, 5.0))
    M = np.zeros((sim.model.nv, sim.model.nv))
    mujoco.mj_fullM(sim.model, sim.data, M)
    g = P.gear
    cross = P.J_1 * g.k_g * g.g_f
    expected = np.array([[P.J_1 * g.k_g ** 2 + P.J_g, cross], [cross, P.J_1 * g.g_f ** 2]])
    expected[1, 1] += SYSTEM.contact.pad_mass * (P.l_f ** 2 + (PAD_THICKNESS / 2) ** 2)   # MuJoCo's pad, not lumped
    assert np.allclose(M[:2, :2], expected, rtol=1e-3, atol=3e-6)   # atol: the 15 g object about the axis


def test_lumped_runs_draw_the_mujoco_gripper_in_their_state(tmp_path):
    """A lumped run draws the MuJoCo plant's gripper (the same URDF as the MuJoCo run of its case) moved by
    the lumped coordinates: the hinges at the logged φ_g and φ_f, the pad compressed by l_f·φ_f so that it
    lies on the object's surface whenever the lumped pad presses."""
    mujoco = pytest.importorskip("mujoco")
    from pipeline.core.robot import URDF_ATTACHMENT

    lumped, simulated = (simulate_case(tmp_path, "gripper-force-control/force-sag", ["scenario.forms=[]"],
                                       f"no-feedforward-{plant}") for plant in ("lumped", "mujoco"))
    assert lumped.attachments[URDF_ATTACHMENT] == simulated.attachments[URDF_ATTACHMENT]
    drawn, logged = lumped["/joint_states"], lumped["/joint_state"]
    for joint in ("gripper", "finger"):
        assert np.allclose(drawn[f"joints.{joint}.position"],
                           np.interp(drawn.index, logged.index, logged[f"position.{joint}"]), atol=1e-12)
    model = mujoco.MjModel.from_xml_string(lumped.attachments["model.xml"].decode())
    data = mujoco.MjData(model)
    force = np.interp(drawn.index, lumped["/wrench"].index, lumped["/wrench"]["force_x.grasp"])
    assert (force > 4.0).all()   # held at about F_set = 5 N throughout
    for k, t in enumerate(drawn.index):
        for joint in ("gripper", "finger", "pad"):
            data.qpos[model.joint(joint).qposadr[0]] = drawn.loc[t, f"joints.{joint}.position"]
        assert data.qpos[model.joint("pad").qposadr[0]] == pytest.approx(P.l_f * drawn.loc[t, "joints.finger.position"])
        mujoco.mj_kinematics(model, data)
        gap = mujoco.mj_geomDistance(model, data, model.geom("pad").id, model.geom("object").id, 1.0, None)
        assert abs(gap) < 1e-5, (k, gap)   # m: touching, up to the pad face's tilt with the finger
