"""The full suite's ``-n 2 --dist loadgroup`` really groups the ROS and build tests: their node
ids carry xdist's group suffix (``@ros1``, ``@ros2_build``: tests/tiers.py ``group_of``).

Without it every such test is a scheduling unit of its own: two workers each set up a
module's fixture (a pip-installed plugin, a catkin workspace) and one tears it down under the
other, which is how the plugin tests once failed in CI.
"""

from __future__ import annotations

import pytest


def _grouped(request: pytest.FixtureRequest) -> None:
    # xdist's workers set ``loadgroup``; a run without workers (no ``-n``) has no such option
    if not getattr(request.config.option, "loadgroup", False):
        pytest.skip("groups exist only under pytest -n N --dist loadgroup (the full suite)")


@pytest.mark.build  # a build test: it must be in the group of the pip-installing tests
def test_a_build_test_runs_in_its_group(request: pytest.FixtureRequest) -> None:
    _grouped(request)
    assert request.node.nodeid.endswith("@ros2_build"), request.node.nodeid


@pytest.mark.ros
@pytest.mark.build  # ROS 1 first: a catkin build is a ROS 1 test's
def test_a_ros1_build_test_runs_with_the_ros1_tests(request: pytest.FixtureRequest) -> None:
    _grouped(request)
    assert request.node.nodeid.endswith("@ros1"), request.node.nodeid


def test_other_tests_are_not_grouped(request: pytest.FixtureRequest) -> None:
    _grouped(request)
    assert "@" not in request.node.nodeid, request.node.nodeid
