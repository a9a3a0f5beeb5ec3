"""The parameter values ``run --ros2`` sets on a user's node carry the types ``describe
--ros2`` lists: a list of points is a double array even when it is empty (a leader without
waypoints), which rclpy alone types as a byte array, refused by a node that declared it.

The messages are built in ``.venv-ros2`` (where rclpy is), as the bridge builds them; no
node and no network are needed."""

from __future__ import annotations

import json
import subprocess

import pytest
from ros2net import PY, ROOT, ros2_missing

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

PROBE = """
import json, sys
from amsa_phys.ros.ros2.bridge import _parameter
from rcl_interfaces.msg import ParameterType
names = {v: k for k, v in vars(ParameterType).items() if k.startswith("PARAMETER_")}
out = []
for value in json.loads(sys.argv[1]):
    msg = _parameter("p", value).to_parameter_msg().value
    out.append([names[msg.type], list(msg.double_array_value)])
print(json.dumps(out))
"""


def test_each_value_is_sent_with_its_declared_type() -> None:
    values = [[], [[1, 2], [3.5, 4]], 0.35, 3, "circle", True]
    done = subprocess.run(
        [str(PY), "-c", PROBE, json.dumps(values)],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    got = json.loads(done.stdout)
    assert got == [
        ["PARAMETER_DOUBLE_ARRAY", []],  # a leader without waypoints: not a byte array
        ["PARAMETER_DOUBLE_ARRAY", [1.0, 2.0, 3.5, 4.0]],  # points, flattened
        ["PARAMETER_DOUBLE", []],
        ["PARAMETER_INTEGER", []],
        ["PARAMETER_STRING", []],
        ["PARAMETER_BOOL", []],
    ]
