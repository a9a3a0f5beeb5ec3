"""The suite's tiers: a marker per slow kind of test, and a CPU budget for every other test.

The quick tier is everything unmarked (``pytest -m "not (ros or ros2 or build or docs or
slow)"``): no catkin build, no ROS launch, no pip install, no docs build. It stays quick only
if nothing slow slips in unmarked, so an unmarked test that spends more than
:data:`BUDGET_S` seconds of CPU (its own process's and its children's, from ``getrusage``:
wall time would make the check fail on a loaded machine) fails, naming the markers to use;
on the pure-Python paths the budget is :data:`PURE_FACTOR` times as large (:func:`budget_s`).
The CPU of the session's background catkin builds (``ros_prebuild.py``) is not a test's and
is taken off.

A test that uses a launch fixture (:data:`ROS_FIXTURES`) is marked ``ros`` even if its file
forgets to say so. The markers are registered in pyproject.toml; this module is loaded by
``tests/conftest.py`` (``pytest_plugins``).
"""

from __future__ import annotations

import resource
import sys
from collections.abc import Generator

import pytest

#: the markers of the slow kinds: a test carrying one is outside the quick tier
SLOW_KINDS = ("ros", "ros2", "build", "docs", "slow")
#: seconds of CPU an unmarked test may spend (setup and call, children included); the ini
#: option ``cpu_budget_s`` changes it (tests/structure/test_tiers.py runs a suite with a small one)
BUDGET_S = 10.0
#: the budget's multiple where the pure-Python paths run (no C compiler at install, or
#: ``AMSA_PHYS_PURE=1``): the budget prices a test on the compiled paths, and the same test
#: costs 4-9 times as much CPU on the pure ones (the quick tier's tests over 10 s there spent
#: 10.3-23.6 s, 1.3-4.7 s compiled), so that a test's tier does not depend on the path it runs
#: on. The ini option ``cpu_budget_pure_factor`` changes it
PURE_FACTOR = 10.0
#: fixtures that launch a ROS package: their tests are ``ros`` whatever their file says
ROS_FIXTURES = frozenset({"launcher", "ros_short_workspace", "ros_short_checked"})

_SPENT = pytest.StashKey[float]()


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addini("cpu_budget_s", "CPU seconds an unmarked test may spend", default=str(BUDGET_S))
    parser.addini(
        "cpu_budget_pure_factor",
        "the budget's multiple on the pure-Python paths",
        default=str(PURE_FACTOR),
    )


def budget_s(config: pytest.Config) -> float:
    """CPU seconds an unmarked test may spend on the path this session runs (the budget, times
    :data:`PURE_FACTOR` where the compiled physics step is not in use)."""
    from amsa_phys.physics.step_path import describe

    budget = float(config.getini("cpu_budget_s"))
    if describe()[0]:
        return budget
    return budget * float(config.getini("cpu_budget_pure_factor"))


def group_of(item: pytest.Item) -> str | None:
    """The xdist group a test runs in under ``pytest -n 2 --dist loadgroup``, or None.

    ``ros1``: every ROS 1 test (catkin builds and launches, the C++ twins), one after another
    on one worker: a module's workspace (a module fixture) is built once, and two ROS 1
    graphs never share the two cores. ``ros2_build``: the ROS 2 tests and the other build
    tests, in turn on one worker: no two workers pip-install (or uninstall) the same package
    into the one environment at once. The two groups are two units of work, so each worker
    takes one and both fill up with the rest (the ROS 1 group alone is most of a worker's
    share; one group for all of them made it the suite's critical path).
    """
    if item.get_closest_marker("ros"):
        return "ros1"
    if item.get_closest_marker("ros2") or item.get_closest_marker("build"):
        return "ros2_build"
    return None


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the group marks
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """A test using a launch fixture is a ROS test; ROS and build tests go to their group
    (:func:`group_of`). Without xdist the groups are ignored.

    xdist's worker turns the ``xdist_group`` marks into an ``@GROUP`` suffix of the node ids
    in its own hook of this name, so this one runs first. With pytest 9.2 that suffix is lost
    (pyproject.toml keeps pytest below it) and nothing was grouped: each such test was a work
    unit of its own, one worker uninstalled the plugin another was using.
    tests/test_serial_group.py fails if the suffix is missing again.
    """
    for item in items:
        # not ``"ros" in item.keywords``: a test under tests/ros/ has that keyword (its folder)
        # and so was never marked
        needs_ros = ROS_FIXTURES & set(getattr(item, "fixturenames", ()))
        if needs_ros and item.get_closest_marker("ros") is None:
            item.add_marker(pytest.mark.ros)
        group = group_of(item)
        if group is not None:
            item.add_marker(pytest.mark.xdist_group(group))


def cpu_seconds() -> float:
    """CPU seconds of this process and its waited-for children, less the background
    builds' (not any test's)."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    prebuild = sys.modules.get("ros_prebuild")
    if prebuild is not None:  # the builds' CPU taken off in the same reading (its lock)
        return own.ru_utime + own.ru_stime + prebuild.tests_children_cpu()
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def unmarked(item: pytest.Item) -> bool:
    """Whether ``item`` belongs to the quick tier."""
    return not any(item.get_closest_marker(kind) for kind in SLOW_KINDS)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_setup(item: pytest.Item) -> Generator[None, None, None]:
    start = cpu_seconds()
    yield
    item.stash[_SPENT] = cpu_seconds() - start


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item: pytest.Item) -> Generator[None, None, None]:
    start = cpu_seconds()
    yield
    item.stash[_SPENT] = item.stash.get(_SPENT, 0.0) + cpu_seconds() - start


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(
    item: pytest.Item, call: pytest.CallInfo[None]
) -> Generator[None, pytest.TestReport, None]:
    """A passing unmarked test over budget is reported failed, saying why."""
    outcome = yield
    report = outcome.get_result()
    if call.when != "call" or not report.passed or not unmarked(item):
        return
    spent = item.stash.get(_SPENT, 0.0)
    budget = budget_s(item.config)
    if spent > budget:
        report.outcome = "failed"
        report.longrepr = (
            f"{item.nodeid} spent {spent:.1f} s of CPU (its process and children), over the "
            f"{budget:g} s of an unmarked test: make it cheaper, or mark it with the kind "
            f"that makes it slow ({', '.join(SLOW_KINDS)}; docs/development.md, the tiers)"
        )
