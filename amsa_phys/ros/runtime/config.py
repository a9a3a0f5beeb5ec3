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


def load_config(rospy: Any) -> NodeConfig:
    """Read ``/amsa/{scenario,mode,local,bag,timeout,container}`` and load the scenario."""
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
    return NodeConfig(scenario, RosGraph.of(scenario.world, local, bag, shared), mode, timeout)
