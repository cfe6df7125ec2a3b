"""forrest-biped: the drives of Secs. 3-4 against identities, the Table 4 model, the wrench QP against an independent
solver (qpOASES through CasADi), and a walk that falls ending as a failed run."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from pipeline.papers.forrest_biped import mechanisms as mech
from pipeline.papers.forrest_biped.controller import FOOT_ROWS, WrenchQP, foot_constraints
from pipeline.papers.forrest_biped.generator import DOUBLE, LEFT
from pipeline.papers.forrest_biped.model import build, table4_links

from .conftest import ROOT

SYSTEM = yaml.safe_load((ROOT / "conf/system/forrest-biped.yaml").read_text())
KNEE = mech.Knee.from_config(SYSTEM["knee"])
ANKLE = mech.Ankle.from_config(SYSTEM["ankle"])


def test_knee_moment_arm_identities():
    theta = np.linspace(0.05, 2.0, 400)
    h = mech.knee_arm(KNEE, theta)
    B = mech.knee_points(KNEE, theta)
    cross = np.abs(KNEE.A[0] * B[:, 1] - KNEE.A[1] * B[:, 0]) / np.linalg.norm(KNEE.A - B, axis=1)
    assert np.allclose(h, cross, atol=1e-12)                                # Heron (eq. 5) = |OA × OB*| / |AB*|
    c = mech.knee_curves(KNEE, theta)
    assert np.allclose(np.abs(c["J_AB"]), h, atol=1e-8)                      # |d‖AB*‖/dq| = h
    power = c["torque"] * c["speed"]
    assert np.allclose(power, 2 * np.pi * KNEE.motor_torque * KNEE.motor_speed / 60)   # power invariance
    fine = np.linspace(0, 2.0, 200001)
    arm = mech.knee_arm(KNEE, fine)
    assert arm.max() == pytest.approx(np.linalg.norm(KNEE.B), rel=1e-9)      # h_max = ‖OB‖
    assert np.degrees(fine[arm.argmax()]) == pytest.approx(60.45, abs=0.01)


def test_ankle_rods_keep_their_length_and_the_jacobian_is_exact():
    q11, q12 = np.meshgrid(np.linspace(-0.6, 0.6, 13), np.linspace(-0.4, 0.4, 9), indexing="ij")
    A, B = mech.ankle_points(ANKLE, q11, q12)
    assert np.abs(np.linalg.norm(B - A, axis=-1) - ANKLE.rod).max() < 1e-12
    J = mech.ankle_jacobian(ANKLE, q11, q12)
    d = 1e-6
    fd = np.stack([(mech.ankle_sliders(ANKLE, q11 + d, q12) - mech.ankle_sliders(ANKLE, q11 - d, q12)) / (2 * d),
                   (mech.ankle_sliders(ANKLE, q11, q12 + d) - mech.ankle_sliders(ANKLE, q11, q12 - d)) / (2 * d)], -1)
    assert np.abs(J - fd).max() < 1e-8
    # virtual work: τᵀ q̇ = fᵀ v for τ = Jᵀ f (eq. 16) and q̇ = J⁻¹ v (eq. 15)
    rng = np.random.default_rng(0)
    f, v = rng.normal(size=2), rng.normal(size=2)
    Jz = J[6, 4]
    assert (Jz.T @ f) @ np.linalg.solve(Jz, v) == pytest.approx(f @ v, rel=1e-12)
    K = mech.ankle_curves(ANKLE, q11, q12)
    assert (K["stiffness_q11"] > 0).all() and (K["stiffness_q12"] > 0).all()


def test_spring_energy_claims():
    assert mech.spring_energy(74000.0, 1800.0) == pytest.approx(21.89, abs=0.01)
    assert mech.speed_for_energy(33.0, 30.0) == pytest.approx(1.483, abs=1e-3)


def test_table4_composes_to_the_legs_of_the_paper():
    links = table4_links(SYSTEM["table4"])
    for first in (7, 13):
        axes = [links[first + k].axis for k in range(6)]
        assert np.allclose(axes, [[0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0], [-1, 0, 0]], atol=1e-12)
    assert sum(link.mass for link in links.values()) == pytest.approx(32.51)
    assert links[7].origin[1] == pytest.approx(0.12) and links[13].origin[1] == pytest.approx(-0.12)
    origin = table4_links(SYSTEM["table4"], inertia_about="origin")
    for i in range(7, 19):
        assert (np.linalg.eigvalsh(origin[i].inertia) > -1e-12).all()


def test_mujoco_model_matches_table4():
    import mujoco

    biped = build(SYSTEM)
    model = mujoco.MjModel.from_xml_string(biped.xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert model.nv == 18 and model.nu == 12
    assert model.body_mass.sum() == pytest.approx(32.51)
    # straight legs: the CoM from Table 4 by hand (link origins + rotated r), against MuJoCo's
    links = biped.links
    com = (sum(link.mass * (link.origin + link.com) for link in links.values()) / biped.mass
           + np.array([0, 0, biped.hip_height]))
    assert np.allclose(data.subtree_com[1], com, atol=1e-12)
    assert com[2] == pytest.approx(0.7736, abs=1e-4)


def _qp() -> WrenchQP:
    c = SYSTEM["controller"]
    return WrenchQP(SYSTEM["model"]["friction"], c["min_normal_force"], 0.1, 0.05, np.asarray(c["weights"]),
                    c["regularization"])


def _map(com: np.ndarray) -> np.ndarray:
    G = np.zeros((6, 12))
    for f, y in enumerate((0.12, -0.12)):
        r = np.array([0.0, y, 0.0]) - com
        G[0:3, 6 * f:6 * f + 3] = np.eye(3)
        G[3:6, 6 * f + 3:6 * f + 6] = np.eye(3)
        G[3:6, 6 * f:6 * f + 3] = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    return G


def test_wrench_qp_meets_a_feasible_demand_and_agrees_with_qpoases():
    import casadi as ca

    qp = _qp()
    rng = np.random.default_rng(3)
    A1, b1 = foot_constraints(SYSTEM["model"]["friction"], SYSTEM["controller"]["min_normal_force"], 0.1, 0.05)
    for state in (DOUBLE, LEFT):
        com = np.array([0.0, 0.05 if state == LEFT else 0.0, 0.72])
        G = _map(com)
        F_d = np.r_[rng.normal(0, 5, 2), 318.9, rng.normal(0, 2, 3)]
        w, flag = qp.solve(G, F_d, state)
        assert flag == 1
        assert np.abs(G @ w - F_d).max() < 1e-3 * np.abs(F_d).max()           # F_opt = F_d when feasible
        for f in ((0, 1) if state == DOUBLE else (0,)):
            assert (A1 @ w[6 * f:6 * f + 6] <= b1 + 1e-9).all()                # f_min, friction, CoP inside
        if state == LEFT:
            assert np.abs(w[6:]).max() < 1e-12                                   # the swing foot carries nothing
        # the same problem by qpOASES
        H = G.T * qp.W @ G + qp.eps * np.eye(12)
        lbx, ubx = qp.lower[state][:12], qp.upper[state][:12]
        uba = qp.upper[state][12:]
        solver = ca.conic("s", "qpoases", {"h": ca.Sparsity.dense(12, 12), "a": ca.Sparsity.dense(2 * FOOT_ROWS, 12)},
                          {"printLevel": "none"})
        ref = solver(h=H, g=-(G.T * qp.W) @ F_d, a=qp.A, lba=-np.inf, uba=np.minimum(uba, 1e20),
                     lbx=np.maximum(lbx, -1e20), ubx=np.minimum(ubx, 1e20))
        assert np.abs(np.asarray(ref["x"]).ravel() - w).max() < 1e-5


def test_infeasible_demand_respects_the_constraints():
    qp = _qp()
    G = _map(np.array([0.0, 0.0, 0.72]))
    F_d = np.array([400.0, 0.0, 318.9, 0.0, 0.0, 0.0])                        # more push than friction allows
    w, flag = qp.solve(G, F_d, DOUBLE)
    assert flag == 1
    fz = w[[2, 8]]
    assert (np.abs(w[[0, 6]]) <= SYSTEM["model"]["friction"] / np.sqrt(2) * fz + 1e-9).all()
    assert (G @ w)[0] < 400.0


def test_a_walk_that_falls_is_a_failed_run_with_its_reason():
    from omegaconf import OmegaConf

    from pipeline.core.runlog import SimulationFailed
    from pipeline.papers.forrest_biped import experiments as ex

    cfg = OmegaConf.create({"system": SYSTEM, "scenario": {"tf_rate_hz": 10.0}})
    cfg.system.model.torque_limit = [1.0] * 6                                 # no strength: it collapses
    cfg.system.walk.duration = 1.0

    class Sink:
        def __getattr__(self, name):
            return lambda *a, **k: None

    with pytest.raises(SimulationFailed, match="fell at t = "):
        ex._walk_case(cfg, "extended")(Sink())


def test_inverse_dynamics_terms_match_mujocos_inverse():
    """Eq. (58)'s M q̈ + h (the controller's mj_fullM + qfrc_bias) equals MuJoCo's own inverse dynamics."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(build(SYSTEM, plant=False).xml)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(7)
    data.qpos[7:] = rng.uniform(-0.4, 0.4, 12)
    data.qvel[:] = rng.normal(0, 0.5, 18)
    data.qacc[:] = rng.normal(0, 2.0, 18)
    mujoco.mj_fwdPosition(model, data)
    mujoco.mj_fwdVelocity(model, data)
    M = np.zeros((18, 18))
    mujoco.mj_fullM(model, data, M)
    ours = M @ data.qacc + data.qfrc_bias
    mujoco.mj_inverse(model, data)
    assert np.allclose(ours, data.qfrc_inverse, atol=1e-9)


def test_markers_draw_every_body_with_its_geoms():
    import mujoco

    from pipeline.core.markers import mujoco_geoms

    biped = build(SYSTEM)
    model = mujoco.MjModel.from_xml_string(biped.xml)
    entities = {e.frame_id: e for e in mujoco_geoms(model, biped.body_names)}
    assert set(entities) == set(biped.body_names)
    thigh = entities["l_link9"]                                  # one capsule: a cylinder and two end spheres
    assert len(thigh.cylinders) == 1 and len(thigh.spheres) == 2
    assert thigh.cylinders[0].size.z == pytest.approx(0.405)
    foot = entities["r_link18"]                                  # plate (a box: a cube), four corner spheres
    corners = [s for s in foot.spheres if s.size.x == pytest.approx(2 * SYSTEM["model"]["corner_radius"])]
    assert len(foot.cubes) == 1 and len(corners) == 4
