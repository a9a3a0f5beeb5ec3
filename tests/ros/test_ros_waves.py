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
from amsa_phys.ros.runtime.waves import DueAt, chained, wave

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


# -- the C++ container: readers of a Leaf asked in the same message are chained -------------
CONTAINER = [*SENSORS, "MyFollowerController", "MyNormalizePower"]


def _shared(*overrides: str, shared: list[str] = CONTAINER) -> RosGraph:
    world = load_scenario(ROOT / "scenarios" / "scenario1.yaml", list(overrides)).world
    return RosGraph.of(world, classify(world), shared=shared)


def test_scenario1_in_the_container_steps_in_one_wave_an_instant() -> None:
    g = _shared()
    due = list(g.world.order)
    now = wave(g, due, "LeaderGPS")
    assert now == [*SENSORS, "MyFollowerController", "MyNormalizePower"]
    # the controller's inputs written at once by the sensors asked before it: counted as
    # "N+", the messages before the instant plus what the sensor publishes now
    assert chained(g, now, "MyFollowerController") == {
        "LeaderGPS.gpsPosX",
        "LeaderGPS.gpsPosY",
        "FollowerGPS.gpsPosX",
        "FollowerGPS.gpsPosY",
        "FollowerCompass.compassHeading",
        "MyDistanceMonitor.distanceFollowerToLeader",
    }
    assert chained(g, now, "MyNormalizePower") == set()  # through the controller's latency
    assert all(chained(g, now, s) == set() for s in SENSORS)


def test_a_writer_with_latency_is_not_chained() -> None:
    # with jitter, what the controller sees of the FollowerGPS now was sent earlier: a count
    # the simulator knows (published less in flight), not one to add the new fix to
    g = _shared("FollowerGPS.jitter=0.1")
    now = wave(g, list(g.world.order), "LeaderGPS")
    assert "MyFollowerController" in now
    assert "FollowerGPS.gpsPosX" not in chained(g, now, "MyFollowerController")


def test_a_reader_outside_the_container_is_not_chained() -> None:
    g = _shared(shared=SENSORS)  # the controller a node of its own (a Python twin)
    due = list(g.world.order)
    assert wave(g, due, "LeaderGPS") == [*SENSORS, "MyNormalizePower"]
    assert chained(g, [*SENSORS, "MyFollowerController"], "MyFollowerController") == set()


def test_a_reader_chains_only_on_writers_in_the_wave() -> None:
    # FollowerCompass reads the Follower, stepped in the simulator after LeaderGPS: it is
    # not in the wave, so the controller that reads it cannot be chained on it either
    g = _shared()
    due = ["LeaderGPS", "Follower", "FollowerCompass", "MyFollowerController"]
    assert wave(g, due, "LeaderGPS") == ["LeaderGPS"]


def test_the_platoon_in_the_container_still_steps_a_controller_before_its_sensors() -> None:
    world = load_scenario(ROOT / "scenarios" / "platoon.yaml").world
    local = classify(world)
    g = RosGraph.of(world, local, shared=[p for p in world.leaves if p not in local])
    due = list(world.order)
    cars = [f"Car{k}" for k in range(1, 11)]
    drives = {f"{c}.Drive" for c in cars}
    assert wave(g, due, "Car1.Drive")[:10] == [f"{c}.Drive" for c in cars]
    # the controller reads its sensors' older values: they must not publish before it steps
    pilot = [p for p in wave(g, due, "Car1.Pilot") if p not in drives]
    assert pilot[0] == "Car1.Pilot"
    assert not {f"Car1.{s}" for s in ("Gps", "AheadGps", "Compass", "Gap")} & set(pilot)
