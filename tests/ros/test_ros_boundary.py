"""The robot boundary's plan and its reading of standard messages (``ros/boundary.py``)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.boundary import NO_FIX, plan, read_fields
from amsa_phys.ros.graph import RosGraph, classify
from amsa_phys.stdmsgs import DEFAULT_ORIGIN, enu_to_geodetic, yaw_quaternion

ROOT = Path(__file__).resolve().parent.parent.parent


def _plan(scenario: str):
    world = load_scenario(ROOT / "scenarios" / scenario).world
    return plan(RosGraph.of(world, classify(world)))


def test_the_sensed_world_runs_its_controller_side_without_the_simulator() -> None:
    p = _plan("paper_fig6_sensed.yaml")
    assert p.controller == ["MyGpsDistance", "MyFollowerController", "MyNormalizePower"]
    assert set(p.sim_only) == {"LeaderGPS", "FollowerGPS", "FollowerCompass", "MyDistanceMonitor"}
    assert {s.topic for s in p.inbound} == {
        "/Leader/LeaderGPS/fix",
        "/Follower/FollowerGPS/fix",
        "/Follower/FollowerCompass/heading",
    }


def test_a_controller_reading_the_true_distance_has_no_side_without_the_simulator() -> None:
    # the paper's wiring: the controller reads the monitor of the true positions
    assert _plan("scenario1.yaml").controller == []


def _fix(x: float, y: float, status: int = 0) -> SimpleNamespace:
    lat, lon = enu_to_geodetic(x, y, DEFAULT_ORIGIN)
    return SimpleNamespace(status=SimpleNamespace(status=status), latitude=lat, longitude=lon)


def test_a_fix_comes_back_to_the_plane_and_a_lost_fix_is_dropped() -> None:
    src = next(s for s in _plan("paper_fig6_sensed.yaml").inbound if s.role.name == "NavSatFix")
    got = read_fields(src, _fix(123.4, -56.7), DEFAULT_ORIGIN)
    assert got is not None
    assert abs(got["x"] - 123.4) < 1e-6
    assert abs(got["y"] + 56.7) < 1e-6
    assert read_fields(src, _fix(1.0, 2.0, NO_FIX), DEFAULT_ORIGIN) is None


def test_a_heading_is_the_orientations_yaw() -> None:
    src = next(s for s in _plan("paper_fig6_sensed.yaml").inbound if s.role.name == "Heading")
    q = SimpleNamespace(**yaw_quaternion(2.5))
    got = read_fields(src, SimpleNamespace(orientation=q), DEFAULT_ORIGIN)
    assert got is not None
    assert abs(got["yaw"] - 2.5) < 1e-12
