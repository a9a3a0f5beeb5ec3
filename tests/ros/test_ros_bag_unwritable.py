"""``bag:=`` naming a file that cannot be written stops the launch at once, saying why.

The recorder is a required node: when it cannot open its bag it prints one line naming the
file and the reason, and roslaunch ends the run there, instead of the simulator waiting for a
recorder that never connects until its start-up deadline. Mutation-checked: without
``required="true"`` on the recorder the launch waits for it (the simulator's "waiting" line
appears; the run never says the recorder failed it) and ends only at the deadline.
The package is the session's build of ``ros_short.yaml`` (``ros_short_workspace``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, ros_missing

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


def test_an_unwritable_bag_stops_the_launch_naming_the_file(
    ros_short_workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    out = tmp_path / "run"
    bag = tmp_path / "no_such_dir" / "run.bag"
    launch = launcher(
        ros_short_workspace, "ros_short.launch", f"out:={out}", "plots:=false", f"bag:={bag}"
    )
    text = launch.finish()
    assert f"error: amsa_bag: cannot write {bag}: No such file or directory" in text, text[-3000:]
    assert "REQUIRED process [amsa_bag" in text, text[-3000:]  # roslaunch ended the run there
    assert "gave up after" not in text  # not the simulator's start-up deadline
    assert not bag.parent.exists()  # nothing made outside what it was told
    assert not (out / "trace.csv").exists()  # no run went ahead without its bag
