"""What every node reads at start: the scenario file and the graph's settings under
``rosnames.NAMESPACE``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ...errors import ConfigError
from ...model.scenario import Scenario, load_scenario
from .. import names
from ..graph import RosGraph

MODES = ("lockstep", "free")


@dataclass
class NodeConfig:
    """The launch's graph-wide parameters (``rosnames.P_*``) and the scenario they point to."""

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
    """Read the graph-wide parameters (scenario, mode, local, bag, timeout, container, rules,
    pipeline, sim, boundary: ``rosnames.P_*``); load the
    scenario."""
    try:
        path = rospy.get_param(names.P_SCENARIO)
        mode = rospy.get_param(names.P_MODE, "lockstep")
        local = rospy.get_param(names.P_LOCAL, [])
        bag = bool(rospy.get_param(names.P_BAG, False))
        timeout = float(rospy.get_param(names.P_TIMEOUT, 60.0))
        shared = rospy.get_param(names.P_CONTAINER, [])  # the C++ Leaves in one process
    except KeyError as exc:
        raise ConfigError(
            "is not on the parameter server (start the nodes with roslaunch)", key=str(exc)
        ) from None
    if mode not in MODES:
        raise ConfigError(f"expected lockstep or free, got {mode!r}", key=names.P_MODE)
    scenario = load_scenario(path)
    rules = str(rospy.get_param(names.P_RULES, "sim"))
    if rules not in ("sim", "node"):
        raise ConfigError(f"expected sim or node, got {rules!r}", key=names.P_RULES)
    sim = bool(rospy.get_param(names.P_SIM, True))
    node = rules == "node" and bool(scenario.adapt) and sim and mode == "lockstep"
    signals = sorted({c.signal for r in scenario.adapt for c in r.when}) if node else []
    graph = RosGraph.of(scenario.world, local, bag, shared, signals)
    pipeline = (
        bool(rospy.get_param(names.P_PIPELINE, False))
        and mode == "lockstep"
        and sim
        and not bag
        and not bool(rospy.get_param(names.P_BOUNDARY, False))
        and not node
        and set(graph.remote) == set(graph.shared)
    )
    return NodeConfig(scenario, graph, mode, timeout, node, pipeline)
