"""How many subscribers a node waits for before it says it is ready (``RosGraph.subscribers``).

ROS 1 drops what is published before a subscriber connects, so every node waits until each
of its publishers has the subscribers the graph says it will have. ROS counts *processes*:
roscpp subscribes a process once per topic, however many of its Leaves read it, and the
master registers it as one node. A count too high and the run never starts; too low and a
node starts publishing before a reader is connected, and that reader misses a message.
"""

from __future__ import annotations

from pathlib import Path

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.graph import RosGraph, classify

ROOT = Path(__file__).resolve().parents[2]
CPP = [
    "LeaderGPS",
    "FollowerGPS",
    "FollowerCompass",
    "MyDistanceMonitor",
    "MyFollowerController",
    "MyNormalizePower",
]


def _graph(shared: list[str]) -> RosGraph:
    world = load_scenario(ROOT / "scenarios" / "scenario1.yaml").world
    return RosGraph.of(world, classify(world), shared=shared)


def test_a_process_per_leaf_counts_each_reader() -> None:
    g = _graph([])
    # the Leader's x: LeaderGPS and MyDistanceMonitor read it (the simulator publishes it)
    assert g.subscribers("Leader.posX") == 2
    # the controller's command: the actuator, and the simulator (the trace)
    assert g.subscribers("MyFollowerController.LeftPower") == 2


def test_the_container_counts_once_however_many_of_its_leaves_read() -> None:
    g = _graph(CPP)
    assert g.subscribers("Leader.posX") == 1  # two Leaves, one process
    # the actuator reads it inside the container (one intra-process subscriber), and the
    # simulator from its own process
    assert g.subscribers("MyFollowerController.LeftPower") == 2
    # a Leaf left out of the container (its own node) is its own subscriber again
    assert _graph(CPP[1:]).subscribers("Leader.posX") == 2
