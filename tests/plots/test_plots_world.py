"""Plots a robotics engineer can read: the arena, collisions, the window's colours, and a
scenario that overrides the world's physics (issue 17 items 6 and 9)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml
from matplotlib.colors import to_hex
from matplotlib.patches import Polygon

from amsa_phys.cli.main import main
from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import ConfigError
from amsa_phys.model.scenario import load_scenario
from amsa_phys.palette import ROVER_COLOURS, hex_colour
from amsa_phys.plots import distance, trajectory
from amsa_phys.view.draw import rover_colour
from amsa_phys.view.scene import Scene

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
ORANGE, BLUE = hex_colour(ROVER_COLOURS[0]), hex_colour(ROVER_COLOURS[1])

#: A fast rover's motors (the MDE world's paper-calibrated rovers are slow).
FAST = {"stallForce": 45.0, "maxWheelTorque": 4.5}

#: scenario 1's straight leader, plus what the scenario adds to the world: a tilted box on
#: the leader's line at x = 50 (it drives into it at ~41 s), a round rock and walls. Both
#: rovers get a fast rover's motors (the world's paper-calibrated ones are slow), so the
#: leader reaches the box within the minute.
ARENA = f"""\
world: {WORLD}
duration: 60
seed: 1
quality: {{signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}}
physics:
  ground: {{rolling_resistance: 0.03}}
  obstacles:
    - {{type: box, x: 50, y: 0.2, width: 2, height: 3, angle: 0.3}}
    - {{type: circle, x: 30, y: 6, radius: 2}}
  walls: {{xmin: -10, xmax: 80, ymin: -20, ymax: 20}}
set: {{Leader.behavior: 1, MyFollowerController.Kv: 0.15, Leader.cruisePower: 22.0,
      Leader.stallForce: 45.0, Leader.maxWheelTorque: 4.5,
      Follower.stallForce: 45.0, Follower.maxWheelTorque: 4.5}}
