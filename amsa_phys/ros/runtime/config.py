"""What every node reads at start: the scenario file and the graph's settings under ``/amsa``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ...errors import ConfigError
from ...model.scenario import Scenario, load_scenario
from ..graph import RosGraph

MODES = ("lockstep", "free")


@dataclass
class NodeConfig:
    """The launch's ``/amsa/*`` parameters and the scenario they point to."""

    scenario: Scenario
    graph: RosGraph
    mode: str
    timeout: float
    #: lockstep with the simulator: the adapt node runs the ``adapt:`` rules, asked by the
    #: simulator at each instant (``rules:=node``), rather than the simulator itself
    rules_node: bool = False
    #: lockstep with every remote Leaf in the C++ container: many instants a message, each
    #: answer checked against the Leaf's in-process template (``pipeline.py``)
    pipeline: bool = False


def load_config(rospy: Any) -> NodeConfig:
    """Read ``/amsa/{scenario,mode,local,bag,timeout,container,rules,pipeline}``; load the
    scenario."""
    try:
        path = rospy.get_param("/amsa/scenario")
        mode = rospy.get_param("/amsa/mode", "lockstep")
        local = rospy.get_param("/amsa/local", [])
        bag = bool(rospy.get_param("/amsa/bag", False))
        timeout = float(rospy.get_param("/amsa/timeout", 60.0))
        shared = rospy.get_param("/amsa/container", [])  # the C++ Leaves in one process
    except KeyError as exc:
        raise ConfigError(
            "is not on the parameter server (start the nodes with roslaunch)", key=str(exc)
        ) from None
    if mode not in MODES:
        raise ConfigError(f"expected lockstep or free, got {mode!r}", key="/amsa/mode")
    scenario = load_scenario(path)
    rules = str(rospy.get_param("/amsa/rules", "sim"))
    if rules not in ("sim", "node"):
        raise ConfigError(f"expected sim or node, got {rules!r}", key="/amsa/rules")
    sim = bool(rospy.get_param("/amsa/sim", True))
    node = rules == "node" and bool(scenario.adapt) and sim and mode == "lockstep"
    signals = sorted({c.signal for r in scenario.adapt for c in r.when}) if node else []
    graph = RosGraph.of(scenario.world, local, bag, shared, signals)
    pipeline = (
        bool(rospy.get_param("/amsa/pipeline", False))
        and mode == "lockstep"
        and sim
        and not bag
        and not bool(rospy.get_param("/amsa/boundary", False))
        and not node
        and set(graph.remote) == set(graph.shared)
    )
    return NodeConfig(scenario, graph, mode, timeout, node, pipeline)
