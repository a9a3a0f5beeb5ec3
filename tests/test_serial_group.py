"""The full suite's ``-n 2 --dist loadgroup`` really keeps ROS, ROS 2 and build tests on one
worker: their node ids carry xdist's ``@serial`` group suffix.

Without it every such test is a scheduling unit of its own: two workers each set up a
module's fixture (a pip-installed plugin, a catkin workspace) and one tears it down under the
other, which is how the plugin tests once failed in CI.
"""

from __future__ import annotations

import pytest


@pytest.mark.build  # a build test: it must be in the serial group
def test_a_build_test_runs_in_the_serial_group(request: pytest.FixtureRequest) -> None:
    if not request.config.getvalue("loadgroup"):
        pytest.skip("groups exist only under pytest -n N --dist loadgroup (the full suite)")
    assert request.node.nodeid.endswith("@serial"), request.node.nodeid


def test_other_tests_are_not_serialised(request: pytest.FixtureRequest) -> None:
    if not request.config.getvalue("loadgroup"):
        pytest.skip("groups exist only under pytest -n N --dist loadgroup (the full suite)")
    assert "@" not in request.node.nodeid, request.node.nodeid
