"""The names amsa-phys takes on a ROS graph (ROS 1 and ROS 2), and what a name may be.

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
#: Names a top-level component may not take (the framework's nodes and namespaces).
RESERVED = {
    "amsa",
    SIMULATOR,
    SCENARIO,
    "clock",
    "rosout",
    "rosout_agg",
    "amsa_bag",
    "amsa_boundary",  # the boundary node
    "amsa_adapt",  # the adapt node
    CONTAINER,
}
