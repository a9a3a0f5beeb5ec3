"""The Python Leaf node with an array input, on a stand-in of rospy (no ROS needed).

``ros/runtime/leaf.py`` is the node every non-C++ Leaf runs (and the avoider's with
``cpp:=false``). Here its lockstep protocol is driven by hand: the obstacle course's Pilot
gets a scan on ``/Scanner/ranges`` (a ``std_msgs/Float64MultiArray`` stand-in) and the pose
topics, is asked to step, and must publish the template's very powers; a scan of the wrong
length must make the step that reads it a fault naming the topic (the simulator then stops
the run with it), while the counts stay in step. Mutation-checked: the node ignoring a bad
length fails the second test; the scan read back to front fails the first.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from amsa_phys.control.avoider import ReactiveAvoider
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros import names
from amsa_phys.ros.runtime import leaf as leafnode
from amsa_phys.ros.runtime import rosio

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "obstacle_course.yaml"
_UNSET = object()


class _Msg(SimpleNamespace):
    def __init__(self, data: Any = None) -> None:
        super().__init__(data=data)


class _Pub:
    def __init__(self) -> None:
        self.sent: list[Any] = []

    def publish(self, msg: Any) -> None:
        self.sent.append(msg)

    def get_num_connections(self) -> int:
        return 0


class _Rospy:
    """The part of rospy the Leaf node uses: parameters, topics, shutdown, logging."""

    class SubscribeListener:
        pass

    def __init__(self, params: dict[str, Any]) -> None:
        self.params = params
        self.subs: dict[str, tuple[Any, Any]] = {}
        self.pubs: dict[str, _Pub] = {}
        self.errors: list[str] = []

    def get_param(self, name: str, default: Any = _UNSET) -> Any:
        if name in self.params:
            return self.params[name]
        if default is _UNSET:
            raise KeyError(name)
        return default

    def get_param_cached(self, name: str) -> Any:
        return self.params[name]

    def get_name(self) -> str:
        return "/Pilot"

    def get_master(self) -> Any:
        def get(_caller: str, name: str) -> tuple[int, str, Any]:
            return (1, "", self.params[name]) if name in self.params else (-1, "", 0)

        return SimpleNamespace(target=SimpleNamespace(getParam=get))

    def Subscriber(self, topic: str, _cls: Any, cb: Any, callback_args: Any = None, **_: Any):
        self.subs[topic] = (cb, callback_args)
        return object()

    def Publisher(self, topic: str, _cls: Any, **_: Any) -> _Pub:
        self.pubs[topic] = _Pub()
        return self.pubs[topic]

    def on_shutdown(self, _fn: Any) -> None:
        pass

    def is_shutdown(self) -> bool:
        return False

    def logerr(self, text: str) -> None:
        self.errors.append(text)

    def send(self, topic: str, msg: Any) -> None:
        cb, arg = self.subs[topic]
        cb(msg, arg) if arg is not None else cb(msg)


def _scan(values: list[float]) -> Any:
    return SimpleNamespace(data=values, layout=SimpleNamespace(data_offset=0))


@pytest.fixture
def node(monkeypatch: pytest.MonkeyPatch) -> tuple[leafnode.LeafNode, _Rospy]:
    monkeypatch.setattr(rosio, "msgs", lambda: (_Msg, _Msg, _Msg))
    monkeypatch.setattr(leafnode, "array_msg", lambda: _Msg)
    monkeypatch.setattr(leafnode, "pack", lambda _cls, _label, values: _Msg(list(values)))
    world = load_scenario(SCENARIO).world
    params: dict[str, Any] = {
        "/amsa/scenario": str(SCENARIO),
        "/amsa/mode": "lockstep",
        "/amsa/local": ["Rover", "Mud", "Parked", "Scanner"],
    }
    for name, value in world.leaves["Pilot"].params.items():
        params[names.param("Pilot", name)] = value
    rospy = _Rospy(params)
    return leafnode.LeafNode(rospy, "Pilot"), rospy


def test_the_python_node_steps_the_avoider_on_the_array_topic(node: Any) -> None:
    _, rospy = node
    ranges = [3.0 + 0.1 * i for i in range(31)]
    ranges[15] = 1.2  # an obstacle straight ahead
    rospy.send("/Scanner/ranges", _scan(ranges))
    for topic, value in (
        ("/Gps/gpsPosX", 4.0),
        ("/Gps/gpsPosY", 0.5),
        ("/Heading/compassHeading", 0.1),
    ):
        rospy.send(topic, _Msg(value))
    rospy.send(names.step_topic("Pilot"), _Msg("step 7 1 10 1 1 1 1"))
    assert rospy.pubs[names.done_topic("Pilot")].sent[-1].data == "done 7 0 1"
    comp = ReactiveAvoider("Pilot", dict(load_scenario(SCENARIO).world.leaves["Pilot"].params))
    comp.initialize(None)
    inp = {"ranges": np.array(ranges), "posX": 4.0, "posY": 0.5, "heading": 0.1}
    want = comp.do_step(0, inp)
    assert rospy.pubs["/Pilot/LeftPower"].sent[-1].data == want["LeftPower"]
    assert rospy.pubs["/Pilot/RightPower"].sent[-1].data == want["RightPower"]


def test_a_scan_of_the_wrong_length_faults_the_step_that_reads_it(node: Any) -> None:
    _, rospy = node
    done = rospy.pubs[names.done_topic("Pilot")].sent
    rospy.send(names.step_topic("Pilot"), _Msg("step 3 0 1 0 0 0 0"))  # before any scan
    assert done[-1].data == "done 3 0 1"
    rospy.send("/Scanner/ranges", _scan([5.0] * 30))
    rospy.send(names.step_topic("Pilot"), _Msg("step 4 1 10 1 0 0 0"))
    assert done[-1].data.startswith(
        "fault 4 /Scanner/ranges carried 30 values, the port declares 31"
    )
    rospy.send("/Scanner/ranges", _scan([5.0] * 31))  # the next scan is read: counts in step
    rospy.send(names.step_topic("Pilot"), _Msg("step 5 2 10 2 0 0 0"))
    assert done[-1].data == "done 5 0 1"
