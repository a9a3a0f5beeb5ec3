"""Keep the figures a plotting module would save, instead of writing PNGs: a test then asserts
on what a plot contains (its artists and data), not on pixels."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
from matplotlib.figure import Figure


def keep_figures(
    monkeypatch: pytest.MonkeyPatch, *modules: ModuleType, draw: bool = False
) -> list[Figure]:
    """The figures handed to ``save_png`` of each of ``modules``, in order (nothing written).

    ``draw``: lay each one out as a saved PNG would be (legend and tick positions final).
    """
    kept: list[Figure] = []

    def keep(fig: Figure, out: Path, *args: object, **kwargs: object) -> Path:
        if draw:
            fig.canvas.draw()
        kept.append(fig)
        return out

    for module in modules:
        monkeypatch.setattr(module, "save_png", keep)
    return kept
