"""A test that launches ROS (it uses a launch fixture) is outside the quick tier wherever it
lives, even when its file forgets the ``ros`` marker.

The check once asked whether ``"ros"`` was among the test's keywords, which every test
under ``tests/ros/`` has (its folder's name): so nothing there was marked, and three ROS
launches (a bad seed, a killed container, free mode's first value) ran in the quick tier.
"""

from __future__ import annotations

import pytest

LAUNCHING = """
import pytest


@pytest.fixture
def launcher():
    return "a launch"


def test_launches(launcher):
    assert launcher


def test_needs_no_ros():
    pass
"""


def test_a_launching_test_under_a_ros_folder_leaves_the_quick_tier(
    pytester: pytest.Pytester,
) -> None:
    pytester.makeconftest('pytest_plugins = ["tiers"]\n')
    pytester.makeini(
        "[pytest]\nmarkers =\n    slow: slow\n    ros: r\n    ros2: r\n    build: b\n    docs: d\n"
    )
    folder = pytester.mkpydir("ros")
    (folder / "test_launch.py").write_text(LAUNCHING)
    quick = pytester.runpytest_inprocess("-m", "not (ros or ros2 or build or docs or slow)")
    quick.assert_outcomes(passed=1, deselected=1)
    quick.stdout.no_fnmatch_line("*test_launches*")
    ros = pytester.runpytest_inprocess("-m", "ros", "-v")
    ros.assert_outcomes(passed=1, deselected=1)
    ros.stdout.fnmatch_lines(["*test_launches PASSED*"])