"""


@pytest.fixture(scope="module")
def arena_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("arena")
    (root / "arena.yaml").write_text(ARENA)
    out = root / "run"
    assert main(["run", str(root / "arena.yaml"), "--headless", "-q", "--out", str(out)]) == 0
    return out


def figure_of(module: Any, draw: Any, monkeypatch: pytest.MonkeyPatch) -> plt.Figure:
    """The figure a plotting call would save (its ``save_png`` intercepted)."""
    caught: list[plt.Figure] = []
    monkeypatch.setattr(module, "save_png", lambda fig, out, **kw: caught.append(fig) or out)
    draw()
    return caught[0]


def test_a_scenario_adds_obstacles_and_merges_physics_over_the_world(arena_run: Path) -> None:
    scenario = load_scenario(arena_run.parent / "arena.yaml")
    physics = scenario.world.physics
    assert physics["ground"] == {"friction": 0.8, "rolling_resistance": 0.03}  # merged
    assert [o["type"] for o in physics["obstacles"]] == ["box", "circle"]
    assert physics["walls"]["xmax"] == 80
    metrics = json.loads((arena_run / "metrics.json").read_text())
    hits = [e for e in metrics["events"] if e["kind"] == "collision"]
    assert [e["detail"] for e in hits] == ["Leader-obstacle[0]"]  # the box stopped the leader
    assert 30 < hits[0]["t"] < 60  # the leader covers the 35 m to the box at ~0.8 m/s
    # the resolved scenario carries the merged physics, and replays byte for byte
    doc = yaml.safe_load((arena_run / "scenario.yaml").read_text())
    assert doc["world"]["physics"]["obstacles"] == physics["obstacles"]
    replay = arena_run.parent / "replay"
    args = ["run", str(arena_run / "scenario.yaml"), "--headless", "-q", "--out", str(replay)]
    assert main(args) == 0
    assert (replay / "trace.csv").read_bytes() == (arena_run / "trace.csv").read_bytes()


def test_set_physics_changes_the_run(tmp_path: Path) -> None:
    path = ROOT / "tests" / "fixtures" / "mde_short.yaml"
    fast = [f"{r}.{k}={v}" for r in ("Leader", "Follower") for k, v in FAST.items()]
    fast.append("Leader.cruisePower=22")
    base = load_scenario(path, duration=5, overrides=fast)
    icy = load_scenario(path, duration=5, overrides=[*fast, "physics.ground.friction=0.02"])
    rolling = base.world.physics["ground"]["rolling_resistance"]
    assert icy.world.physics["ground"] == {"friction": 0.02, "rolling_resistance": rolling}
    assert base.world.physics["ground"]["friction"] == 0.8  # the world is not touched
    ends = []
    for scenario in (base, icy):
        sim = Simulation.from_scenario(scenario)
        sim.run()
        ends.append(sim.values["Follower.posX"])
    assert ends[1] < ends[0] - 1  # on ice the wheels slip: the follower gets less far


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "physics.ground.frction=0.5",
            "--set physics.ground.frction: unknown key (did you mean friction?)",
        ),
        ("physics.gravity=-1", "--set physics.gravity: must be > 0, got -1"),
        ("physics.ground=3", "--set physics.ground: expected a mapping, got integer 3"),
    ],
)
def test_a_bad_physics_override_is_one_line_naming_the_option(text: str, message: str) -> None:
    with pytest.raises(ConfigError) as err:
        load_scenario(ROOT / "scenarios" / "scenario1.yaml", overrides=[text])
    assert str(err.value) == message


def test_a_bad_physics_key_in_a_scenario_names_file_line_and_key(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(ARENA.replace("rolling_resistance: 0.03", "rolling_resistence: 0.03"))
    assert main(["validate", str(path)]) == 2
    with pytest.raises(ConfigError) as err:
        load_scenario(path)
    assert str(err.value) == (
        f"{path}:6: physics.ground.rolling_resistence: unknown key "
        "(did you mean rolling_resistance?)"
    )


def test_trajectory_draws_the_arena_the_collision_and_the_window_colours(
    arena_run: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from amsa_phys.runs.plotjob import plot_context

    metrics = json.loads((arena_run / "metrics.json").read_text())
    world = plot_context(load_scenario(arena_run / "scenario.yaml").world)
    fig = figure_of(
        trajectory,
        lambda: trajectory.plot_trajectory(
            arena_run / "trace.csv", metrics, arena_run / "t.png", world
        ),
        monkeypatch,
    )
    try:
        ax = fig.axes[0]
        shapes = [p for p in ax.patches if isinstance(p, Polygon)]
        assert len(shapes) == 2  # the box and the rock
        centres = sorted(tuple(np.round(p.get_xy()[:-1].mean(axis=0))) for p in shapes)
        assert centres == [(30.0, 6.0), (50.0, 0.0)]
        walls = [ln for ln in ax.lines if len(ln.get_xdata()) == 5]
        assert sorted(walls[0].get_xdata()) == [-10, -10, -10, 80, 80]
        colours = {ln.get_label(): to_hex(ln.get_color()) for ln in ax.lines}
        assert colours["Leader (true)"] == ORANGE
        assert colours["Follower (true)"] == BLUE
        (cross,) = [ln for ln in ax.lines if ln.get_marker() == "D" and len(ln.get_xdata())]
        x, y = cross.get_xdata()[0], cross.get_ydata()[0]
        assert 47 < x < 50  # the leader's nose at the box
        assert abs(y) < 0.5
        assert "collision (1)" in [t.get_text() for t in ax.get_legend().get_texts()]
    finally:
        plt.close(fig)


def test_the_window_colours_rovers_like_the_plots() -> None:
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=1)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    rovers = Scene(sim, scenario.quality).rovers()
    assert [(r.name, hex_colour(rover_colour(i))) for i, r in enumerate(rovers)] == [
        ("Leader", ORANGE),
        ("Follower", BLUE),
    ]


def test_distance_plot_marks_the_collision(
    arena_run: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    metrics = json.loads((arena_run / "metrics.json").read_text())
    fig = figure_of(
        distance,
        lambda: distance.plot_distance(arena_run / "trace.csv", metrics, arena_run / "d.png"),
        monkeypatch,
    )
    try:
        (cross,) = [ln for ln in fig.axes[0].lines if ln.get_label() == "collision (1)"]
        assert cross.get_xdata()[0] == metrics["events"][0]["t"]
        assert 10 < cross.get_ydata()[0] < 20  # on the distance curve
    finally:
        plt.close(fig)


def test_a_long_straight_run_is_drawn_as_a_lateral_offset_view(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "s1"
    args = ["run", str(ROOT / "scenarios" / "scenario1.yaml"), "--headless", "-q"]
    assert main([*args, "--out", str(out), "--no-plot"]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    fig = figure_of(
        trajectory,
        lambda: trajectory.plot_trajectory(out / "trace.csv", metrics, out / "t.png"),
        monkeypatch,
    )
    try:
        ax = fig.axes[0]
        assert ax.get_xlabel() == "distance along the route (m)"
        assert ax.get_ylabel() == "lateral offset (m, stretched)"
        low, high = ax.get_ylim()
        assert high - low <= 5  # not +-200 m of nothing around a line
        starts = {ln.get_color(): ln.get_xdata()[0] for ln in ax.lines if ln.get_marker() == "o"}
        assert sorted(starts.values()) == pytest.approx([0.0, 15.0])  # both rovers apart
        colours = {ln.get_label(): to_hex(ln.get_color()) for ln in ax.lines}
        assert (colours["Leader (true)"], colours["Follower (true)"]) == (ORANGE, BLUE)
    finally:
        plt.close(fig)


def test_without_a_quality_signal_no_blank_distance_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "free.yaml"
    path.write_text(f"world: {WORLD}\nduration: 5\n")
    out = tmp_path / "run"
    assert main(["run", str(path), "--headless", "--out", str(out)]) == 0
    assert "no quality: section, so no metrics of control and no distance.png" in (
        capsys.readouterr().out
    )
    assert (out / "trajectory.png").is_file()
    assert not (out / "distance.png").exists()
    assert main(["plot", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"wrote {out / 'trajectory.png'}\n" in printed
    assert "no distance.png: the scenario has no quality: section" in printed


def test_the_window_and_the_replay_mark_the_collision_where_the_plot_does(
    arena_run: Path,
) -> None:
    """The leader drives into the box at x = 50: the live scene (window, video), the replay
    and trajectory.png all put one collision mark at its nose there."""
    from amsa_phys.cli.view import load_run
    from amsa_phys.engine.runner import Simulation

    scenario = load_scenario(arena_run.parent / "arena.yaml")
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    scene = Scene(sim, scenario.quality)
    sim.advance(sim.grid.ticks(sim.duration))
    (live,) = scene.frame().collisions
    assert 47 < live[0] < 50
    assert abs(live[1]) < 0.5
    replay = load_run(arena_run)
    (hit,) = replay.frame(replay.rows - 1).collisions
    assert abs(hit[0] - live[0]) < 0.2
    assert abs(hit[1] - live[1]) < 0.2
    assert replay.frame(0).collisions == []  # not before it happened
