"""A launch file whose ``/amsa/seed`` was edited to something that is not a seed (negative,
text, empty, beyond 2^63 - 1): ``rosrun PKG run_lockstep`` exits 2 with one line naming
``/amsa/seed``, never a run that goes on with another seed's noise, a hang or a crash.

Runs in ``unshare -n`` on the session's build of ``tests/fixtures/ros_short.yaml`` (its
noisy GPS is a C++ sensor that reads the seed); skipped, with the reason, where ROS, catkin,
unshare or root is missing.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, package_edit, ros_missing

pytestmark = pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing()))
launcher = ros_launch.launcher  # the fixture
PKG = "mdeChallenge"
SEEDS = {"negative": "-1", "text": "abc", "empty": "", "beyond-2^63": str(2**70)}


@pytest.mark.parametrize("seed", SEEDS.values(), ids=list(SEEDS))
def test_a_launch_with_a_bad_seed_is_exit_2_naming_it(
    ros_short_workspace: Path,
    ros_short_checked: Path,
    launcher: Callable[..., Launch],
    tmp_path: Path,
    seed: str,
) -> None:
    launch_file = ros_short_workspace / "src" / PKG / "launch" / "ros_short.launch"
    original = launch_file.read_text()
    found = re.search(r'<param name="seed" type="str" value="(\d+)"/>', original)
    assert found is not None, original[:2000]
    edited = original.replace(found.group(0), f'<param name="seed" type="str" value="{seed}"/>')
    out = tmp_path / "run"
    with package_edit(launch_file, edited):
        launch = launcher(
            ros_short_checked, "ros_short.launch", f"out:={out}", "plots:=false", "timeout:=600"
        )
        text = launch.finish()
    assert launch.proc.returncode == 2, text[-3000:]
    assert "/amsa/seed" in text.strip().splitlines()[-1], text[-3000:]
    assert "Traceback" not in text, text[-3000:]
