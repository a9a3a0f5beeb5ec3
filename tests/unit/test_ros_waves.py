"""Lockstep waves (``ros/runtime/waves.py``): which nodes of an instant are asked together.

A node asked too early steps on inputs an earlier Leaf of the same instant has not written
yet, and the run silently differs from ``amsa-phys run``; a node left out only costs a
round trip. So the property checked is exactly the reading rule: a Leaf joins the wave iff
no Leaf due between the one stepped now and itself still writes one of its inputs at once.
"""

from __future__ import annotations

from pathlib import Path

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.graph import RosGraph, classify
from amsa_phys.ros.runtime.waves import DueAt, wave

ROOT = Path(__file__).resolve().parent.parent.parent
SENSORS = ["LeaderGPS", "FollowerGPS", "FollowerCompass", "MyDistanceMonitor"]


def _graph(*overrides: str) -> RosGraph:
    world = load_scenario(ROOT / "scenarios" / "scenario1.yaml", list(overrides)).world
    return RosGraph.of(world, classify(world))


def test_scenario1_steps_in_two_waves_an_instant() -> None:
    g = _graph()
    due = list(g.world.order)  # at t = 0 every Leaf is due
    # the sensors read only the rovers (stepped already); the actuator reads the controller
    # through its 0.75 s latency, so the controller's step now cannot change what it sees
    assert wave(g, due, "LeaderGPS") == [*SENSORS, "MyNormalizePower"]
    # the controller reads the sensors, which step at this instant: not before they have
    assert wave(g, due, "MyFollowerController") == ["MyFollowerController", "MyNormalizePower"]


def test_a_reader_of_a_producer_without_latency_waits_for_it() -> None:
    g = _graph("MyFollowerController.latency=0")
    due = list(g.world.order)
    assert wave(g, due, "LeaderGPS") == SENSORS
    assert wave(g, due, "MyFollowerController") == ["MyFollowerController"]


def test_a_simulator_leaf_still_due_at_the_instant_blocks_its_readers() -> None:
    g = _graph()
    # were the Follower (stepped in the simulator) due after LeaderGPS at an instant, its
    # readers could not be asked before it has stepped; LeaderGPS reads only the Leader
    due = ["LeaderGPS", "Follower", "FollowerGPS", "FollowerCompass", "MyDistanceMonitor"]
    assert wave(g, due, "LeaderGPS") == ["LeaderGPS"]


def test_a_writer_waits_for_an_earlier_reader_of_the_wave() -> None:
    # a loop cut by the schedule: the actuator before the controller it reads. Without
    # latency, the controller's new command must not reach the actuator's node before it
    # stepped on the old one; through the latency, it may (the node keeps the old message)
    due = ["MyNormalizePower", "MyFollowerController"]
    g = _graph("MyFollowerController.latency=0")
    assert wave(g, due, "MyNormalizePower") == ["MyNormalizePower"]
    assert wave(_graph(), due, "MyNormalizePower") == due


def test_a_writer_waits_for_a_reader_due_before_it_even_outside_the_wave() -> None:
    # the controller (not in the wave: it reads LeaderGPS, stepping now) is asked later; a
    # FollowerGPS due after it must not publish before the controller read the old fix
    g = _graph()
    due = ["LeaderGPS", "MyFollowerController", "FollowerGPS"]
    assert wave(g, due, "LeaderGPS") == ["LeaderGPS"]


def test_the_platoon_steps_its_actuators_together() -> None:
    world = load_scenario(ROOT / "scenarios" / "platoon.yaml").world
    g = RosGraph.of(world, classify(world))
    due = list(world.order)
    cars = [f"Car{k}" for k in range(1, 11)]
    assert wave(g, due, "Car1.Drive") == [f"{c}.Drive" for c in cars]
    # then each car's controller alone (the actuators, asked already, are not asked again),
    # and its sensors once it has stepped on their older values
    drives = {f"{c}.Drive" for c in cars}
    assert [p for p in wave(g, due, "Car1.Pilot") if p not in drives] == ["Car1.Pilot"]
    sensors = [p for p in wave(g, due, "Car1.Gps") if p not in drives]
    assert sensors == [f"Car1.{s}" for s in ("Gps", "AheadGps", "Compass", "Gap")]


def test_only_leaves_due_at_the_instant_are_asked() -> None:
    g = _graph()
    due = ["Leader", "LeaderGPS", "MyDistanceMonitor"]
    assert wave(g, due, "LeaderGPS") == ["LeaderGPS", "MyDistanceMonitor"]


def test_due_at_follows_each_leaf_s_period_and_phase() -> None:
    periods = {"A": 10, "B": 25, "C": 25}
    phases = {"A": 0, "B": 0, "C": 5}
    due = DueAt(["A", "B", "C"], periods.__getitem__, phases.__getitem__)
    assert due.at(0) == ["A", "B"]
    assert due.at(3) == []
    assert due.at(5) == ["C"]
    assert due.at(30) == ["A", "C"]
    assert due.at(50) == ["A", "B"]
    assert due.at(55) == ["C"]
