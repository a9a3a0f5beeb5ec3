"""Array ports over ROS: a lidar's ranges as one topic, and a robot's scan fitted to the lidar.

A Data buffer holds one number, so an array port (``Port(array=True)``: a Lidar's
``ranges``) is as many buffers in the engine and the trace (``Scanner.ranges[i]``). In the
exported package it is ONE topic, named after the port (``/Scanner/ranges``), of type
``std_msgs/Float64MultiArray``: one layout dimension labelled with the port's name, ``size``
and ``stride`` the port's length, ``data_offset`` 0, the doubles in element order (beam
order for a lidar). The length is fixed by the world (a Lidar's ``beams``, as the trace's
columns are) and checked on receipt: a message of another length is an error naming the
topic. At the robot boundary the lidar is a ``sensor_msgs/LaserScan``; a driver's scan has
its own beam count, so :func:`fit_scan` maps it onto the declared beams.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .. import names


def array_msg() -> Any:
    """``std_msgs/Float64MultiArray``: the message of an array port's topic."""
    from std_msgs.msg import Float64MultiArray

    return Float64MultiArray


def pack(cls: Any, label: str, values: Any) -> Any:
    """An array port's value as its topic carries it: one dimension, labelled with the port's
    name, ``size`` = ``stride`` = the length, ``data_offset`` 0, the doubles in beam order."""
    from std_msgs.msg import MultiArrayDimension

    data = [float(v) for v in values]
    msg = cls()
    msg.layout.dim = [MultiArrayDimension(label, len(data), len(data))]
    msg.layout.data_offset = 0
    msg.data = data
    return msg


def unpack(msg: Any, size: int, topic: str) -> tuple[float, ...]:
    """An array topic's doubles, checked against the port's declared length (else
    ``ValueError`` naming the topic: the length is fixed by the world, as the trace's
    columns are)."""
    data = tuple(msg.data)[msg.layout.data_offset :]
    if len(data) != size:
        raise ValueError(
            f"{topic} carried {len(data)} values, the port declares {size} "
            "(std_msgs/Float64MultiArray of fixed length)"
        )
    return data


def read(graph: Any, data: str, msg: Any) -> tuple[Any, str]:
    """A Data topic's message as its value (an array port's: a tuple, checked), and ``""``;
    or ``(None, why)`` for an array of the wrong length (``graph``: a ``RosGraph``)."""
    if not graph.is_array(data):
        return msg.data, ""
    try:
        return unpack(msg, graph.size(data), names.topic(data)), ""
    except ValueError as exc:
        return None, str(exc)


def elements(arrays: Mapping[str, list[str]], data: str, value: Any) -> list[tuple[str, Any]]:
    """``(buffer, value)`` pairs of one Data's value: an array port's elements, or itself."""
    if data in arrays:
        return list(zip(arrays[data], value, strict=True))
    return [(data, value)]


@dataclass(frozen=True)
class ScanShape:
    """A lidar Leaf's declared scan: its beams' directions and its range limits."""

    angles: tuple[float, ...]
    range_min: float
    range_max: float

    @classmethod
    def of(cls, p: Mapping[str, Any]) -> ScanShape:
        """From the Lidar's parameters (``beams``, ``angle_min``/``angle_max``, ranges)."""
        n, lo, hi = int(p["beams"]), float(p["angle_min"]), float(p["angle_max"])
        angles = [lo] if n == 1 else [lo + (hi - lo) * i / (n - 1) for i in range(n)]
        return cls(tuple(angles), float(p["range_min"]), float(p["range_max"]))


def fit_scan(msg: Any, shape: ScanShape) -> list[float]:
    """A robot's ``LaserScan`` as the lidar Leaf's ranges: one per declared beam.

    The array port's length is the world's (a driver's 360 or 720 beams are not), so each
    declared beam takes the nearest return among the driver's beams within half a declared
    beam spacing of its direction (the obstacle nearest along it: what an avoider must not
    miss); none, or none valid (``inf``, NaN, outside the driver's ``[range_min,
    range_max]``), reads the Leaf's ``range_max``, as its own no-echo beam does. A return is
    clipped to the Leaf's ``[range_min, range_max]``. A scan with the declared beams at the
    declared angles passes through beam for beam.
    """
    ranges = list(msg.ranges)
    n = len(shape.angles)
    spacing = (shape.angles[-1] - shape.angles[0]) / (n - 1) if n > 1 else 0.0
    half = max(spacing / 2, abs(float(msg.angle_increment)) / 2) * (1 + 1e-6)
    out = []
    for a in shape.angles:
        best = math.inf
        for j, r in enumerate(ranges):
            angle = float(msg.angle_min) + j * float(msg.angle_increment)
            off = abs(math.remainder(angle - a, 2 * math.pi))
            if off <= half and msg.range_min <= r <= msg.range_max and r < best:
                best = r
        out.append(
            shape.range_max
            if math.isinf(best)
            else min(shape.range_max, max(shape.range_min, best))
        )
    return out
