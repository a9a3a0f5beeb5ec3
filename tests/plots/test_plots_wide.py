"""Plots never slow the run (issue 19): a wide run's trajectory is drawn per role, not per
rover; reading only the plotted columns changes no pixel; colours past the palette's end
stay distinct; a goal is drawn where the world puts it."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.pyplot as plt
import pytest
import yaml
from matplotlib.collections import LineCollection

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.plots import distance, trajectory
from amsa_phys.runs.plotjob import draw_run_plots, plot_context

ROOT = Path(__file__).resolve().parent.parent.parent


def figure_of(draw, monkeypatch: pytest.MonkeyPatch) -> plt.Figure:
    """The trajectory figure a call would save (its ``save_png`` intercepted)."""
    caught: list[plt.Figure] = []
    monkeypatch.setattr(trajectory, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    draw()
    return caught[0]


@pytest.fixture(scope="module")
def wide_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """scenarios/platoon.yaml with 199 cars (200 rovers), 3 s, no plots."""
    root = tmp_path_factory.mktemp("wide")
    world = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    world["components"]["Car"]["count"] = 199
    (root / "platoon199.yaml").write_text(yaml.safe_dump(world, sort_keys=False))
    scen = yaml.safe_load((ROOT / "scenarios" / "platoon.yaml").read_text())
    scen.update(world="platoon199.yaml", duration=3)
    scen.pop("expect")
    (root / "scenario.yaml").write_text(yaml.safe_dump(scen, sort_keys=False))
    out = root / "run"
    args = ["run", str(root / "scenario.yaml"), "--headless", "-q", "--no-plot"]
    assert main([*args, "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def small_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("small") / "run"
    args = ["run", str(ROOT / "tests" / "fixtures" / "mde_short.yaml"), "--headless", "-q"]
    assert main([*args, "--duration", "20", "--no-plot", "--out", str(out)]) == 0
    return out


def test_a_200_rover_legend_has_one_entry_per_role(
    wide_run: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    metrics = json.loads((wide_run / "metrics.json").read_text())
    world = plot_context(load_scenario(wide_run / "scenario.yaml").world)
    fig = figure_of(
        lambda: trajectory.plot_trajectory(
            wide_run / "trace.csv", metrics, wide_run / "t.png", world
        ),
        monkeypatch,
    )
    try:
        ax = fig.axes[0]
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert texts == ["Leader (true)", "Car*.Robot ×199 (true)", "GPS fixes (a sample)"]
        # every car's path is there, in one artist: the cost is per role, not per rover
        (cars,) = [c for c in ax.collections if isinstance(c, LineCollection)][1:]
        assert len(cars.get_segments()) == 199
        assert len(ax.lines) + len(ax.collections) < 20
        assert not [t for t in ax.texts if t.get_text().startswith("Car")]  # no per-rover text
    finally:
        plt.close(fig)


@pytest.mark.parametrize("which", ["small_run", "wide_run"])
def test_reading_only_the_plotted_columns_changes_no_pixel(
    which: str, request: pytest.FixtureRequest, tmp_path: Path
) -> None:
    """The run's plots (read with ``keep``) are byte-identical to plots drawn from the
    whole trace. Mutation-checked: a ``keep`` that shifted the header against the columns
    made this fail."""
    run: Path = request.getfixturevalue(which)
    metrics = json.loads((run / "metrics.json").read_text())
    world = plot_context(load_scenario(run / "scenario.yaml").world)
    draw_run_plots(run / "trace.csv", metrics, tmp_path / "d1.png", tmp_path / "t1.png", world)
    distance.plot_distance(run / "trace.csv", metrics, tmp_path / "d2.png")
    trajectory.plot_trajectory(run / "trace.csv", metrics, tmp_path / "t2.png", world)
    assert (tmp_path / "t1.png").read_bytes() == (tmp_path / "t2.png").read_bytes()
    assert (tmp_path / "d1.png").read_bytes() == (tmp_path / "d2.png").read_bytes()
    assert (tmp_path / "t1.png").stat().st_size > 10_000  # a picture, not an empty frame


def test_small_runs_keep_one_legend_entry_and_colour_per_rover(
    small_run: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    metrics = json.loads((small_run / "metrics.json").read_text())
    fig = figure_of(
        lambda: trajectory.plot_trajectory(small_run / "trace.csv", metrics, small_run / "t.png"),
        monkeypatch,
    )
    try:
        labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        assert labels[:2] == ["Leader (true)", "Follower (true)"]
    finally:
        plt.close(fig)


def test_rovers_past_the_palette_end_still_look_different() -> None:
    names = [f"Car{i}.Robot" for i in range(1, 31)]
    styles = trajectory.rover_styles(names)
    looks = {(s.colour, s.linestyle) for s in styles.values()}
    assert len(looks) == 30
    assert styles["Car1.Robot"].linestyle == "-"
    assert styles["Car10.Robot"].colour != styles["Car1.Robot"].colour  # 20 colours first
    assert styles["Car21.Robot"].colour == styles["Car1.Robot"].colour  # the palette again,
    assert styles["Car21.Robot"].linestyle != "-"  # dashed


def test_the_obstacle_course_goal_is_drawn(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    out = tmp_path / "run"
    args = ["run", str(ROOT / "scenarios" / "obstacle_course.yaml"), "--headless", "-q"]
    assert main([*args, "--duration", "5", "--no-plot", "--out", str(out)]) == 0
    world = plot_context(load_scenario(out / "scenario.yaml").world)
    assert world["goals"] == [{"x": 50.0, "y": 0.0, "radius": 0.5}]  # navigator + monitor: one
    metrics = json.loads((out / "metrics.json").read_text())
    fig = figure_of(
        lambda: trajectory.plot_trajectory(out / "trace.csv", metrics, out / "t.png", world),
        monkeypatch,
    )
    try:
        ax = fig.axes[0]
        (star,) = [ln for ln in ax.lines if ln.get_marker() == "*"]
        assert (star.get_xdata()[0], star.get_ydata()[0]) == (50.0, 0.0)
        assert "goal (50, 0)" in [t.get_text() for t in ax.get_legend().get_texts()]
        x0, x1 = ax.get_xlim()
        assert x0 < 50 < x1  # in the picture even though the rover is 5 s from it
    finally:
        plt.close(fig)


def test_a_too_wide_row_is_refused_when_only_some_columns_are_read(tmp_path: Path) -> None:
    path = tmp_path / "trace.csv"
    path.write_text("t,A.posX,A.posY,B.x\n0,1,2,3\n0.05,1,2,3,4\n")
    from amsa_phys.errors import ConfigError

    with pytest.raises(ConfigError) as err:
        distance.read_trace(path, frozenset({"A.posX", "A.posY"}))
    assert str(err.value).endswith(
        "trace.csv:3: not a whole trace: 5 values where the header names 4"
    )
