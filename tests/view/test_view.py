"""Camera, parameter panel and scene: the window's logic without pixels."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.camera import Camera
from amsa_phys.view.draw import error_colour, nice_step
from amsa_phys.view.panel import ParamPanel
from amsa_phys.view.scene import Scene, describe_phase, static_obstacles

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


@pytest.fixture
def sim() -> Simulation:
    s = Simulation.from_scenario(load_scenario(SCENARIO, duration=10))
    s.initialize()
    return s


def test_camera_round_trips_and_keeps_every_rover_in_view() -> None:
    cam = Camera((640, 360))
    points = [(0.0, 0.0, "a"), (80.0, -30.0, "b")]
    for _ in range(50):
        cam.update(points, 0.1)
    for x, y, _ in points:
        px, py = cam.to_screen(x, y)
        assert 0 <= px <= 640
        assert 0 <= py <= 360
        assert cam.to_world(px, py) == pytest.approx((x, y))
    # a jump far away is followed at once, not glided off-screen
    cam.update([(500.0, 500.0, "a"), (510.0, 500.0, "b")], 0.01)
    px, py = cam.to_screen(500.0, 500.0)
    assert 0 <= px <= 640
    assert 0 <= py <= 360


def test_camera_zoom_keeps_the_point_under_the_cursor() -> None:
    cam = Camera((640, 360))
    before = cam.to_world(100, 50)
    cam.zoom(2.0, (100, 50))
    assert cam.to_world(100, 50) == pytest.approx(before)
    assert cam.mode == "free"


def test_camera_cycles_fit_follow_each_rover_fit() -> None:
    cam = Camera((640, 360))
    assert [cam.cycle(["Leader", "Follower"]) for _ in range(3)] == [
        "follow Leader",
        "follow Follower",
        "fit",
    ]
    cam.cycle(["Leader", "Follower"])
    cam.update([(3.0, 4.0, "Leader"), (0.0, 0.0, "Follower")], 0.1)
    assert (cam.cx, cam.cy) == (3.0, 4.0)


def test_panel_steps_within_range_and_refuses_fixed_parameters(sim: Simulation) -> None:
    panel = ParamPanel(sim)
    keys = [r.key for r in panel.rows]
    assert "MyFollowerController.Kv" in keys
    assert "Leader.behavior" in keys
    panel.index = keys.index("MyNormalizePower.motorCoef")  # int in [0, 100], value 100
    panel.step(+1)
    assert panel.pending == 100  # clamped at the maximum
    panel.step(-1)
    assert panel.pending == 95
    change = panel.commit()
    assert change is not None
    assert (change.key, change.value) == ("MyNormalizePower.motorCoef", 95)
    panel.index = keys.index("Leader.mass")
    panel.step(+1)
    assert panel.commit() is None
    assert "fixed once the run has started" in panel.message


def test_panel_typed_values_are_checked_like_a_scenario_file(sim: Simulation) -> None:
    panel = ParamPanel(sim)
    panel.index = [r.key for r in panel.rows].index("MyFollowerController.Kv")
    for ch in "42":
        panel.type_char(ch)
    assert panel.commit() is None
    assert panel.message == "MyFollowerController.Kv: 42 is above the maximum 10 (range [0, 10])"
    panel.type_char("x")  # not part of a number: ignored
    assert panel.text is None
    panel.index = [r.key for r in panel.rows].index("Leader.behavior")
    panel.step(+1)
    assert panel.pending == 2  # next behaviour


def test_panel_refuses_a_value_that_breaks_a_rule_and_the_run_goes_on(sim: Simulation) -> None:
    # powerMin above powerMax is in range on its own; queued, it would end the session
    panel = ParamPanel(sim)
    panel.index = [r.key for r in panel.rows].index("MyNormalizePower.powerMin")
    for ch in "-5":
        panel.type_char(ch)
    assert panel.commit() is not None  # -5 <= powerMax 100: fine
    sim.components["MyNormalizePower"].p.powerMax = 10.0
    for ch in "20":
        panel.type_char(ch)
    assert panel.commit() is None
    assert panel.message == "MyNormalizePower.powerMin: powerMin 20 is above powerMax 10"


def test_live_change_lands_at_the_next_instant_after_the_timeline(sim: Simulation) -> None:
    panel = ParamPanel(sim)
    sim.advance(sim.grid.ticks(sim.duration) // 2)
    panel.index = [r.key for r in panel.rows].index("MyFollowerController.Kv")
    panel.type_char("1")
    change = panel.commit()
    assert change is not None
    at = sim.apply_live(change)
    assert at > sim.now
    assert sim.components["MyFollowerController"].p.Kv == 0.35
    sim.advance(sim.grid.ticks(at))
    assert sim.components["MyFollowerController"].p.Kv == 1.0
    assert sim.live_changes == [(at, change)]
    assert [e.kind for e in sim.events] == ["live change"]
    # the HUD's phase line shows the value in force, not the phase's own
    line = describe_phase(sim)
    assert f"Kv=1 live at {float(at):.1f} s" in line
    assert "Kv=0.35" not in line
    # phases are numbered from 0, as in the summary table and expect: {phase: i}
    assert line.startswith(f"phase {sim.phase_index} ")


def test_scene_marks_lost_gps_fixes_at_the_true_position(tmp_path: Path) -> None:
    scen = load_scenario(SCENARIO, duration=10, overrides=["LeaderGPS.lostDataGPS=50"])
    sim = Simulation.from_scenario(scen)
    sim.initialize()
    scene = Scene(sim, scen.quality)
    for tick in range(0, sim.grid.ticks(sim.duration), 5):
        sim.advance(tick)
        frame = scene.frame()
    leader_gps = next(t for t in frame.gps if t.path == "LeaderGPS")
    assert leader_gps.rover == "Leader"
    assert leader_gps.lost_total == sim.components["LeaderGPS"].lost > 5
    for x, y in leader_gps.lost:  # the leader drives along y = 0 from x = 15
        assert abs(y) < 0.5
        assert x >= 15
    assert frame.metrics.count > 0
    assert frame.metrics.max >= frame.metrics.min


def test_obstacle_geometry_matches_the_settings() -> None:
    obs = static_obstacles(
        {
            "obstacles": [
                {"type": "box", "x": 1, "y": 2, "width": 4, "height": 2, "angle": math.pi / 2},
                {"type": "circle", "x": 0, "y": 0, "radius": 3},
            ],
            "walls": {"xmin": -5, "xmax": 5, "ymin": -5, "ymax": 5},
        }
    )
    box = obs[0].points
    xs = sorted(round(p[0], 9) for p in box)
    ys = sorted(round(p[1], 9) for p in box)
    assert (xs[0], xs[-1], ys[0], ys[-1]) == (0, 2, 0, 4)  # rotated a quarter turn
    assert obs[1].radius == 3
    assert obs[2].kind == "line"
    assert len(obs[2].points) == 5


def test_drawing_helpers() -> None:
    assert [nice_step(x) for x in (0.3, 1.0, 1.2, 3.0, 7.0)] == [0.5, 1.0, 2.0, 5.0, 10.0]
    assert error_colour(0.5, 1.0) == error_colour(-1.0, 1.0)  # inside the band: same green
    assert error_colour(5.0, 1.0) == error_colour(2.5, 1.0) == (214, 39, 40)  # never orange
    assert error_colour(1.1, 1.0) == error_colour(2.0, 1.0) == (250, 200, 40)  # amber, not olive


def test_hud_lines_wrap_between_items_never_inside_one() -> None:
    """At any width a HUD line breaks after an item (``, ``), a label (``: ``) or between
    fields, so ``Kv=0.2 live at 9.4 s`` is never cut from its ``s`` while it fits at all
    (word wrapping cut it at 1280x720)."""
    from amsa_phys.view.draw import _wrap
    from amsa_phys.view.pg import font

    fnt = font(15)
    text = (
        "phase 0 (of 0–3) from 0 s: behavior=1, lostDataGPS=0, motorCoef=100, Kv=0.2 live at 9.4 s"
    )
    item = "Kv=0.2 live at 9.4 s"
    widest = fnt.size(text)[0]
    for room in range(fnt.size(item)[0], widest + 2):
        lines = _wrap(text, fnt, room)
        assert any(line.endswith(item) for line in lines), (room, lines)
        assert all(fnt.size(line)[0] <= room for line in lines), (room, lines)
        assert " ".join(lines) == text  # nothing lost or doubled at the breaks
    assert _wrap(text, fnt, widest) == [text]
