"""The quick tier's guard: an unmarked test that spends too much CPU fails, a marked one not.

A small suite runs under pytester with a budget of 0.3 s (the ini option ``cpu_budget_s``;
the real suite's is 10 s): CPU is counted in the test's own process and in the children it
waits for, never as wall time, so a loaded machine cannot make the check fail.
"""

from __future__ import annotations

import pytest

from amsa_phys.physics.step_path import PURE_ENV, extension

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


def _ini(pytester: pytest.Pytester, factor: float) -> None:
    """The tiers plugin with a budget of 0.3 s, ``factor`` times that on the pure paths."""
    pytester.makeconftest('pytest_plugins = ["tiers"]\n')
    pytester.makeini(
        f"[pytest]\ncpu_budget_s = 0.3\ncpu_budget_pure_factor = {factor}\n"
        "markers =\n    slow: slow\n    ros: r\n    ros2: r\n    build: b\n    docs: d\n"
    )


def test_an_unmarked_test_over_its_cpu_budget_fails_a_marked_one_passes(
    pytester: pytest.Pytester,
) -> None:
    _ini(pytester, factor=1.0)  # the same budget on either physics step
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


@pytest.mark.parametrize("pure", [True, False])
def test_on_the_pure_paths_the_budget_is_the_factor_times_larger(
    pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch, pure: bool
) -> None:
    """A test's tier does not depend on the physics step it runs on: 0.6 s of CPU is over a
    0.3 s budget with the compiled step, within it (3 s) on the pure one, which is slower."""
    if not pure and extension() is None:
        pytest.skip("the compiled step was not built (no C compiler at install)")
    if pure:
        monkeypatch.setenv(PURE_ENV, "1")
    else:
        monkeypatch.delenv(PURE_ENV, raising=False)
    _ini(pytester, factor=10.0)
    pytester.makepyfile(test_suite=SUITE)
    result = pytester.runpytest_inprocess("-k", "burns_in_process")
    result.assert_outcomes(**({"passed": 1} if pure else {"failed": 1}))
