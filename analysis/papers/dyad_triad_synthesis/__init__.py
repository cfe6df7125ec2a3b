"""Analysis of `dyad-triad-synthesis`: Table 5 and the worked example, the Burmester curves, the synthetic
round trips, the four-bar in Exudyn and the solvers' compute time."""

from __future__ import annotations

from analysis.papers.dyad_triad_synthesis import figures, metrics
from analysis.papers.dyad_triad_synthesis.tables import report_sections


def _analysis(compute, draw):
    def run(runs, figs):
        draw(runs, figs)
        return compute(runs).frame()

    return run


ANALYSES = {name: _analysis(getattr(metrics, fn), getattr(figures, fn))
            for name, fn in (("table5", "table5"), ("burmester-curves", "burmester_curves"),
                             ("round-trips", "round_trips"), ("four-bar", "four_bar"),
                             ("compute-time", "compute_time"))}

__all__ = ["ANALYSES", "report_sections"]
