"""Array ports in the exported package: their topics, the length check, a robot's scan fitted.

``ros/graph.py`` names an array port's topic once (``/Scanner/ranges``, not per element),
``ros/runtime/arrays.py`` checks a message's length against the port's and fits a driver's
``LaserScan`` onto the lidar Leaf's beams. No ROS needed: messages are stand-ins.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.boundary import plan
from amsa_phys.ros.graph import RosGraph, classify
from amsa_phys.ros.runtime.arrays import ScanShape, elements, fit_scan, unpack

ROOT = Path(__file__).resolve().parent.parent.parent


@pytest.fixture(scope="module")
def graph() -> RosGraph:
    world = load_scenario(ROOT / "scenarios" / "obstacle_course.yaml").world
    return RosGraph.of(world, classify(world))


def test_an_array_port_is_one_topic_in_trace_order(graph: RosGraph) -> None:
    data = graph.data()
    assert "Scanner.ranges" in data
    assert not [d for d in data if "[" in d]  # "/Scanner/ranges[0]" is no legal ROS name
    assert data.index("Scanner.ranges") == data.index("Parked.wheelSpeedR") + 1
    assert graph.is_array("Scanner.ranges")
    assert graph.size("Scanner.ranges") == 31
    assert graph.size("Gps.gpsPosX") == 1
    assert graph.initial("Scanner.ranges") == (0.0,) * 31
    assert graph.producer("Scanner.ranges") == "Scanner"
    # the avoider reads it; the simulator (the Lidar's home) publishes it to that one reader
    assert graph.input_buffers("Pilot")[0] == "Scanner.ranges"
    assert graph.subscribers("Scanner.ranges") == 1


def test_the_pilot_runs_on_a_robot_from_its_laserscan(graph: RosGraph) -> None:
    """sim:=false: the Lidar steps in the simulator, yet its LaserScan is read in."""
    p = plan(graph)
    assert p.controller == ["Pilot", "Drive"]
    assert "/Rover/Scanner/scan" in {s.topic for s in p.inbound}


def _msg(data: list[float], offset: int = 0) -> SimpleNamespace:
    return SimpleNamespace(data=data, layout=SimpleNamespace(data_offset=offset))


def test_a_message_of_another_length_is_an_error_naming_the_topic() -> None:
    assert unpack(_msg([1.0, 2.0, 3.0]), 3, "/Scanner/ranges") == (1.0, 2.0, 3.0)
    assert unpack(_msg([9.0, 1.0, 2.0], offset=1), 2, "/Scanner/ranges") == (1.0, 2.0)
    with pytest.raises(ValueError, match=r"/Scanner/ranges carried 2 values, the port declares 3"):
        unpack(_msg([1.0, 2.0]), 3, "/Scanner/ranges")


def test_elements_spread_an_array_over_its_buffers(graph: RosGraph) -> None:
    arrays = graph.world.arrays
    pairs = elements(arrays, "Scanner.ranges", [float(i) for i in range(31)])
    assert pairs[0] == ("Scanner.ranges[0]", 0.0)
    assert pairs[30] == ("Scanner.ranges[30]", 30.0)
    assert elements(arrays, "Gps.gpsPosX", 1.5) == [("Gps.gpsPosX", 1.5)]


SHAPE = ScanShape.of(
    {"beams": 5, "angle_min": -math.pi / 2, "angle_max": math.pi / 2, "range_min": 0.15}
    | {"range_max": 12.0}
)


def _scan(ranges: list[float], angle_min: float, inc: float) -> SimpleNamespace:
    return SimpleNamespace(
        ranges=ranges, angle_min=angle_min, angle_increment=inc, range_min=0.1, range_max=30.0
    )


def test_a_scan_of_the_declared_shape_passes_beam_for_beam() -> None:
    scan = _scan([1.0, 2.0, 3.0, 4.0, 5.0], -math.pi / 2, math.pi / 4)
    assert fit_scan(scan, SHAPE) == [1.0, 2.0, 3.0, 4.0, 5.0]


def test_a_full_circle_driver_scan_gives_the_nearest_return_in_each_beams_sector() -> None:
    n = 360
    inc = 2 * math.pi / n
    ranges = [math.inf] * n  # nothing echoes: drivers publish inf
    ranges[180] = 7.0  # straight ahead (angle -pi + 180 * inc = 0)
    ranges[185] = 3.0  # 5 degrees left: within the middle beam's +-22.5 degree sector
    ranges[90] = 0.05  # right (-90 degrees): below the driver's range_min, not an echo
    ranges[91] = 40.0  # beyond the driver's range_max: no echo either
    ranges[270] = 0.12  # left (+90 degrees): an echo closer than the Leaf's range_min
    got = fit_scan(_scan(ranges, -math.pi, inc), SHAPE)
    assert got == [12.0, 12.0, 3.0, 12.0, 0.15]
