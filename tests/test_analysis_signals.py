"""The shared chattering measures (analysis/core/signals.py) on signals whose values are known in closed form."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.core.signals import (
    chattering_stats,
    high_frequency_rms,
    low_pass,
    sign_change_rate,
    total_variation_rate,
)

RATE = 1000.0
T = np.arange(0, 10.0 + 0.5 / RATE, 1 / RATE)    # 10 s at 1 kHz, both ends included


def test_total_variation_rate_of_a_sine_and_of_switching():
    A, f = 3.0, 0.5                                 # 5 whole periods: each travels 4A
    assert total_variation_rate(T, A * np.sin(2 * np.pi * f * T)) == pytest.approx(4 * A * f, rel=1e-4)
    delta = 0.2                                     # ±δ every sample: 2δ per sample
    switching = 5.0 + delta * (-1.0) ** np.arange(len(T))
    assert total_variation_rate(T, switching) == pytest.approx(2 * delta * RATE, rel=1e-12)
    assert total_variation_rate(T, np.full_like(T, 7.0)) == 0.0


def test_high_frequency_rms_keeps_only_what_lies_above_the_cutoff():
    slow = 20.0 * np.sin(2 * np.pi * 0.5 * T)       # the exercise: large, 0.5 Hz
    fast = 0.3 * np.sin(2 * np.pi * 200 * T)        # chattering: small, 200 Hz
    assert high_frequency_rms(T, slow) < 1e-6 * 20.0
    assert high_frequency_rms(T, slow + fast) == pytest.approx(0.3 / np.sqrt(2), rel=1e-3)
    assert high_frequency_rms(T, slow + fast + 100.0) == pytest.approx(0.3 / np.sqrt(2), rel=1e-3)   # offset
    assert np.abs(low_pass(T, slow + fast) - slow)[500:-500].max() < 1e-3 * 20.0


def test_sign_changes_and_the_metric_dictionary():
    assert sign_change_rate(T, np.sin(2 * np.pi * 3.0 * T + 0.1)) == pytest.approx(6.0, rel=1e-2)
    assert sign_change_rate(T, np.zeros_like(T)) == 0.0
    stats = chattering_stats(T, 0.2 * (-1.0) ** np.arange(len(T)), "tau.joint1", "Nm")
    assert set(stats) == {"tau.joint1.tv", "tau.joint1.hf_rms"}
    assert stats["tau.joint1.tv"] == (pytest.approx(400.0), "Nm/s")
    assert stats["tau.joint1.hf_rms"][0] == pytest.approx(0.2, rel=1e-3)   # a Nyquist-rate square wave: all fast


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="Nyquist"):
        high_frequency_rms(T, np.sin(T), cutoff_hz=600.0)
    with pytest.raises(ValueError, match="two samples"):
        total_variation_rate(np.array([0.0]), np.array([1.0]))
