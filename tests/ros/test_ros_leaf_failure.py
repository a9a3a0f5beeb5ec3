"""A C++ Leaf that fails at start fails its process, and the launch ends with its one line.

A Leaf that cannot start (a parameter out of range on the parameter server, its readers
never connecting) prints one line naming itself and the cause and shuts ROS down
(``LeafNode::fail``). Its process must then exit non-zero, whether it is the container
``amsa_leaves`` or a ``nodelet standalone`` of ``cpp_container:=false``: it used to exit 0
when the Leaf failed on its start-up thread (after its load), and ``nodelet standalone``
always did, so roslaunch reported "process has finished cleanly". And the launch must end
at once (every Leaf process is ``required``), not when some timeout runs out:
``rosrun PKG run_lockstep`` then exits 2.

The Python nodes stopped while they start (the simulator, the scenario node) say nothing, and
``run_lockstep``'s last line names the Leaf's error. Mutation-checked: without the node
script's start-up handler (``files/node.py.in``) the bad-parameter cases fail on the
KeyboardInterrupt traceback; with ``run_lockstep`` not passing what it saw to ``judge``, on
the last line.

One build of ``tests/fixtures/ros_short.yaml`` serves every case. Mutation-checked: with
``amsa_leaves``' main returning 0 after ``ros::spin()`` the container's start-up-thread case
fails (exit code 0); without ``amsa_exit.h``'s exit handler both ``nodelet standalone``
cases fail ("process has finished cleanly"). Skipped, with the reason, where ROS, catkin,
unshare or root is missing.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, package_edit, ros_missing

ROOT = Path(__file__).resolve().parent.parent.parent
PKG = "mdeChallenge"
BAD_KV = "error: /MyFollowerController: /MyFollowerController/Kv: -5 is below the minimum 0"

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture
# ros_short_workspace, ros_short_checked: the session's build of ros_short and its
# run_lockstep (tests/ros/conftest.py), edited only through ``package_edit``


def _first_death(text: str) -> tuple[str, str]:
    """roslaunch's verdict on the first required process that ended, the one that ended
    the launch: (its node name, its exit code), the code "0" for roslaunch's "process has
    finished cleanly"."""
    found = re.search(
        r"REQUIRED process \[(\w+)-\d+\] has died!\n"
        r"process has (?:died \[pid \d+, exit code (-?\d+)|finished cleanly)",
        text,
    )
    assert found is not None, text[-3000:]
    return found.group(1), found.group(2) or "0"


def _no_crash(text: str) -> None:
    """The Leaf's line is the whole story: no C++ exception, no abort."""
    for sign in ("terminate called", "what():", "Aborted", "core dumped", "Segmentation"):
        assert sign not in text, text[-3000:]


@pytest.mark.parametrize("container", ["true", "false"])
def test_a_bad_parameter_fails_the_leaf_process_and_run_lockstep(
    ros_short_workspace: Path,
    ros_short_checked: Path,
    launcher: Callable[..., Launch],
    container: str,
    tmp_path: Path,
) -> None:
    """Kv out of range in the params file: the C++ controller refuses it at load, its
    process (the container, or its own ``nodelet standalone``) exits 2, the launch ends,
    and ``rosrun PKG run_lockstep`` exits 2. ``timeout:=600``: a launch that waited for
    some timeout instead would be killed by the test's watchdog (120 s) and fail."""
    params = ros_short_workspace / "src" / PKG / "config" / "ros_short_params.yaml"
    original = params.read_text()
    assert original.count("  Kv: 0.1\n") == 1
    with package_edit(params, original.replace("  Kv: 0.1\n", "  Kv: -5.0\n")):
        out = tmp_path / f"bad-{container}"
        launch = launcher(
            ros_short_checked,
            "ros_short.launch",
            f"out:={out}",
            "plots:=false",
            "timeout:=600",
            f"cpp_container:={container}",
        )
        text = launch.finish()
    assert launch.proc.returncode == 2, text[-3000:]
    assert text.count(BAD_KV) == 1, text[-3000:]
    process = "amsa_leaves" if container == "true" else "MyFollowerController"
    assert _first_death(text) == (process, "2"), text[-3000:]
    # the Leaf's line is the one error: the Python nodes roslaunch stopped while they were
    # starting end at once and quietly (no KeyboardInterrupt traceback, no node that only
    # roslaunch's SIGTERM or SIGKILL ends), and run_lockstep's last line names the cause
    assert "Traceback" not in text, text[-3000:]
    assert "escalating to SIGTERM" not in text, text[-3000:]
    # (the simulator, if it got as far as reading the parameters, says Kv is out of range
    # too: the Leaf's line is still the first)
    last = (
        re.escape(f"run_lockstep: no run in {out} (metrics.json missing): the run did not start: ")
        + r"see the (?:error above \(|\d errors above \(the first: )"
    )
    last += re.escape(f"{BAD_KV.removeprefix('error: ')})")
    assert re.fullmatch(last, text.rstrip().splitlines()[-1]), text[-3000:]
    _no_crash(text)


@pytest.mark.parametrize("container", ["true", "false"])
def test_a_leaf_failing_on_its_start_up_thread_fails_its_process(
    ros_short_workspace: Path, launcher: Callable[..., Launch], container: str
) -> None:
    """No simulator in the launch file: each C++ Leaf loads, then gives up on its start-up
    thread after 2 × ``timeout`` waiting for its readers. The first to give up ends its
    process with exit code 2 (the container's main used to return 0 then) and the launch."""
    launch_dir = ros_short_workspace / "src" / PKG / "launch"
    original = (launch_dir / "ros_short.launch").read_text()
    nosim = re.sub(r'  <node [^>]*type="amsa_simulator.py".*?</node>\n', "", original, flags=re.S)
    nosim = re.sub(r'  <node [^>]*type="amsa_scenario.py"[^>]*/>\n', "", nosim)
    assert "amsa_simulator.py" not in nosim
    assert "amsa_scenario.py" not in nosim
    name = f"ros_short_nosim_{container}.launch"
    with package_edit(launch_dir / name, nosim):
        launch = launcher(ros_short_workspace, name, "timeout:=0.5", f"cpp_container:={container}")
        text = launch.finish()
    assert launch.proc.returncode == 0  # roslaunch's own: 0 whatever its nodes did
    gave_up = re.findall(r"error: /(\w+): gave up after \d+\.\d s waiting for the readers of", text)
    assert gave_up, text[-3000:]
    # cpp_container:=false: a process per Leaf, several may give up at once
    processes = ["amsa_leaves"] if container == "true" else gave_up
    process, code = _first_death(text)
    assert process in processes, text[-3000:]
    assert code == "2", text[-3000:]
    _no_crash(text)
