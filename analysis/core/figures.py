"""Figure output shared by every paper: one style, PNG for the report (and SVG on request)."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

from pipeline.core.files import atomic_path

matplotlib.use("Agg")
import matplotlib.pyplot as plt

plt.rcParams.update({
    "figure.dpi": 110, "savefig.dpi": 110, "font.size": 9, "axes.grid": True, "grid.alpha": 0.3,
    "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False,
})


# Vector copies for papers and slides: `REPRO_SVG=1 python -m analysis ...` (they double the figure time).
SVG = os.environ.get("REPRO_SVG", "0") == "1"


class Figures:
    """Saves an experiment's figures under <data_dir>/figures/<slug>/<experiment>/."""

    def __init__(self, directory: Path):
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.saved: list[Path] = []

    def save(self, fig, name: str) -> Path:
        png = self.directory / f"{name}.png"
        fig.tight_layout()
        for path in (png, png.with_suffix(".svg")) if SVG else (png,):
            with atomic_path(path) as tmp:
                fig.savefig(tmp, format=path.suffix[1:])
        plt.close(fig)
        self.saved.append(png)
        return png


__all__ = ["Figures", "plt"]
