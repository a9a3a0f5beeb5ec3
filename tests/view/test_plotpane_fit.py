"""A plot pane's legend line fits its pane: a long signal name gives up its start, never
the value and range after it (they ran off the pane's right edge)."""

from __future__ import annotations

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

from amsa_phys.view.pg import font
from amsa_phys.view.plotpane import fit_text

NAME = "MyDistanceMonitor.distanceFollowerToLeader"
REST = " 15.69  [14.5 .. 16.09]"


def test_a_long_name_is_cut_at_its_start_and_the_numbers_kept() -> None:
    face = font(12)
    width = face.size(NAME + REST)[0] - 40
    text = fit_text(face, NAME, REST, width)
    assert face.size(text)[0] <= width
    assert text.endswith("distanceFollowerToLeader" + REST)
    assert text.startswith("\u2026")


def test_a_name_that_fits_is_left_whole() -> None:
    face = font(12)
    assert fit_text(face, "Kv", REST, 1000) == "Kv" + REST
