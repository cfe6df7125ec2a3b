"""Figure output shared by every paper: one style, PNG (150 dpi, for the report) and SVG (for papers and slides).

A paper's printed values are drawn on its figures with `paper_hline` / `paper_vline` / `paper_point`, their
value read from targets.csv by `analysis.core.targets.paper_value` (never retyped), and labelled "paper".
Each figure is declared in the paper's paper.yaml (`figures:`, see analysis/core/report.py) with the paper
figure it regenerates, a caption and the report section it belongs to.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

from pipeline.core.files import atomic_path

matplotlib.use("Agg")
import matplotlib.pyplot as plt

DPI = 150
plt.rcParams.update({
    "figure.dpi": DPI, "savefig.dpi": DPI, "font.size": 9, "axes.grid": True, "grid.alpha": 0.3,
    "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False,
    "svg.fonttype": "none",   # text stays text in the SVG
})

PAPER_STYLE = {"color": "crimson", "ls": "--", "lw": 1.1}


def paper_hline(ax, y: float, label: str = "paper", **style) -> None:
    """A value the paper prints (a bound, a peak) as a horizontal line labelled as the paper's."""
    ax.axhline(y, **(PAPER_STYLE | style), label=label)


def paper_vline(ax, x: float, label: str = "paper", **style) -> None:
    """A time or abscissa the paper prints (a convergence time, …) as a vertical line."""
    ax.axvline(x, **(PAPER_STYLE | style), label=label)


def paper_point(ax, x: float, y: float, label: str = "paper", **style) -> None:
    """One printed point (a peak at a given abscissa)."""
    ax.plot([x], [y], marker="D", ms=6, ls="none", mfc="none", mec=PAPER_STYLE["color"], mew=1.5,
            label=label, **style)


class Figures:
    """Saves an experiment's figures under <data_dir>/figures/<slug>/<experiment>/ as PNG and SVG."""

    def __init__(self, directory: Path):
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.saved: list[Path] = []

    def save(self, fig, name: str, tight: bool = True) -> Path:
        png = self.directory / f"{name}.png"
        if tight:
            fig.tight_layout()
        for path in (png, png.with_suffix(".svg")):
            with atomic_path(path) as tmp:
                fig.savefig(tmp, format=path.suffix[1:])
        plt.close(fig)
        self.saved.append(png)
        return png


__all__ = ["DPI", "PAPER_STYLE", "Figures", "paper_hline", "paper_point", "paper_vline", "plt"]
