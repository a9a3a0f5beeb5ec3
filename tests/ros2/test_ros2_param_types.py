"""The parameter values ``run --ros2`` sets on a node, and those an exported node declares,
carry the types ``describe --ros2`` lists: a list of points is a double array even when it is
empty (a leader without waypoints), which rclpy alone types as a byte array, so a node that
declared it refused the value, and an exported node declared it so.

Built in ``.venv-ros2`` (where rclpy is); the declaring node in a private network."""

from __future__ import annotations

import json
import shlex
import subprocess
from pathlib import Path

import pytest
from ros2net import PY, ROOT, in_private_network, ros2_missing

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


DECLARE = """
import json, sys
import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from amsa_phys.model.params import Param
from amsa_phys.ros.ros2.bridge import _parameter
from amsa_phys.ros.ros2.leafnode import declare
rclpy.init()
node = Node("probe")
param = Param("waypoints", "points", "the points", ())
declare(node, param, [])
declared = node.get_parameter("waypoints")
result = node.set_parameters([_parameter("waypoints", [[1, 2]])])[0]
print(json.dumps([declared.type_.name, list(declared.value), result.successful,
                  list(node.get_parameter("waypoints").value)]))
node.destroy_node()
rclpy.shutdown()
"""


def test_an_exported_node_declares_empty_points_as_the_double_array_it_is_sent(
    tmp_path: Path,
) -> None:
    script = tmp_path / "probe.sh"
    out = tmp_path / "probe.out"
    cmd = " ".join(shlex.quote(str(a)) for a in [PY, "-c", DECLARE])
    script.write_text(f"set -e\nip link set lo up\ncd {shlex.quote(str(ROOT))}\n{cmd} >{out}\n")
    rc, left = in_private_network(script, {}, log=tmp_path / "probe.log")
    assert rc == 0, (tmp_path / "probe.log").read_text()
    assert left == []
    declared_type, declared, accepted, now = json.loads(out.read_text())
    assert declared_type == "DOUBLE_ARRAY"
    assert declared == []
    assert accepted  # the bridge's value fits the declared type
    assert now == [1.0, 2.0]
