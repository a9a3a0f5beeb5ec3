"""``sim:=false``: a robot's drivers' messages are input from outside. The boundary drops a
message whose numbers are not finite (a NaN latitude, an infinite quaternion) or a scan it
cannot fit in bounded time, as it drops a lost fix: a NaN reaching the controller side went
on to the wheel commands. A scan's no-return (inf) and erroneous (NaN) ranges read as
nothing within reach."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.boundary import MAX_SCAN_RANGES, plan, read_fields
from amsa_phys.ros.graph import RosGraph, classify
from amsa_phys.ros.runtime.arrays import ScanShape
from amsa_phys.stdmsgs import DEFAULT_ORIGIN, enu_to_geodetic, yaw_quaternion

ROOT = Path(__file__).resolve().parent.parent.parent
NAN, INF = math.nan, math.inf


def _source(scenario: str, role: str):  # type: ignore[no-untyped-def]
    world = load_scenario(ROOT / "scenarios" / scenario).world
    inbound = plan(RosGraph.of(world, classify(world))).inbound
    return next(s for s in inbound if s.role.name == role)


def _fix(lat: float, lon: float) -> SimpleNamespace:
    return SimpleNamespace(status=SimpleNamespace(status=0), latitude=lat, longitude=lon)


@pytest.mark.parametrize(("lat", "lon"), [(NAN, 0.0), (0.0, INF), (-INF, 0.0), (NAN, NAN)], ids=str)
def test_a_fix_that_is_not_finite_is_dropped(lat: float, lon: float) -> None:
    src = _source("paper_fig6_sensed.yaml", "NavSatFix")
    good_lat, good_lon = enu_to_geodetic(3.0, 4.0, DEFAULT_ORIGIN)
    assert read_fields(src, _fix(good_lat, good_lon), DEFAULT_ORIGIN) is not None
    real_lat = good_lat if math.isfinite(lat) else lat
    real_lon = good_lon if math.isfinite(lon) else lon
    assert read_fields(src, _fix(real_lat, real_lon), DEFAULT_ORIGIN) is None


@pytest.mark.parametrize("bad", ["z", "w"])  # the yaw reads z and w
def test_a_heading_that_is_not_finite_is_dropped(bad: str) -> None:
    src = _source("paper_fig6_sensed.yaml", "Heading")
    q = {**yaw_quaternion(1.0), bad: NAN}
    assert (
        read_fields(src, SimpleNamespace(orientation=SimpleNamespace(**q)), DEFAULT_ORIGIN) is None
    )


def _scan(ranges: list[float], **over: float) -> SimpleNamespace:
    fields = {
        "angle_min": -math.pi,
        "angle_increment": 2 * math.pi / max(1, len(ranges)),
        "range_min": 0.1,
        "range_max": 30.0,
        **over,
    }
    return SimpleNamespace(ranges=ranges, **fields)


def test_a_scan_without_a_declared_shape_reads_nan_and_inf_as_out_of_reach() -> None:
    src = _source("obstacle_course.yaml", "LaserScan")
    got = read_fields(src, _scan([5.0, NAN, INF, -INF, 50.0]), DEFAULT_ORIGIN)
    assert got == {"ranges": [5.0, 30.0, 30.0, 0.1, 30.0]}


@pytest.mark.parametrize(
    "over", [{"angle_min": NAN}, {"angle_increment": INF}, {"range_max": NAN}], ids=str
)
def test_a_scan_whose_geometry_is_not_finite_is_dropped(over: dict[str, float]) -> None:
    src = _source("obstacle_course.yaml", "LaserScan")
    shape = ScanShape((-1.0, 0.0, 1.0), 0.1, 30.0)
    assert read_fields(src, _scan([1.0] * 360, **over), DEFAULT_ORIGIN, shape) is None


def test_a_scan_too_long_to_fit_is_dropped_not_fitted() -> None:
    src = _source("obstacle_course.yaml", "LaserScan")
    shape = ScanShape(tuple(i / 100 for i in range(360)), 0.1, 30.0)
    huge = _scan([1.0] * (MAX_SCAN_RANGES + 1))  # fitting would cost 360 x 65,537 steps
    assert read_fields(src, huge, DEFAULT_ORIGIN, shape) is None
    assert read_fields(src, _scan([1.0] * 720), DEFAULT_ORIGIN, shape) is not None
