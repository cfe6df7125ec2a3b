"""cobot-6r-ik: the spec's independent checks (§8), the SymPy oracle against the compiled assembly of Λ,
round trips, the multi-start reference, the paper's own back-substitution path, bad input."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pipeline.papers.cobot_6r_ik import (
    CRX10IAL,
    Geometry,
    cayley,
    cayley_params,
    fk,
    ik_all,
    ik_batch,
    ik_diagnose,
    twin,
    wrap,
)
from pipeline.papers.cobot_6r_ik import resultant as rs
from pipeline.papers.cobot_6r_ik.kinematics import JOINT_LIMITS
from pipeline.papers.cobot_6r_ik.reference import multistart
from pipeline.robotics import dh as dhk

RNG = np.random.default_rng(11)
EXAMPLE = dataclasses.replace(CRX10IAL, d1=0.245)
Q31 = np.deg2rad([78, 131, 24, 42, -60, -10])   # eq. (31)


def random_q(n: int) -> np.ndarray:
    return RNG.uniform(-JOINT_LIMITS, JOINT_LIMITS, (n, 6))


# -- §8.1-8.3: Cayley map, FK against MuJoCo, twins ----------------------------------------------------


def test_cayley_is_a_rotation_and_inverts():
    c = RNG.normal(scale=2.0, size=(200, 3))
    R = cayley(c)
    assert np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max() < 1e-12
    assert np.abs(np.linalg.det(R) - 1).max() < 1e-12
    assert np.abs(cayley_params(R) - c).max() < 1e-9
    for ci, Ri in zip(c[:20], R[:20], strict=True):   # eq. (6) is (I + C)(I − C)^-1, eq. (5)
        C = np.array([[0, -ci[2], ci[1]], [ci[2], 0, -ci[0]], [-ci[1], ci[0], 0]])
        assert np.allclose((np.eye(3) + C) @ np.linalg.inv(np.eye(3) - C), Ri, atol=1e-12)


def test_fk_equals_dh_product_and_mujoco():
    mujoco = pytest.importorskip("mujoco")
    from pipeline.robotics.mjcf import ArmDynamics, serial_arm

    q = random_q(30)
    dh = dhk.DH.from_config(CRX10IAL.dh)
    assert np.abs(fk(q) - dhk.fk(dh, q)).max() < 1e-14
    dyn = ArmDynamics(masses=[1.0] * 6, link_radius=0.05, armature=[0.1] * 6, damping=[0.0] * 6,
                      torque_limit=[100.0] * 6)
    model = mujoco.MjModel.from_xml_string(serial_arm("crx", dh, dyn, timestep=1e-3, kp=[1.0] * 6, kv=[1.0] * 6,
                                                      radii=[0.09, 0.07, 0.07, 0.06, 0.05, 0.04], dh_segments=True))
    data = mujoco.MjData(model)
    site = model.site("flange").id
    for qi in q:
        data.qpos[:] = qi
        mujoco.mj_kinematics(model, data)
        T = fk(qi)
        assert np.allclose(data.site_xpos[site], T[:3, 3], atol=1e-12)
        assert np.allclose(data.site_xmat[site].reshape(3, 3), T[:3, :3], atol=1e-12)


def test_twin_reaches_the_same_pose_with_the_same_frame_4():
    q = random_q(500)
    assert np.abs(fk(twin(q)) - fk(q)).max() < 1e-12
    dh = dhk.DH.from_config(CRX10IAL.dh)
    assert np.abs(dhk.frames(dh, twin(q))[:, 4] - dhk.frames(dh, q)[:, 4]).max() < 1e-12


# -- §8.4-8.5: round trips, completeness on the example --------------------------------------------------


def test_round_trip_random_poses():
    q = random_q(300)
    T = fk(q)
    sols, counts = ik_batch(T)
    found = 0
    for k in range(len(q)):
        s = sols[k, :counts[k]]
        assert counts[k] % 2 == 0 and counts[k] <= 16            # twins; Bézout bound of three quadrics
        if counts[k]:
            assert np.abs(fk(s) - T[k]).max() < 1e-9             # every returned solution reaches the pose
            found += np.abs(wrap(s - q[k])).max(axis=1).min() < 1e-6
    assert found / len(q) >= 0.98   # the rest: Λ's near-double roots in double precision (completeness experiment)


def test_batched_equals_scalar():
    T = fk(random_q(50))
    sols, counts = ik_batch(T)
    for k in range(len(T)):
        assert np.array_equal(sols[k, :counts[k]], ik_all(T[k]))


def test_example_has_eight_solutions_and_multistart_least_squares_agrees():
    T = fk(Q31, EXAMPLE)
    ours = ik_all(T, EXAMPLE)
    ref = multistart(T, 2000, np.random.default_rng(0), EXAMPLE)
    assert len(ours) == 8 and len(ref) == 8
    same = np.abs(wrap(ours[:, None] - ref[None])).max(axis=2) < 1e-6
    assert same.any(axis=0).all() and same.any(axis=1).all()
    assert np.abs(wrap(ours - Q31)).max(axis=1).min() < 1e-9


def test_example_roots_genuine_and_extraneous():
    d = ik_diagnose(fk(Q31, EXAMPLE), EXAMPLE)
    assert len(d.roots) == 16
    real = d.roots[np.abs(d.roots.imag) < 1e-9].real
    assert len(real) == 8
    genuine = d.records[d.records[:, 11] >= 1, 0]
    extraneous = d.records[d.records[:, 11] == 0, 0]
    assert np.allclose(np.sort(genuine), [-9.67318, -7.72938, -7.60272, -0.47957], atol=1e-4)
    assert np.allclose(np.sort(extraneous), [-13.10480, -6.13457, -3.73768, -3.22919], atol=1e-4)
    assert d.records[d.records[:, 11] == 0, 7].min() > 1e-3   # extraneous candidates miss the pose by > 1 mm


# -- §8.6: SymPy oracle on rational inputs ------------------------------------------------------------------


def _symbolic(T: np.ndarray, g: Geometry, a2_in_phi6: str = "a2", d1_sign_200: int = -1):
    """Φ4, Φ5, Φ6 written from their definitions (eqs. 12-17, with eq. 18), Λ by SymPy resultants."""
    sp = pytest.importorskip("sympy")
    c1, c2, c3 = sp.symbols("c1 c2 c3")
    R = lambda x: sp.Rational(float(x)).limit_denominator(10 ** 9)   # noqa: E731
    P6 = [R(x / g.a2) for x in T[:3, 3]]
    P5 = [R((T[i, 3] - g.d6 * T[i, 2]) / g.a2) for i in range(3)]
    d1, d4, d5 = R(g.d1 / g.a2), R(g.d4 / g.a2), R(g.d5 / g.a2)
    M = sp.Matrix([[c1**2 - c2**2 - c3**2 + 1, 2*c1*c2 - 2*c3, 2*c2 + 2*c1*c3],
                   [2*c3 + 2*c1*c2, -c1**2 + c2**2 - c3**2 + 1, 2*c2*c3 - 2*c1],
                   [2*c1*c3 - 2*c2, 2*c1 + 2*c2*c3, -c1**2 - c2**2 + c3**2 + 1]])   # eq. (6) × S
    S = 1 + c1**2 + c2**2 + c3**2
    P5v, P1 = sp.Matrix(P5), sp.Matrix([0, 0, d1])
    P4S = P5v * S - d5 * M[:, 2]                                       # eq. (18) × S
    phi4 = sp.expand(sp.cancel((M[0, 1] * P4S[1] - M[1, 1] * P4S[0]) / S))          # eq. (12): det[z0, y4, P4]
    phi5 = sp.expand(sum(M[i, 2] * (P5[i] - P6[i]) for i in range(3)))            # eq. (14)
    P3S = P4S + d4 * M[:, 1]                                           # P3 = P4 + R4 (0, d4, 0)
    phi6 = sp.expand(sp.cancel(((P3S - S * P1).dot(P3S - S * P1) - S**2) / S))     # eq. (16), a2 = 1
    psi1, psi2 = sp.resultant(phi4, phi6, c3), sp.resultant(phi5, phi6, c3)
    lam = sp.Poly(sp.resultant(psi1, psi2, c2), c1)
    return sp, (c1, c2, c3), (phi4, phi5, phi6), lam


def test_sympy_oracle_matches_the_compiled_assembly_and_factors_8_plus_8():
    T = fk(Q31, EXAMPLE)
    sp, (c1, c2, c3), phis, lam = _symbolic(T, EXAMPLE)
    f, _, _, lam_fast = rs.system(T, EXAMPLE.array)
    for h, phi in enumerate(phis):   # Appendix A (corrected) = the definitions
        poly = sp.Poly(phi, c1, c2, c3)
        exact = np.array([float(poly.coeff_monomial(c1**i * c2**j * c3**k)) for i, j, k in rs.MONOMIALS])
        assert np.allclose(f[h], exact, rtol=1e-9, atol=1e-12 * np.abs(exact).max())
    exact = np.array([float(c) for c in reversed(lam.all_coeffs())])
    assert lam.degree() == 16
    scale = np.abs(exact).max()
    assert np.abs(lam_fast / np.abs(lam_fast).max() * np.sign(lam_fast[16] * exact[16]) - exact / scale).max() < 1e-9
    factors = [sp.Poly(fac, c1).degree() for fac, _ in sp.factor_list(lam.as_expr())[1]]
    assert sorted(d for d in factors if d > 0) == [8, 8]


def test_genuine_octic_vanishes_at_the_true_c1():
    T = fk(Q31, EXAMPLE)
    sp, (c1, *_), _, lam = _symbolic(T, EXAMPLE)
    c_true = cayley_params(dhk.frames(dhk.DH.from_config(EXAMPLE.dh), Q31)[4, :3, :3])
    values = []
    for fac, _ in sp.factor_list(lam.as_expr())[1]:
        p = sp.Poly(fac, c1)
        if p.degree() == 8:
            coeffs = np.array([float(c) for c in p.monic().all_coeffs()])
            values.append(abs(np.polyval(coeffs, c_true[0])) / np.abs(coeffs).max())
    assert min(values) < 1e-9 < max(values)   # the genuine factor vanishes there, the extraneous one does not


@pytest.mark.parametrize("misprint", ["d2", "d1+d5"])
def test_appendix_a_misprints_change_the_roots(misprint):
    # errata: φ6 with −d2² for −a2², and φ6,200 with (d1 + d5)
    T = fk(Q31, EXAMPLE)
    g = EXAMPLE
    P6 = T[:3, 3] / g.a2
    P5 = P6 - g.d6 / g.a2 * T[:3, 2]
    f = rs.phi(P5, P6, g.d1 / g.a2, g.d4 / g.a2, g.d5 / g.a2, 1.0)
    if misprint == "d2":
        f[2, [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]] += np.r_[1, 0, 0, 0, 1, 1, 1, 0, 0, 0] * (1.0 - (g.d2 / g.a2) ** 2)
    else:
        f[2, rs.I200] -= 4 * P5[2] * g.d5 / g.a2
    lam = rs.lam(rs.psi(f, 0, 2), rs.psi(f, 1, 2))
    roots = np.roots(lam[::-1])
    assert np.abs(roots[:, None] - np.array([-9.67318, -7.60272])[None]).min(axis=0).max() > 1e-2


def test_eq29_is_ill_conditioned_where_c2_is_large():
    # Table 2 prints c2 = −18.981 for c1 = −7.730; the common root of Ω1, Ω2 is −19.020 (SymPy agrees), and
    # eq. (29)'s 6×6 solve moves by ~0.15 per 1e-9 of c1 there
    from pipeline.papers.cobot_6r_ik.experiments import _c2_eq29
    from pipeline.papers.cobot_6r_ik.ik import _common_c2

    T = fk(Q31, EXAMPLE)
    _, psi1, psi2, _ = rs.system(T, EXAMPLE.array)
    c1 = ik_diagnose(T, EXAMPLE).records[:, 0]
    c1 = c1[np.argmin(np.abs(c1 + 7.7294))]
    assert _common_c2(psi1, psi2, c1) == pytest.approx(-19.0201, abs=1e-4)
    moved = [_c2_eq29(rs.omegas(psi1, x), rs.omegas(psi2, x)) for x in (c1 - 1e-9, c1 + 1e-9)]
    assert abs(moved[1] - moved[0]) > 0.1


# -- peers and bad input ---------------------------------------------------------------------------------------


def test_crx_kinematics_convention_by_fk_matching():
    pytest.importorskip("crx_kinematics")
    from pipeline.papers.cobot_6r_ik import peers

    crx = peers.crx_kinematics()
    for T in fk(random_q(40)):
        theirs = crx.solve(T)
        assert len(theirs) and np.abs(fk(theirs) - T).max() < 1e-9


@pytest.mark.parametrize("T", [np.eye(3), np.full((4, 4), np.nan), np.zeros((2, 4, 4))])
def test_bad_pose_is_refused(T):
    with pytest.raises(ValueError, match="4×4"):
        ik_all(T)


def test_bad_geometry_and_joints_are_refused():
    with pytest.raises(ValueError, match="d2 = d3"):
        Geometry(d1=0.25, a2=0.71, d2=0.26, d3=0.20, d4=0.54, d5=0.15, d6=0.16)
    with pytest.raises(ValueError, match="shape"):
        fk(np.zeros(5))
    with pytest.raises(ValueError, match="shape"):
        ik_batch(np.eye(4))


def test_unreachable_pose_has_no_solution():
    T = np.eye(4)
    T[:3, 3] = [3.0, 0.0, 0.5]   # 3 m away: beyond the arm's reach
    assert ik_all(T).shape == (0, 6)


def test_genuine_octic_is_the_genuine_factor_of_lambda():
    # ours: resultant.genuine gives exactly the roots of Λ's genuine octic (SymPy factorisation)
    T = fk(Q31, EXAMPLE)
    sp, (c1, *_), _, lam = _symbolic(T, EXAMPLE)
    f = rs.system(T, EXAMPLE.array)[0]
    ours = np.sort_complex(np.roots(rs.genuine(f)[::-1]))
    factors = [sp.Poly(fac, c1).monic() for fac, _ in sp.factor_list(lam.as_expr())[1]
               if sp.Poly(fac, c1).degree() == 8]
    exact = [np.sort_complex(np.roots([float(c) for c in p.all_coeffs()])) for p in factors]
    assert min(np.abs(ours - e).max() for e in exact) < 1e-9


def test_octic_finds_every_generating_configuration():
    q = random_q(300)
    sols, counts = ik_batch(fk(q), method="octic")
    for k in range(len(q)):
        s = sols[k, :counts[k]]
        assert np.abs(fk(s) - fk(q[k])).max() < 1e-9
        assert np.abs(wrap(s - q[k])).max(axis=1).min() < 1e-6
