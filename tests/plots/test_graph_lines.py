"""The architecture diagram's lines: none runs through a component, no label sits on a crossing."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from matplotlib.patches import FancyArrowPatch
from matplotlib.transforms import Bbox

from amsa_phys.model.world import load_world
from amsa_phys.plots.graph import diagram

ROOT = Path(__file__).resolve().parent.parent.parent


def arrow_points(fig: object) -> list[np.ndarray]:
    """Every arrow of the figure as points at most 1 px apart, in display pixels."""
    fig.canvas.draw()  # type: ignore[attr-defined]  # annotation arrows are laid out on draw
    ax = fig.axes[0]  # type: ignore[attr-defined]
    arrows = [p for p in ax.patches if isinstance(p, FancyArrowPatch)]
    arrows += [t.arrow_patch for t in ax.texts if getattr(t, "arrow_patch", None) is not None]
    out = []
    for arrow in arrows:
        path = arrow.get_transform().transform_path(arrow.get_path())
        pts = []
        for poly in path.to_polygons(closed_only=False):
            for a, b in itertools.pairwise(poly):
                n = max(2, int(np.hypot(*(b - a))) + 1)
                pts.append(a + np.linspace(0, 1, n)[:, None] * (b - a))
        out.append(np.concatenate(pts))
    return out


def inside(points: np.ndarray, box: Bbox) -> bool:
    x, y = points[:, 0], points[:, 1]
    return bool(np.any((x > box.x0) & (x < box.x1) & (y > box.y0) & (y < box.y1)))


@pytest.mark.parametrize("name", ["mde_challenge", "platoon"])
def test_no_line_crosses_a_component_and_no_label_sits_on_another_line(name: str) -> None:
    import matplotlib.pyplot as plt

    fig, boxes, labels = diagram(load_world(ROOT / "worlds" / f"{name}.yaml"))
    try:
        arrows = arrow_points(fig)
        assert len(arrows) == len(labels)
        for i, pts in enumerate(arrows):
            for box in boxes:  # 8 px in: an arrow ends on its boxes (their rounded pad included)
                shrunk = Bbox.from_extents(box.x0 + 8, box.y0 + 8, box.x1 - 8, box.y1 - 8)
                assert not inside(pts, shrunk), f"arrow {i} runs through the box at {box}"
        for j, label in enumerate(labels):
            under = [i for i, pts in enumerate(arrows) if inside(pts, label)]
            assert len(under) == 1, f"label {j} covers arrows {under}"  # its own line only
    finally:
        plt.close(fig)
