"""``graph`` never draws a link through a third box: read as a straight line, such a link looks
like that box's (FollowerGPS -> MotorMonitor drawn through LeaderGPSMonitor in the adaptive
world read as a link of the loss estimator). A link a straight line would draw through a box
goes around it, in every shipped world and in the expanded platoon."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.transforms import Bbox

from amsa_phys.model.world import load_world
from amsa_phys.plots import graph
from amsa_phys.plots.graphgeom import BOX_H, BOX_W, line_crosses
from amsa_phys.plots.graphmodel import structure

ROOT = Path(__file__).resolve().parents[2]
WORLDS = sorted((ROOT / "worlds").glob("*.yaml"))


def _through_boxes(path: Path, collapse: bool = True) -> list[tuple[str, str, str]]:
    st = structure(load_world(path), collapse)
    pos = graph._positions(st)
    links = list(dict.fromkeys((a, b) for a, b, _ in st.links))
    found = []
    for (a, b), line in graph._routes(pos, links).items():
        for name, (x, y) in pos.items():
            box = Bbox.from_extents(x - BOX_W / 2, y - BOX_H / 2, x + BOX_W / 2, y + BOX_H / 2)
            if name not in (a, b) and line_crosses(np.asarray(line), box):
                found.append((a, b, name))
    return found


@pytest.mark.parametrize("path", WORLDS, ids=lambda p: p.name)
def test_no_link_crosses_a_third_box(path: Path) -> None:
    assert _through_boxes(path) == []


def test_the_adaptive_worlds_gps_to_motor_monitor_link_goes_around() -> None:
    st = structure(load_world(ROOT / "worlds" / "mde_adaptive.yaml"))
    pos = graph._positions(st)
    links = list(dict.fromkeys((a, b) for a, b, _ in st.links))
    line = graph._routes(pos, links)[("FollowerGPS", "MotorMonitor")]
    assert len(line) > 2  # not the straight line it was
    assert line[0][0] == pos["FollowerGPS"][0] + BOX_W / 2
    assert line[-1][0] == pos["MotorMonitor"][0] - BOX_W / 2
