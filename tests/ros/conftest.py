"""Fixtures shared by several e2e files, made once per session."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
#: ``ros_short_workspace``'s build: (scenario, package, catkin_make install as well)
ROS_SHORT = (ROOT / "tests" / "fixtures" / "ros_short.yaml", "mdeChallenge", True)


@pytest.fixture(scope="session")
def ros_short_workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``tests/fixtures/ros_short.yaml`` exported as package ``mdeChallenge``, built with
    catkin and installed (``catkin_make install``), once: tests/e2e/test_ros.py and
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


def _skipped(item: pytest.Item) -> bool:
    """Marked to be skipped whatever happens (a skipif whose condition is already True)."""
    for mark in item.iter_markers():
        if mark.name == "skip" or (mark.name == "skipif" and mark.args and mark.args[0] is True):
            return True
    return False


def _builds_wanted(items: list[pytest.Item]) -> list[tuple[Path, str, bool]]:
    """The catkin builds the collected tests will ask for, in the order they will: the
    session's ros_short, and the ``SCENARIO`` as ``PKG`` of every module that imports
    ``build_workspace`` (a module building something else builds it in the foreground)."""
    wanted: list[tuple[Path, str, bool]] = []
    for item in items:
        module = getattr(item, "module", None)
        if module is None or _skipped(item):
            continue
        if "ros_short_workspace" in getattr(item, "fixturenames", ()):
            key = (ROS_SHORT[0].resolve(), *ROS_SHORT[1:])
        elif getattr(getattr(module, "build_workspace", None), "__module__", "") == "ros_launch":
            scenario, pkg = getattr(module, "SCENARIO", None), getattr(module, "PKG", None)
            if not isinstance(scenario, Path) or not isinstance(pkg, str):
                continue
            key = (scenario.resolve(), pkg, False)
        else:
            continue
        if key not in wanted:
            wanted.append(key)
    return wanted


@pytest.fixture(scope="session", autouse=True)
def _ros_prebuild(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[None]:
    """The session's catkin builds start in the background at the first e2e test, at the
    lowest CPU priority, while the tests before the ROS files run (tests/ros_prebuild.py);
    whatever is still building when the session ends is ended."""
    wanted = _builds_wanted(request.session.items)
    if wanted:
        from ros_launch import ros_missing

        if ros_missing() is not None:
            wanted = []
    if not wanted:
        yield
        return
    import ros_prebuild

    ros_prebuild.start(tmp_path_factory.mktemp("ros_prebuild"), wanted)
    try:
        yield
    finally:
        ros_prebuild.stop()
