"""The rolling chain drawn by revolute joints: the URDF generated from `revolute.chain_xml` and moved by
`hinge_angles` puts every sphere where the exact rolling plant and the paper's forward kinematics (eqs. 17, 26)
put it, at random configurations, for equal spheres (four hinges a joint) and unequal ones on any rolling path
(five); its joints are the hinges the runs publish, continuous over a trajectory."""

from __future__ import annotations

import io

import mujoco
import numpy as np
import pytest
import yourdfpy

from pipeline.papers.src_joint import Chain, RollingChain
from pipeline.papers.src_joint.revolute import chain_xml, hinge_angles, hinge_names
from pipeline.papers.src_joint.rolling import exp_so3, trolley_rates
from pipeline.robotics.urdf import describe

RADIUS = 0.034   # m, Table II


def urdf_of(radii) -> tuple[yourdfpy.URDF, object]:
    description = describe(mujoco.MjModel.from_xml_string(chain_xml(radii)))
    return yourdfpy.URDF.load(io.StringIO(description.urdf()), load_meshes=False,
                              load_collision_meshes=False), description


def urdf_frames(urdf: yourdfpy.URDF, description, qpos: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    urdf.update_cfg(dict(zip(description.joint_names, description.joint_positions(qpos)[0], strict=True)))
    T = np.stack([urdf.get_transform(f"{description.name}/B{i}", "world") for i in range(n + 1)])
    return T[:, :3, 3], T[:, :3, :3]


def driven(radii, seed: int, steps: int = 60) -> RollingChain:
    """The plant after trolleys drove it at random speeds while steering at random rates (heading changes)."""
    rng = np.random.default_rng(seed)
    plant = RollingChain(radii)
    n = plant.n
    heading = rng.uniform(-np.pi, np.pi, n)
    for _ in range(steps):
        steer = rng.uniform(-2.0, 2.0, n)
        plant.roll(trolley_rates(rng.uniform(-0.1, 0.1, n), heading, radii[1]), 0.05, steer)
        heading = heading + steer * 0.05
    return plant


def assert_drawn_where_plant_and_model_put_it(urdf, description, qpos, plant, radii) -> None:
    """The URDF at the hinge angles puts every sphere where the exact plant and the paper's model (eqs. 17, 26)
    put it, positions and rotations within 1e-12."""
    pos, rot = urdf_frames(urdf, description, qpos, len(radii) - 1)
    plant_pos, plant_rot = plant.frames()
    model_pos, model_rot = Chain(radii, q1=plant.model_state()[0], q2=plant.model_state()[1]).frames()
    assert np.abs(pos - plant_pos).max() < 1e-12 and np.abs(rot - plant_rot).max() < 1e-12
    assert np.abs(pos - model_pos).max() < 1e-12 and np.abs(rot - model_rot).max() < 1e-12


@pytest.mark.parametrize("n", [3, 4])
def test_urdf_fk_equals_rolling_and_the_papers_fk(n):
    radii = np.full(n + 1, RADIUS)
    urdf, description = urdf_of(radii)
    assert urdf.actuated_joint_names == hinge_names(radii) == description.joint_names
    assert len(description.joint_names) == 4 * n
    for seed in range(6):
        plant = driven(radii, seed)
        qpos = hinge_angles(plant.tangent, plant.relative, radii)
        assert_drawn_where_plant_and_model_put_it(urdf, description, qpos, plant, radii)
        assert np.abs(plant.frames()[0][1:] - plant.frames()[0][:1]).max() > 0.05   # moved away from straight up
        # equal spheres: the roll is halved between the two sides and the azimuths cancel
        azimuth, lower, upper, back = qpos.reshape(n, 4).T
        assert np.allclose(lower, upper, atol=1e-15) and np.allclose(back, -azimuth, atol=1e-15)


def test_unequal_spheres_share_the_roll_in_the_radius_ratio():
    """A straight roll of B_1 (l_1 = 40 mm) on B_0 (l_0 = 20 mm): the contact normal turns l_1/(l_0 + l_1) of
    B_1's turn, so the lower roll is l_1/l_0 times the upper, and B_1 does not lean; FK still equals the plant's
    and the model's."""
    radii = np.array([0.02, 0.04])
    plant = RollingChain(radii)
    plant.roll(np.array([[0.3, -0.5]]), 1.0)
    qpos = hinge_angles(plant.tangent, plant.relative, radii)
    azimuth, lower, upper, lean, back = qpos
    assert lower == pytest.approx(2.0 * upper, rel=1e-12) and upper > 0.1
    assert abs(lean) < 1e-15 and back == pytest.approx(-azimuth, abs=1e-12)
    urdf, description = urdf_of(radii)
    assert_drawn_where_plant_and_model_put_it(urdf, description, qpos[None], plant, radii)


@pytest.mark.parametrize("radii", [[0.04, 0.03], [0.02, 0.04], [0.04, 0.03, 0.034, 0.05]],
                             ids=["joint-model", "small-on-large", "mixed-chain"])
def test_unequal_spheres_on_any_rolling_path(radii):
    """Unequal spheres driven round random curves (the trolleys steer) end leaning and twisted, off the four-hinge
    form: the five hinges draw them exactly, at every random state, as the plant and the paper's model put them."""
    radii = np.asarray(radii)
    urdf, description = urdf_of(radii)
    assert urdf.actuated_joint_names == hinge_names(radii) == description.joint_names
    leans = []
    for seed in range(6):
        plant = driven(radii, seed)
        qpos = hinge_angles(plant.tangent, plant.relative, radii)
        assert_drawn_where_plant_and_model_put_it(urdf, description, qpos, plant, radii)
        leans.append(np.abs(qpos[[k for k, name in enumerate(hinge_names(radii)) if "lean" in name]]).max())
    assert max(leans) > 0.01   # the states are off the four-hinge form: a lean is needed to draw them


def test_a_state_four_hinges_cannot_draw_is_refused():
    """Unequal spheres rolled round a loop end twisted about their contact normal and are drawn by five hinges;
    equal spheres never twist by rolling, and a twisted state of theirs is refused, not drawn wrong."""
    radii = np.array([0.02, 0.04])
    plant = RollingChain(radii)
    for rates in ([0.5, 0.0], [0.0, 0.5], [-0.5, 0.0], [0.0, -0.5]):
        plant.roll(np.array([rates]), 1.0)
    qpos = hinge_angles(plant.tangent, plant.relative, radii)
    assert abs(qpos[3]) > 0.01
    urdf, description = urdf_of(radii)
    pos, rot = urdf_frames(urdf, description, qpos[None], 1)
    assert np.abs(pos - plant.frames()[0]).max() < 1e-12 and np.abs(rot - plant.frames()[1]).max() < 1e-12
    equal = np.full(2, 0.034)
    tangent = exp_so3(np.array([[0.3, 0.2, 0.0]]))
    twisted = exp_so3(tangent[:, :, 2] * 0.2) @ exp_so3(np.array([[0.6, 0.4, 0.0]]))   # turned about the normal
    with pytest.raises(ValueError, match="four hinges"):
        hinge_angles(tangent, twisted, equal)


def test_the_aligned_start_is_all_zeros():
    radii = np.full(4, RADIUS)
    plant = RollingChain(radii)
    assert np.array_equal(hinge_angles(plant.tangent, plant.relative, radii), np.zeros(12))
    assert np.array_equal(hinge_angles(plant.tangent[:1], plant.relative[:1], [0.04, 0.03]), np.zeros(5))


def test_a_trajectory_keeps_its_azimuths_continuous():
    """Over time the azimuths are unwrapped: the same poses as sample by sample (up to 2π), without 2π steps.
    The states: equal spheres rolled 0.4 rad about an axis that turns twice round the normal (reachable by
    rolling: the constraint is integrable, reachability.py)."""
    radii = np.full(2, RADIUS)
    turn = np.linspace(0.0, 4 * np.pi, 400)
    r = 0.4 * np.stack([np.cos(turn), np.sin(turn), np.zeros_like(turn)], axis=-1)[:, None]
    tangent, relative = exp_so3(r), exp_so3(2 * r)
    qpos = hinge_angles(tangent, relative, radii)
    each = np.stack([hinge_angles(T, R, radii) for T, R in zip(tangent, relative, strict=True)])
    assert qpos.shape == (400, 4) and np.allclose(np.angle(np.exp(1j * (qpos - each))), 0.0, atol=1e-12)
    assert np.allclose(qpos[:, 0] - qpos[0, 0], turn, atol=1e-12)   # the azimuth follows the axis round twice


def test_a_trajectory_through_the_pole_stays_continuous():
    """Unequal spheres rolled straight across the aligned state and back out the other side: where the contact
    normal passes through B_0's pole, the azimuth holds and the tilt changes sign, so no hinge steps; at the
    first sample, exactly at the pole, the azimuth is already the one the roll takes. FK is exact throughout."""
    radii = np.array([0.04, 0.03])
    plant = RollingChain(radii)
    plant.roll(np.array([[0.6, -0.8]]), -1.0)   # start on one side of the pole
    tangent, relative = [], []
    for _ in range(101):
        tangent.append(plant.tangent.copy())
        relative.append(plant.relative.copy())
        plant.roll(np.array([[0.6, -0.8]]), 0.02)
    tangent, relative = np.stack(tangent), np.stack(relative)
    qpos = hinge_angles(tangent, relative, radii)
    assert np.abs(np.diff(qpos, axis=0)).max() < 0.05          # 0.02 s steps of a 1.75 rad/s roll: no jumps
    assert np.ptp(qpos[:, 0]) < 1e-12 and qpos[0, 1] * qpos[-1, 1] < 0   # one azimuth; the tilt crosses 0
    urdf, description = urdf_of(radii)
    for k in (0, 50, 100):
        pos, rot = urdf_frames(urdf, description, qpos[k], 1)
        frames = RollingChain(radii)
        frames.tangent, frames.relative = tangent[k], relative[k]
        plant_pos, plant_rot = frames.frames()
        assert np.abs(pos - plant_pos).max() < 1e-12 and np.abs(rot - plant_rot).max() < 1e-12
    from_pole = hinge_angles(tangent[50:], relative[50:], radii)   # sample 50 is the aligned state
    assert np.abs(np.diff(from_pole, axis=0)).max() < 0.05 and from_pole[0, 0] == from_pole[1, 0]
