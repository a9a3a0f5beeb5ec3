"""ROS 2 names from amsa-phys paths: ``Team.Car3.GPS`` -> ``Team/Car3/GPS``.

A ROS 2 topic token holds letters, digits and underscores and does not start with a digit;
a world's component names already follow that rule (they are identifiers), so a path keeps
its spelling and only its dots change. Anything else (an array element's ``[3]``) becomes
an underscore: ``Lidar.ranges[3]`` -> ``Lidar/ranges_3``.
"""

from __future__ import annotations

import re

from ..model.rosnames import DATA

_BAD = re.compile(r"[^A-Za-z0-9_]")


def ros_token(text: str) -> str:
    """One valid name token for ``text`` (never empty, never starting with a digit)."""
    token = _BAD.sub("_", text.replace("]", "")).strip("_") or "_"
    return f"_{token}" if token[0].isdigit() else token


def ros_path(path: str) -> str:
    """A dotted amsa-phys path as slash-separated ROS name tokens."""
    return "/".join(ros_token(part) for part in path.split("."))


def unique(name: str, taken: set[str]) -> str:
    """``name``, or ``name_2``, ``name_3``... if taken; the result is added to ``taken``."""
    out, k = name, 1
    while out in taken:
        k += 1
        out = f"{name}_{k}"
    taken.add(out)
    return out


def data_topic(buffer: str) -> str:
    """The topic of a Data buffer's stamped scalar: ``rosnames.DATA`` then ``/<path>/<port>``."""
    return DATA + "/" + ros_path(buffer)
