"""The quick tier's guard: an unmarked test that spends too much CPU fails, a marked one not.

A small suite runs under pytester with a budget of 0.3 s (the ini option ``cpu_budget_s``;
the real suite's is 10 s): CPU is counted in the test's own process and in the children it
waits for, never as wall time, so a loaded machine cannot make the check fail.
"""

from __future__ import annotations

import pytest

SUITE = """
import subprocess
import sys
import time

import pytest

BURN = "import time\\nend = time.process_time() + 0.6\\nwhile time.process_time() < end: pass"


def test_burns_in_process():
    exec(BURN)


def test_burns_in_a_child():
    subprocess.run([sys.executable, "-c", BURN], check=True)


@pytest.mark.slow
def test_burns_marked():
    exec(BURN)


def test_waits_without_burning():
    time.sleep(0.6)
"""


def test_an_unmarked_test_over_its_cpu_budget_fails_a_marked_one_passes(
    pytester: pytest.Pytester,
) -> None:
    pytester.makeconftest('pytest_plugins = ["tiers"]\n')
    pytester.makeini(
        "[pytest]\ncpu_budget_s = 0.3\nmarkers =\n    slow: slow\n    ros: r\n    ros2: r\n"
        "    build: b\n    docs: d\n"
    )
    pytester.makepyfile(test_suite=SUITE)
    result = pytester.runpytest_inprocess()
    result.assert_outcomes(passed=2, failed=2)
    outcomes = {
        r.head_line: r.outcome
        for r in result.reprec.getreports("pytest_runtest_logreport")
        if r.when == "call"
    }  # type: ignore[attr-defined]
    assert outcomes == {
        "test_burns_in_process": "failed",
        "test_burns_in_a_child": "failed",
        "test_burns_marked": "passed",
        "test_waits_without_burning": "passed",  # wall time is not CPU time
    }
    result.stdout.fnmatch_lines(["*test_burns_in_a_child spent *s of CPU*over the 0.3 s*"])
