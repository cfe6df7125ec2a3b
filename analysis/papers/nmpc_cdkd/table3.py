"""`nmpc-cdkd` Table 3 as statistics: every timed OCP solve of every (model, case, horizon) cell, pooled over the
seeds, with bootstrap intervals of the paper's ratios.

The unit of resampling is the move: all twelve cells solve their OCPs on the same moves (and, with sampled
states, at the same updates), so one resample of moves serves every cell (a paired bootstrap) and a ratio of two
cells keeps what the cells share. Each resample gives the cells' t̄ and σ (the paper's mean and standard deviation
per OCP step), hence every ratio; a ratio is reported as the median of its bootstrap distribution with the 2.5 %
and 97.5 % percentiles as its 95 % interval (`<metric>.ci_low`, `<metric>.ci_high`, which a target with the
tolerance `ci` is judged by: see analysis/core/targets.py).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pandas as pd

from pipeline.core.runlog import Run

MODELS = ("decomposed", "full")
CASES = ("no-obstacle", "obstacle", "obstacle-height")
RESAMPLES = 2000
CONFIDENCE = 0.95
BOOTSTRAP_SEED = 0   # the resampling is part of the analysis: the same runs give the same intervals
CONTROL_HORIZON = 0.04   # s: 4 × 10 ms; a solve longer than this would delay the robot (Sec. 4.2)


def cell_of(run_id: str) -> tuple[str, str, int]:
    """`decomposed-obstacle-k10__seed=1` -> (decomposed, obstacle, 10)."""
    model, rest = run_id.split("__")[0].split("-", 1)
    case, k = rest.rsplit("-k", 1)
    return model, case, int(k)


def timed_solves(runs: Iterable[Run]) -> pd.DataFrame:
    """One row per timed OCP solve: model, case, k, seed, move, seconds, iterations, success."""
    frames = []
    for run in runs:
        solves = run["/nmpc/solve"]
        if "timed" in solves:
            solves = solves[solves["timed"].astype(bool)]
        model, case, k = cell_of(run.run_id)
        frames.append(pd.DataFrame({
            "model": model, "case": case, "k": k, "seed": int(run.config.get("seed", 0)),
            "move": solves["move"].to_numpy() if "move" in solves else 0, "seconds": solves["seconds"].to_numpy(),
            "iterations": solves["iterations"].to_numpy(), "success": solves["success"].astype(bool).to_numpy()}))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(
        columns=["model", "case", "k", "seed", "move", "seconds", "iterations", "success"])


class Cells:
    """Per-move sums of the timed solve times of every cell, and the cells' t̄ and σ under move weights."""

    def __init__(self, solves: pd.DataFrame):
        moves = solves[["seed", "move"]].drop_duplicates().sort_values(["seed", "move"])
        self.moves = pd.MultiIndex.from_frame(moves)
        self.keys = sorted({(m, c, int(k)) for m, c, k in solves[["model", "case", "k"]].itertuples(index=False)},
                           key=lambda key: (MODELS.index(key[0]), CASES.index(key[1]), key[2]))
        shape = (len(self.keys), len(self.moves))
        self.count, self.sum, self.square = np.zeros(shape), np.zeros(shape), np.zeros(shape)
        for i, key in enumerate(self.keys):
            cell = solves[(solves["model"] == key[0]) & (solves["case"] == key[1]) & (solves["k"] == key[2])]
            grouped = cell.groupby(["seed", "move"])["seconds"]
            where = self.moves.get_indexer(grouped.sum().index)
            self.count[i, where] = grouped.count().to_numpy()
            self.sum[i, where] = grouped.sum().to_numpy()
            self.square[i, where] = grouped.apply(lambda s: float((s ** 2).sum())).to_numpy()

    def stats(self, weights: np.ndarray) -> tuple[dict, dict]:
        """(t̄, σ) per cell key, each an array over the rows of `weights` (resamples × moves)."""
        n = weights @ self.count.T
        mean = (weights @ self.sum.T) / n
        std = np.sqrt(np.maximum((weights @ self.square.T) / n - mean ** 2, 0.0))   # ddof = 0, like the paper's σ
        return ({key: mean[:, i] for i, key in enumerate(self.keys)},
                {key: std[:, i] for i, key in enumerate(self.keys)})


