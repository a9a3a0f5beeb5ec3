"""The names amsa-phys takes on a ROS graph (ROS 1 and ROS 2), and what a name may be.

The one registry of the framework's own names: every topic and graph-wide parameter under the
framework's namespace is spelled here and nowhere else in the package (a test scans the package,
the C++ headers and file templates included). Python reads the constants; generated files get
them through a template hole of their key in :data:`FRAMEWORK` (``@@{p_seed:cpp_string}``),
filled by the typed escapers of ``ros/quote.py``, so renaming one is one edit.

Here, below the ROS layer, because the scenario loader judges ``ros2:`` Leaf names with
them (``model/externals.py``); ``ros/names.py`` builds every topic and parameter name on top.
"""

from __future__ import annotations

import re

#: A ROS graph resource base name: a letter, then letters, digits and underscores.
BASE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
SIMULATOR = "amsa_simulator"
SCENARIO = "amsa_scenario"
#: The process that hosts every C++ Leaf (a nodelet manager: ros/files/amsa_leaves.cpp).
CONTAINER = "amsa_leaves"
#: The ``bag:=`` recorder (ros/runtime/bagrecord.py).
BAG = "amsa_bag"
#: Names a top-level component may not take (the framework's nodes and namespaces).
RESERVED = {
    "amsa",
    SIMULATOR,
    SCENARIO,
    "clock",
    "rosout",
    "rosout_agg",
    BAG,
    "amsa_boundary",  # the boundary node
    "amsa_adapt",  # the adapt node
    CONTAINER,
}

#: The namespace of the framework's own topics and graph-wide parameters (a launch file's
#: ``<group ns=...>`` takes its base name, :data:`NAMESPACE_BASE`).
NAMESPACE = "/amsa"
NAMESPACE_BASE = "amsa"

# -- topics ---------------------------------------------------------------------------------
#: Latched start-up handshake: a node says here that its publishers have their subscribers.
READY = "/amsa/ready"
#: The scenario node's count of the timeline points it has applied.
PHASE = "/amsa/phase"
#: Lockstep requests and answers: a Leaf's are these plus its node name (``/amsa/step/A/B``).
STEP = "/amsa/step"
DONE = "/amsa/done"
#: The C++ container's one request and one answer topic for a whole wave of its Leaves.
STEP_CONTAINER = "/amsa/step/" + CONTAINER
DONE_CONTAINER = "/amsa/done/" + CONTAINER
#: Where ``ros2 lockstep`` delivers a node's inputs: this plus the node and port.
IN = "/amsa/in"
#: A bag's stamped scalar of a Data buffer: this plus the buffer's path and port.
DATA = "/amsa/data"
#: A bag's timeline events (phase starts, changes, rule switches).
EVENTS = "/amsa/events"
#: ``boundary:=true``: the simulator's values for the boundary node, and its flush answers.
BOUNDARY_VALUES = "/amsa/boundary/values"
BOUNDARY_FLUSHED = "/amsa/boundary/flushed"
#: ``bag:=``: the simulator's count of each topic's messages at the run's end, and the
#: recorder's answer once it has written as many (``ros/runtime/bagrecord.py``).
BAG_FLUSH = "/amsa/bag/flush"
BAG_WRITTEN = "/amsa/bag/written"

# -- graph-wide parameters (the launch file's group of :data:`NAMESPACE_BASE`) -----------------
P_SCENARIO = "/amsa/scenario"
P_MODE = "/amsa/mode"
P_LOCAL = "/amsa/local"
P_BAG = "/amsa/bag"
P_TIMEOUT = "/amsa/timeout"
P_CONTAINER = "/amsa/container"
P_RULES = "/amsa/rules"
P_SIM = "/amsa/sim"
P_PIPELINE = "/amsa/pipeline"
P_BOUNDARY = "/amsa/boundary"
P_SEED = "/amsa/seed"

#: Every framework name by the key a template hole uses (``@@{ready:cpp_string}``).
FRAMEWORK: dict[str, str] = {
    "namespace": NAMESPACE,
    "ready": READY,
    "phase": PHASE,
    "step": STEP,
    "done": DONE,
    "step_container": STEP_CONTAINER,
    "done_container": DONE_CONTAINER,
    "in": IN,
    "data": DATA,
    "events": EVENTS,
    "boundary_values": BOUNDARY_VALUES,
    "boundary_flushed": BOUNDARY_FLUSHED,
    "bag_flush": BAG_FLUSH,
    "bag_written": BAG_WRITTEN,
    "p_scenario": P_SCENARIO,
    "p_mode": P_MODE,
    "p_local": P_LOCAL,
    "p_bag": P_BAG,
    "p_timeout": P_TIMEOUT,
    "p_container": P_CONTAINER,
    "p_rules": P_RULES,
    "p_sim": P_SIM,
    "p_pipeline": P_PIPELINE,
    "p_boundary": P_BOUNDARY,
    "p_seed": P_SEED,
}
