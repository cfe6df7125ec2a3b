"""nmpc-cdkd Table 3 statistics: the pooled t̄ and σ are the plain ones, the paired bootstrap keeps what the
cells share, its intervals cover a known ratio, and the claims follow the intervals."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from analysis.papers.nmpc_cdkd.table3 import Cells, per_seed, table3

CELLS = [(model, case, k) for model in ("decomposed", "full") for case in ("no-obstacle", "obstacle-height")
         for k in (10, 20)]


def _solves(seconds_of, moves: int = 60, seeds: int = 2, seed: int = 0) -> pd.DataFrame:
    """One timed solve per move and cell; `seconds_of(cell, move_difficulty)` gives its time."""
    rng = np.random.default_rng(seed)
    rows = []
    for s in range(seeds):
        for move in range(moves):
            difficulty = rng.lognormal(0.0, 0.5)           # shared by every cell: a hard move is hard for all
            for model, case, k in CELLS:
                rows.append({"model": model, "case": case, "k": k, "seed": s, "move": move,
                             "seconds": seconds_of((model, case, k), difficulty, rng), "iterations": 7,
                             "success": True})
    return pd.DataFrame(rows)


def _proportional(cell, difficulty, rng):
    base = {"decomposed": 0.01, "full": 0.04}[cell[0]] * (2.0 if cell[2] == 20 else 1.0)
    return base * difficulty


def test_pooled_statistics_are_the_plain_ones():
    solves = _solves(_proportional, moves=30)
    cells = Cells(solves)
    mean, std = cells.stats(np.ones((1, len(cells.moves))))
    for key in CELLS:
        part = solves[(solves["model"] == key[0]) & (solves["case"] == key[1]) & (solves["k"] == key[2])]
        assert mean[key][0] == pytest.approx(part["seconds"].mean(), rel=1e-12)
        assert std[key][0] == pytest.approx(part["seconds"].std(ddof=0), rel=1e-9)   # σ as the paper's (ddof 0)


def test_paired_bootstrap_keeps_an_exact_ratio():
    """Every move is 4x as long for the full model: every resample gives exactly 0.25 (paired), although the
    moves' times spread widely."""
    out = table3(_solves(_proportional))
    for case in ("no-obstacle", "obstacle-height"):
        for k in (10, 20):
            name = f"ratio.{case}.k{k}"
            assert out[name][0] == pytest.approx(0.25) and out[f"{name}.ci_low"][0] == pytest.approx(0.25)
            assert out[f"{name}.ci_high"][0] == pytest.approx(0.25)
            assert out[f"sigma_ratio.{case}.k{k}"][0] == pytest.approx(0.25)
        for model in ("decomposed", "full"):
            assert out[f"growth.{model}.{case}"][0] == pytest.approx(1.0)   # k = 20 takes twice k = 10
    assert out["moves"][0] == 120 and out["claim.sigma_lower_everywhere"][0] == 1.0


def test_interval_covers_a_known_ratio():
    """Independent noise on each cell: the true t̄ ratio (0.25) lies in the 95 % interval about 95 % of the time
    (here: at least 17 of 20 independent samples), and an interval is not a point."""
    def noisy(cell, difficulty, rng):
        return _proportional(cell, difficulty, rng) * rng.lognormal(0.0, 0.2)   # same mean noise in every cell
    covered, widths = 0, []
    for seed in range(20):
        out = table3(_solves(noisy, moves=30, seed=seed), resamples=500)
        low, high = out["ratio.no-obstacle.k10.ci_low"][0], out["ratio.no-obstacle.k10.ci_high"][0]
        covered += low <= 0.25 <= high
        widths.append(high - low)
    assert covered >= 17 and min(widths) > 0.005


def test_claims_follow_the_intervals():
    """The full model slows down with the constraints (×3), the decomposed one does not: the gap's interval is
    above 0 at both horizons. With the same slow-down for both (no noise) the gap is 0 and the claim fails."""
    def constrained(factor_full, factor_dec, noise):
        def seconds(cell, difficulty, rng):
            factor = factor_full if cell[0] == "full" else factor_dec
            return _proportional(cell, difficulty, rng) * (factor if cell[1] == "obstacle-height" else 1.0) \
                * rng.lognormal(0.0, noise)
        return seconds
    assert table3(_solves(constrained(3.0, 1.0, 0.1)))["claim.full_grows_with_complexity_more"][0] == 1.0
    out = table3(_solves(constrained(2.0, 2.0, 0.0)))
    assert out["complexity_gap.k10"][0] == pytest.approx(0.0, abs=1e-12)
    assert out["claim.full_grows_with_complexity_more"][0] == 0.0


def test_each_seed_has_its_own_point_estimates():
    per = per_seed(_solves(_proportional, seeds=3))
    assert sorted(per) == [0, 1, 2] and all(v["ratio.no-obstacle.k10"] == pytest.approx(0.25) for v in per.values())
