"""Report sections a paper adds beside its targets (its `report_sections`): prose and tables as data, so that
the report's templates render them to HTML and Markdown with every cell escaped by construction.

    Section("Fig. 8: force sag, every run",
            "F_set = 5 N, 40° at ω_max = 5.9 rad/s; the window runs ...",   # Markdown prose, no tables
            Table(frame, floatfmt=".3f"),
            "The two plants:", Table(other))

A section may name the targets' category it belongs to (`category="force errors"`); the report then places it
right after that category's targets, beside the figures of that category. Otherwise it goes to "Further results".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd


@dataclass(frozen=True)
class Table:
    """A table of a report section. `index=True` shows the frame's index as the first column(s)."""

    frame: pd.DataFrame
    floatfmt: str = ".4g"
    index: bool = False

    def _shown(self) -> pd.DataFrame:
        return self.frame.reset_index() if self.index else self.frame

    def header(self) -> list[str]:
        return [str(c) for c in self._shown().columns]

    def rows(self) -> list[list[str]]:
        return [[self.cell(v) for v in row] for row in self._shown().itertuples(index=False)]

    def cell(self, value) -> str:
        if isinstance(value, bool):
            return str(value)
        if isinstance(value, float):
            return "" if math.isnan(value) else format(value, self.floatfmt)
        if value is None or value is pd.NA:
            return ""
        return str(value)


class Section:
    """A titled block of prose (Markdown, without tables) and `Table`s, in order."""

    def __init__(self, title: str, *blocks: str | Table, category: str | None = None):
        self.title = title
        self.blocks = [b.strip() if isinstance(b, str) else b for b in blocks if not isinstance(b, str) or b.strip()]
        self.category = category

    def __repr__(self) -> str:
        return f"Section({self.title!r}, {len(self.blocks)} blocks)"


__all__ = ["Section", "Table"]
