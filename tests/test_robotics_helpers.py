"""Shared kinematics helpers against their plain definitions: DH frames against the product of the 4×4 link
transforms, row interpolation against np.interp column by column."""

from __future__ import annotations

import numpy as np
import pytest

from pipeline.robotics import dh as dhk
from pipeline.robotics.profiles import interpolate

RNG = np.random.default_rng(11)
TABLE = dhk.DH(alpha=np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.3, -1.1]),
               a=np.array([0.0, -0.425, -0.392, 0.0, 0.05, 0.0, 0.1]),
               d=np.array([0.089, 0.0, 0.0, 0.109, 0.095, 0.082, -0.02]),
               theta_offset=np.array([0.0, 0.2, 0.0, -0.4, 0.0, 0.0, 1.0]))


@pytest.mark.parametrize("batch", [(), (1,), (2001,), (3, 5), (0,)])
def test_dh_frames_are_the_product_of_the_link_transforms(batch):
    q = RNG.uniform(-np.pi, np.pi, (*batch, TABLE.n))
    frames = dhk.frames(TABLE, q)
    links = dhk.link_transforms(TABLE, q)
    expected = np.broadcast_to(np.eye(4), (*batch, 4, 4))
    assert frames.shape == (*batch, TABLE.n + 1, 4, 4)
    assert np.array_equal(frames[..., 0, :, :], expected)
    for i in range(TABLE.n):
        expected = expected @ links[..., i, :, :]
        assert np.abs(frames[..., i + 1, :, :] - expected).max(initial=0.0) < 1e-14  # rounding of 7 products


def test_interpolated_rows_are_np_interp_of_every_column():
    times = np.cumsum(RNG.uniform(0.001, 0.01, 300))
    values = RNG.normal(size=(300, 4, 4))
    t = np.concatenate([[times[0] - 1.0], RNG.uniform(times[0], times[-1], 500), times, [times[-1] + 1.0]])
    expected = np.stack([np.interp(t, times, values[:, i, j]) for i in range(4) for j in range(4)], axis=1)
    assert np.abs(interpolate(t, times, values).reshape(-1, 16) - expected).max() < 1e-14
    assert np.array_equal(interpolate(times, times, values), values)  # the samples themselves, exactly
    assert np.array_equal(interpolate(t[:3], times[:1], values[:1]), np.repeat(values[:1], 3, axis=0))