def ratios(mean: dict, std: dict) -> dict[str, np.ndarray]:
    """Every ratio of Sec. 4.1 that the cells on hand allow, as arrays over resamples."""
    out: dict[str, np.ndarray] = {}
    horizons = sorted({k for *_, k in mean})
    for case in CASES:
        for k in horizons:
            dec, full = ("decomposed", case, k), ("full", case, k)
            if dec in mean and full in mean:
                out[f"ratio.{case}.k{k}"] = mean[dec] / mean[full]
                out[f"sigma_ratio.{case}.k{k}"] = std[dec] / std[full]
        for model in MODELS:
            if len(horizons) == 2 and all((model, case, k) in mean for k in horizons):
                out[f"growth.{model}.{case}"] = mean[model, case, horizons[1]] / mean[model, case, horizons[0]] - 1
    for model in MODELS:
        for k in horizons:
            if (model, "no-obstacle", k) in mean and (model, "obstacle-height", k) in mean:
                out[f"complexity.{model}.k{k}"] = mean[model, "obstacle-height", k] / mean[model, "no-obstacle", k]
    stacked = {prefix: [v for name, v in out.items() if name.startswith(prefix)]
               for prefix in ("ratio.", "sigma_ratio.", "growth.decomposed.", "growth.full.")}
    if stacked["ratio."]:
        out["claim.ratio_max"] = np.max(stacked["ratio."], axis=0)
        out["claim.ratio_min"] = np.min(stacked["ratio."], axis=0)
    for model in MODELS:
        if stacked[f"growth.{model}."]:
            out[f"claim.growth_max.{model}"] = np.max(stacked[f"growth.{model}."], axis=0)
    for k in horizons:
        if f"complexity.full.k{k}" in out and f"complexity.decomposed.k{k}" in out:
            out[f"complexity_gap.k{k}"] = out[f"complexity.full.k{k}"] - out[f"complexity.decomposed.k{k}"]
    return out


def table3(solves: pd.DataFrame, resamples: int = RESAMPLES) -> dict[str, tuple[float, str]]:
    """The `table3` aggregate: per cell t̄, σ (pooled, with intervals); every ratio as the bootstrap median with
    its interval; the claims of Sec. 4.1 decided on the intervals; the sample sizes."""
    if solves.empty:
        return {}
    cells = Cells(solves)
    moves = len(cells.moves)
    weights = np.random.default_rng(BOOTSTRAP_SEED).multinomial(moves, np.full(moves, 1 / moves), size=resamples)
    mean, std = cells.stats(weights.astype(float))
    low, high = 100 * (1 - CONFIDENCE) / 2, 100 * (1 + CONFIDENCE) / 2
    out: dict[str, tuple[float, str]] = {"moves": (moves, "count"), "resamples": (resamples, "count")}

    def add(name: str, samples: np.ndarray, unit: str) -> None:
        finite = samples[np.isfinite(samples)]
        if not len(finite):
            return
        lo, median, hi = np.percentile(finite, [low, 50, high])
        out[name], out[f"{name}.ci_low"], out[f"{name}.ci_high"] = (median, unit), (lo, unit), (hi, unit)

    for key in cells.keys:
        label = f"{key[0]}.{key[1]}.k{key[2]}"
        add(f"mean.{label}", mean[key], "s")
        add(f"std.{label}", std[key], "s")
        cell = solves[(solves["model"] == key[0]) & (solves["case"] == key[1]) & (solves["k"] == key[2])]
        out |= {f"samples.{label}": (len(cell), "count"), f"median.{label}": (cell["seconds"].median(), "s"),
                f"p95.{label}": (cell["seconds"].quantile(0.95), "s"),
                f"iterations.{label}": (cell["iterations"].mean(), "count"),
                f"failures.{label}": (int((~cell["success"]).sum()), "count"),
                f"over_control_horizon.{label}": ((cell["seconds"] > CONTROL_HORIZON).mean(), "fraction")}
    values = ratios(mean, std)
    for name, samples in values.items():
        add(name, samples, "fraction" if "growth" in name else "ratio")
    sigma_high = [out[f"{n}.ci_high"][0] for n in values if n.startswith("sigma_ratio.") and f"{n}.ci_high" in out]
    if sigma_high:   # "lower deviations σ, independent of the scenario": every σ ratio's interval below 1
        out["claim.sigma_lower_everywhere"] = (float(max(sigma_high) < 1), "bool")
    gaps = [out[f"{n}.ci_low"][0] for n in values if n.startswith("complexity_gap.") and f"{n}.ci_low" in out]
    if gaps:         # full grows more with the constraints than decomposed, at every horizon
        out["claim.full_grows_with_complexity_more"] = (float(min(gaps) > 0), "bool")
    return out


def per_seed(solves: pd.DataFrame) -> dict[int, dict[str, float]]:
    """Each seed's own point estimates of the ratios (how far one seed's moves move them)."""
    out = {}
    for seed, part in solves.groupby("seed"):
        cells = Cells(part)
        mean, std = cells.stats(np.ones((1, len(cells.moves))))
        out[int(seed)] = {name: float(v[0]) for name, v in ratios(mean, std).items()}
    return out
