"""Fixtures shared by several ROS test files, made once per session (their background
build: ``tests/ros_prebuild.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest
from ros_prebuild import ROS_SHORT


@pytest.fixture(scope="session")
def ros_short_workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``tests/fixtures/ros_short.yaml`` exported as package ``mdeChallenge``, built with
    catkin and installed (``catkin_make install``), once: tests/ros/test_ros.py and
    test_ros_boundary_stamps.py launch it, and a catkin build costs 15-30 s of a 2-core
    machine. A test edits the package only through ``ros_launch.package_edit`` (put back
    whatever happens) and writes its outputs in its own ``tmp_path``; the one test that
    hides the workspace (renames it) puts it back after its launch."""
    from ros_launch import build_workspace

    return build_workspace(tmp_path_factory.mktemp("ros_short_ws"), *ROS_SHORT)


@pytest.fixture(scope="session")
def ros_short_checked(ros_short_workspace: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A directory whose ``launch.sh`` runs ``rosrun mdeChallenge run_lockstep`` on
    ``ros_short_workspace`` (tests/ros_launch.py ``run_lockstep_dir``)."""
    from ros_launch import run_lockstep_dir

    return run_lockstep_dir(ros_short_workspace, ROS_SHORT[1], tmp_path_factory.mktemp("checked"))
