"""The floor under Sec. V-B's targets: the closed-form kinematics of equal-sphere chains against the paper's model
in every form, what exact rolling and the literal eq. (5) can reach, and the twist the literal update leaves."""

from __future__ import annotations

import numpy as np
import pytest

from pipeline.papers.src_joint.model import CONVENTIONS, JOINT_UPDATES, Chain, ModelForm, rotation
from pipeline.papers.src_joint.reachability import MODES, fk, floors, model_state, read_quaternion, rotvecs
from pipeline.papers.src_joint.rolling import RollingChain

L = 0.034


@pytest.mark.parametrize("radius_convention", CONVENTIONS)
@pytest.mark.parametrize("free_mode_sign", CONVENTIONS)
def test_closed_form_equals_the_paper_model(radius_convention, free_mode_sign):
    r = np.random.default_rng(3).normal(size=(5, 3, 3))
    pos, rot = fk(r, L)
    for k in range(len(r)):
        chain = Chain(np.full(4, L), ModelForm(radius_convention, free_mode_sign), *model_state(r[k]))
        p, R = chain.frames()
        assert np.allclose(p, pos[k], atol=1e-15) and np.allclose(R, rot[k], atol=1e-14)
        assert np.allclose(rotation(chain.orientation()), rot[k, -1], atol=1e-14)


def test_a_straight_roll_of_the_model_is_the_closed_form_in_the_tangent_plane():
    """Exact rolling from the identity: the model's state after any straight roll is exp(±r) with r_z = 0."""
    x = np.random.default_rng(4).uniform(-1, 1, (1, 6))
    chain = Chain(np.full(4, L), ModelForm(joint_update="incremental"))
    chain.roll(x.reshape(3, 2), 1.0)
    pos, rot = fk(rotvecs(x, "incremental", 3), L)
    p, R = chain.frames()
    assert np.allclose(p, pos[0], atol=1e-15) and np.allclose(R, rot[0], atol=1e-14)


@pytest.mark.parametrize("joint_update", JOINT_UPDATES)
def test_only_the_literal_update_twists_a_joint_rolled_round_a_loop(joint_update):
    chain, plant = Chain([L, L], ModelForm(joint_update=joint_update)), RollingChain([L, L])
    for rate in np.repeat([[0.5, 0.0], [0.0, 0.5], [-0.5, 0.0], [0.0, -0.5]], 100, axis=0):
        chain.roll(rate[None], 0.01)
        plant.roll(rate[None], 0.01)
    eps_z = abs(chain.joint_quaternions()[0, 3])
    same_as_plant = np.allclose(rotation(chain.joint_quaternions())[0], plant.relative[0], atol=1e-12)
    if joint_update == "incremental":
        assert eps_z < 1e-12 and same_as_plant
    else:
        assert eps_z > 0.1 and not same_as_plant


@pytest.mark.parametrize("mode", MODES)
def test_a_pose_made_by_the_chain_has_no_floor(mode):
    """FK of a configuration the mode allows is reached to round-off; an exact-rolling pose by both modes."""
    rng = np.random.default_rng(5)
    x = rng.uniform(-1, 1, (1, 6 if mode == "incremental" else 9))
    pos, rot = fk(rotvecs(x, mode, 3), L)
    found = floors(pos[0, -1], rot[0, -1], L, 3, mode, (0.01, 1.0, 100.0), 16, 25, rng)
    assert found[-1].position_error < 1e-9 and found[-1].orientation_error < 1e-9


def test_a_twisted_pose_is_beyond_exact_rolling():
    """A pose whose joints twist about their normals: eq. (5) literal reaches it, exact rolling cannot."""
    r = np.array([[[0.3, -0.2, 0.5], [0.4, 0.1, -0.6], [-0.2, 0.5, 0.4]]])
    pos, rot = fk(r, L)
    exact = floors(pos[0, -1], rot[0, -1], L, 3, "incremental", (0.01, 1.0, 100.0), 32, 25,
                   np.random.default_rng(6))
    assert exact[-1].orientation_error < 1e-6 and exact[-1].position_error > 1e-3


def test_readings_of_a_printed_quaternion():
    q = np.array([0.8610, 0.4687, 0.1356, 0.1437])
    q = q / np.linalg.norm(q)
    assert np.allclose(read_quaternion(q, "printed"), q)
    assert np.allclose(read_quaternion(q, "scalar-last"), [q[3], q[0], q[1], q[2]])
    assert np.allclose(rotation(read_quaternion(q, "conjugate")), rotation(q).T)
    with pytest.raises(ValueError, match="reading"):
        read_quaternion(q, "bogus")
