"""One visual language: the window, the replay and the plots make the same choices, taken
from ``amsa_phys/palette.py`` and written down once in ``docs/visual-language.md``."""

from __future__ import annotations

import itertools
import json
import math
import re
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import pytest
from matplotlib.colors import to_hex, to_rgb

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.palette import (
    ALERT,
    COLLISION,
    LOST_FIX,
    MARKS,
    REFERENCE,
    ROVER_COLOURS,
    SIGNAL,
    WARN,
    hex_colour,
    rover_colour,
)
from amsa_phys.plots import paper, trajectory
from amsa_phys.plots.distance import cut_note, distance_figure
from amsa_phys.runs.plotjob import plot_context
from amsa_phys.view.draw import Renderer
from amsa_phys.view.marks import draw_collision, draw_lost_fix
from amsa_phys.view.pg import pygame

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"
DOC = ROOT / "docs" / "visual-language.md"


def figure_of(draw: Any, monkeypatch: pytest.MonkeyPatch) -> plt.Figure:
    """The figure ``plot_trajectory`` would save (its ``save_png`` intercepted)."""
    caught: list[plt.Figure] = []
    monkeypatch.setattr(trajectory, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    draw()
    return caught[0]


def run(tmp: Path, *extra: str) -> Path:
    out = tmp / "run"
    argv = ["run", str(SCENARIO), "--headless", "--duration", "30", "--out", str(out)]
    assert main([*argv, *extra]) == 0
    return out


def trajectory_figure(rundir: Path, monkeypatch: pytest.MonkeyPatch) -> plt.Figure:
    metrics = json.loads((rundir / "metrics.json").read_text())
    world = plot_context(load_scenario(rundir / "scenario.yaml").world)
    return figure_of(
        lambda: trajectory.plot_trajectory(rundir / "trace.csv", metrics, rundir / "t.png", world),
        monkeypatch,
    )


def test_a_rover_has_its_world_colour_whatever_columns_the_trace_keeps(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = run(tmp_path, "--trace-columns", "Follower.*,LeaderGPS.*,MyDistanceMonitor.*")
    fig = trajectory_figure(out, monkeypatch)
    try:
        colours = {ln.get_label(): to_hex(ln.get_color()) for ln in fig.axes[0].lines}
        # the follower is the world's second rover: blue, as in the window, not the first colour
        assert colours["Follower (true)"] == hex_colour(ROVER_COLOURS[1])
        # the leader is not traced, its GPS is: its crosses keep the leader's orange
        assert colours["LeaderGPS (measured)"] == hex_colour(ROVER_COLOURS[0])
    finally:
        plt.close(fig)


def test_lost_fixes_and_collisions_have_one_mark_each_everywhere(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = run(tmp_path, "--set", "LeaderGPS.lostDataGPS=30")
    fig = trajectory_figure(out, monkeypatch)
    try:
        lost = [ln for ln in fig.axes[0].lines if str(ln.get_label()).startswith("lost GPS fix")]
        (legend,) = lost
        assert legend.get_marker() == LOST_FIX.marker == "x"
        assert to_hex(legend.get_color()) == hex_colour(LOST_FIX.colour)
        drawn = [
            ln
            for ln in fig.axes[0].lines
            if ln.get_marker() == "x" and len(ln.get_xdata()) and ln is not legend
        ]
        n = int(re.search(r"\((\d+)\)", str(legend.get_label())).group(1))  # type: ignore[union-attr]
        assert sum(len(ln.get_xdata()) for ln in drawn) == n > 20
    finally:
        plt.close(fig)
    # the window draws the same marks in the same colours
    surface = pygame.Surface((40, 40))
    surface.fill((255, 255, 255))
    draw_lost_fix(surface, (10, 10))
    draw_collision(surface, (30, 30))
    assert tuple(surface.get_at((10, 10)))[:3] == LOST_FIX.colour
    assert tuple(surface.get_at((30, 30)))[:3] == COLLISION.colour
    assert COLLISION.marker != LOST_FIX.marker  # a red × is never a collision


def test_the_distance_curve_is_the_signal_colour_in_every_plot(tmp_path: Path) -> None:
    out = run(tmp_path)
    metrics = json.loads((out / "metrics.json").read_text())
    fig = distance_figure(out / "trace.csv", metrics)
    try:
        ax = fig.axes[0]
        (curve,) = [ln for ln in ax.lines if ln.get_label() == metrics["quality"]["signal"]]
        assert to_hex(curve.get_color()) == hex_colour(SIGNAL)
        (ref,) = [ln for ln in ax.lines if str(ln.get_label()).startswith("reference")]
        assert to_hex(ref.get_color()) == hex_colour(REFERENCE)
    finally:
        plt.close(fig)
    assert hex_colour(SIGNAL) == paper.FOLLOWER  # Fig. 5/6 draw the distance alike


def test_rover_colours_are_distinct_and_never_a_mark_colour() -> None:
    reserved = [ALERT, REFERENCE, WARN, SIGNAL, (127, 127, 127)]
    for a, b in itertools.combinations([*ROVER_COLOURS, *reserved], 2):
        assert math.dist(a, b) > 30, (a, b)
    # Car9 and Car10 (the 10th and 11th rovers) are not the leader's and Car1's colours
    assert rover_colour(9) not in (rover_colour(0), rover_colour(1))
    assert rover_colour(10) not in (rover_colour(0), rover_colour(1))
    # the window's amber distance line is clear of the leader's orange (hue, not only RGB)
    assert math.dist(WARN, ROVER_COLOURS[0]) > 80


def test_the_doc_table_is_the_palette() -> None:
    text = DOC.read_text()
    for i, colour in enumerate(ROVER_COLOURS):
        assert f"| rover {i} | `{hex_colour(colour)}` |" in text
    for mark in MARKS:
        assert f"`{mark.marker}`" in text, mark.name
    for colour in (ALERT, SIGNAL, REFERENCE, WARN):
        assert hex_colour(colour) in text


def test_a_run_closed_in_the_window_says_where_in_its_plot_titles(tmp_path: Path) -> None:
    out = run(tmp_path)
    metrics = json.loads((out / "metrics.json").read_text())
    # --duration 30 of a 500 s scenario: said too, as shortened (tryout: it said nothing)
    assert cut_note(metrics) == (
        " — shortened to 30 s of 500 s by --duration (1 of 2 phases, the last cut)"
    )
    # a run directory written before metrics.json said what was planned
    old = {k: v for k, v in metrics.items() if k != "planned"}
    assert cut_note(old) == " — shortened to 30 s by --duration (its last phase cut)"
    whole = {**metrics, "overall": {**metrics["overall"], "partial": False}}
    assert cut_note(whole) == ""
    metrics.update(simulated=12.5, duration=30.0, status="closed in the window at t=12.5 s")
    fig = distance_figure(out / "trace.csv", metrics)
    try:
        assert fig.axes[0].get_title().endswith(" — cut at 12.5 s of 30 s (closed in the window)")
    finally:
        plt.close(fig)
    assert cut_note({**metrics, "status": "interrupted"}).endswith("(interrupted (Ctrl-C))")


def test_renderer_labels_never_overlap_when_rovers_meet() -> None:
    """Two rovers side by side (``FollowLeader``'s start): both names readable."""
    from amsa_phys.view.camera import Camera
    from amsa_phys.view.scene import RoverPose

    rovers = [
        RoverPose("Leader", 0.0, 0.0, 0.0, 0.8, 0.6, 0.5, 0, 0, 0, index=0),
        RoverPose("Follower", 0.3, 0.1, 0.0, 0.8, 0.6, 0.5, 0, 0, 0, index=1),
        RoverPose("Car2", 0.1, -0.1, 0.0, 0.8, 0.6, 0.5, 0, 0, 0, index=2),
    ]
    r = Renderer((640, 360))
    surface = pygame.Surface((640, 360))
    r._labels(surface, Camera((640, 360)), rovers)
    assert len(r.labels) == 3
    for a, b in itertools.combinations(r.labels, 2):
        assert not a.colliderect(b)


@pytest.mark.parametrize("name", ["ALERT", "SIGNAL"])
def test_matplotlib_reads_the_palette_as_drawn(name: str) -> None:
    colour = {"ALERT": ALERT, "SIGNAL": SIGNAL}[name]
    assert tuple(round(c * 255) for c in to_rgb(hex_colour(colour))) == colour


def test_the_distance_line_is_never_a_rovers_colour() -> None:
    """Amber blended toward red passed through the leader's orange: the line between the
    rovers vanished into the leader's trail. Every error now draws a colour no rover has."""
    from amsa_phys.view.draw import error_colour

    for k in range(0, 61):
        colour = error_colour(k / 10, 1.0)
        for rover in ROVER_COLOURS:
            assert math.dist(colour, rover) > 60, (k / 10, colour, rover)
