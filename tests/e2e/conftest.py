"""Fixtures shared by several e2e files, made once per session."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent.parent


@pytest.fixture(scope="session")
def ros_short_workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``tests/fixtures/ros_short.yaml`` exported as package ``mdeChallenge``, built with
    catkin and installed (``catkin_make install``), once: tests/e2e/test_ros.py and
    test_ros_boundary_stamps.py launch it, and a catkin build costs 15-30 s of a 2-core
    machine. A test edits the package only through ``ros_launch.package_edit`` (put back
    whatever happens), writes its outputs in its own ``tmp_path``, and moves a copy, never
    the workspace itself."""
    from ros_launch import build_workspace

    ws = tmp_path_factory.mktemp("ros_short_ws")
    return build_workspace(ws, ROOT / "tests" / "fixtures" / "ros_short.yaml", "mdeChallenge", True)
