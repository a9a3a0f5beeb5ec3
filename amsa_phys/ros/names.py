"""ROS names for the model's things: a Leaf is a node, a Data a topic, a Parameter a parameter.

A Leaf ``Team.Leader`` is the node ``/Team/Leader``; its output ``posX`` is the topic
``/Team/Leader/posX`` (``std_msgs/Float64``) and its parameter ``x`` the parameter
``/Team/Leader/x`` — the node's private names (``~posX``, ``~x``). The framework's own topics
live under ``rosnames.NAMESPACE`` (every one spelled only in ``model/rosnames.py``); the
simulator and scenario nodes are ``/amsa_simulator`` and ``/amsa_scenario``.
"""

from __future__ import annotations

from ..errors import ConfigError
from ..model.filenames import file_name_problem, shown

# the names amsa-phys itself takes on a ROS graph, both targets' (model/rosnames.py: the
# scenario loader judges ros2: names with them, below this layer)
from ..model.rosnames import (
    BAG,
    BASE,
    CONTAINER,
    DONE,
    IN,
    P_BAG,
    P_BOUNDARY,
    P_CONTAINER,
    P_LOCAL,
    P_MODE,
    P_PIPELINE,
    P_RULES,
    P_SCENARIO,
    P_SEED,
    P_SIM,
    P_TIMEOUT,
    PHASE,
    READY,
    RESERVED,
    SCENARIO,
    SIMULATOR,
    STEP,
)
from ..model.world import WorldSpec

__all__ = [
    "BAG",
    "BASE",
    "CONTAINER",
    "PHASE",
    "P_BAG",
    "P_BOUNDARY",
    "P_CONTAINER",
    "P_LOCAL",
    "P_MODE",
    "P_PIPELINE",
    "P_RULES",
    "P_SCENARIO",
    "P_SEED",
    "P_SIM",
    "P_TIMEOUT",
    "READY",
    "RESERVED",
    "SCENARIO",
    "SIMULATOR",
]
#: The package's script that launches a scenario and exits with its verdict (``runcheck.py``).
RUN_LOCKSTEP = "run_lockstep"

CLOCK = "/clock"


def ns(path: str) -> str:
    """``Team.Leader`` -> ``/Team/Leader``."""
    return "/" + path.replace(".", "/")


def topic(buffer: str) -> str:
    """The topic of a Data buffer ``Component.output``."""
    return ns(buffer)


def input_topic(path: str, port: str) -> str:
    """Where ``ros2 lockstep`` delivers a node's input ``port`` (remapped from the producer's
    topic): ``rosnames.IN`` then ``/Team/Leader/port``."""
    return IN + ns(path) + "/" + port


def param(path: str, name: str) -> str:
    """The ROS parameter of a Leaf's parameter."""
    return f"{ns(path)}/{name}"


def step_topic(path: str) -> str:
    """Where the simulator tells a node to step (lockstep)."""
    return STEP + ns(path)


def done_topic(path: str) -> str:
    """Where a node says it has stepped (lockstep)."""
    return DONE + ns(path)


def script(path: str) -> str:
    """The file name (without extension) of a Leaf's node: ``Team__Leader``."""
    return path.replace(".", "__")


def check_world(world: WorldSpec) -> None:
    """Every component, output and parameter name must be a valid ROS name, and a Leaf's path
    short enough to name its node's file (else one line)."""
    for path, leaf in world.leaves.items():
        parts = path.split(".")
        for part in parts:
            if not BASE.match(part):
                raise ConfigError(
                    f"{part!r} is not a valid ROS name (a letter, then letters, digits, _)",
                    key=f"component {path}",
                )
        # the node's script is named after the whole path
        if (why := file_name_problem(script(path), "the node's file name")) is not None:
            raise ConfigError(f"{why}: shorten the names", key=f"component {shown(path)}")
        if parts[0] in RESERVED:
            raise ConfigError(
                f"{parts[0]!r} is a name the ROS package uses itself; rename the component",
                key=f"component {path}",
            )
        for what, names in (
            ("output", [p.name for p in leaf.template.outputs]),
            ("parameter", [p.name for p in leaf.template.params]),
        ):
            for name in names:
                if not BASE.match(name):
                    raise ConfigError(
                        f"{what} {name!r} of template {leaf.template.name()} is not a valid "
                        "ROS name",
                        key=f"component {path}",
                    )
