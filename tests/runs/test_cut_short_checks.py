"""A run cut short (``--duration``) fails a check it has already failed for good (issue 33, 10).

A skipped check passes, so skipping one that a cut-short run had already broken (a collision
under ``collisions below 1``) made ``amsa-phys run`` exit 0 and ``Run.passed`` True on a run
that crashed. A count or a maximum only grows and a minimum only shrinks as a block goes on:
past its bound it is FAIL whatever the rest of the block would have done. Anything else
about a cut-short block is still skipped.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import amsa_phys as ap
from amsa_phys.cli.main import main
from amsa_phys.model.scenario import Expectation
from amsa_phys.runs.expect import check_expectations

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
#: the issue's command: the follower told to sit on the leader collides at ~9.7 s
CRASH = ["MyFollowerController.distanceRef=0", "MyFollowerController.Kv=1"]


def test_issue_command_collides_and_exits_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["run", str(SCENARIO1), "--headless", "--duration", "60", "--no-plot", "-q"]
    argv += ["--out", str(tmp_path / "o")]
    for text in CRASH:
        argv += ["--set", text]
    assert main(argv) == 1
    captured = capsys.readouterr()
    # every verdict on stdout, the failure said once on stderr; the checks a cut run
    # cannot judge stay skipped
    assert (
        "expect collisions = 1 (already broken when the run was cut short at t=60 s: "
        "a count only grows), below 1: FAIL\n"
    ) in captured.out
    # the setpoint moved away from quality.reference is warned about, then the failure
    warning, error = captured.err.splitlines()
    assert warning.startswith("warning: MyFollowerController.distanceRef is 0 m, but the run")
    # the run's own requirement "never closer than 3 m" is broken for good too; the checks
    # and the requirement reading the last phase are not judged
    assert error == "error: 2 checks of 6 failed: collisions, requirement no_contact"
    assert captured.out.count(": skipped (") == 4


def test_api_run_is_not_passed() -> None:
    # the setpoint moved away from quality.reference is warned about, as on the command line
    with pytest.warns(ap.ReferenceWarning, match="distanceRef is 0 m"):
        run = ap.run(
            SCENARIO1,
            duration=60,
            set={"MyFollowerController.distanceRef": 0, "MyFollowerController.Kv": 1},
        )
    assert run.metrics["overall"]["partial"] is True
    assert not run.passed
    failed = [c for c in run.checks if not c.passed]
    assert [(c.expectation.metric or c.expectation.name, c.skipped) for c in failed] == [
        ("collisions", False),
        ("no_contact", False),  # "never closer than 3 m": broken when they touched
    ]
    assert failed[0].value == 1
    assert failed[1].value is not None
    assert failed[1].value < 0
    # the other four are still not judged
    assert sorted(c.expectation.metric or c.expectation.name for c in run.skipped) == [
        "final_distance",
        "holds_last_phase",
        "rms_error",
        "settling_time",
    ]


def _metrics(**block: Any) -> dict[str, Any]:
    """metrics.json of a run cut short at t = 30 s inside phase 0 (the only phase)."""
    full = {"partial": True, **block}
    return {"simulated": 30.0, "overall": full, "phases": [dict(full, start=0.0)]}


def _expect(metric: str, below: float | None = None, above: float | None = None) -> Expectation:
    return Expectation(metric, None, below, above, 1)


@pytest.mark.parametrize(
    ("metric", "value", "below", "above", "verdict"),
    [
        ("collisions", 2, 2, None, "FAIL"),  # at the bound: `below` is strict
        ("collisions", 1, 2, None, "skipped"),  # may still collide again
        ("collisions", 3, None, 5, "skipped"),  # a count may still reach 5
        ("max_distance", 30.0, 26.0, None, "FAIL"),
        ("max_distance", 20.0, 26.0, None, "skipped"),
        ("max_distance", 20.0, None, 25.0, "skipped"),  # a maximum may still rise above
        ("max_after_approach", 33.0, 32.0, None, "FAIL"),
        ("max_after_approach", None, 32.0, None, "skipped"),  # no approach yet: nothing known
        ("min_distance", 0.5, None, 1.0, "FAIL"),
        ("min_distance", 2.0, None, 1.0, "skipped"),
        ("min_distance", 0.5, 5.0, None, "skipped"),  # a minimum may still fall below 5
        ("min_distance", 0.5, 5.0, 1.0, "FAIL"),  # one side broken is enough
        ("rms_error", 99.0, 2.0, None, "skipped"),  # not monotone: the rest could lower it
        ("mean_error", -99.0, None, 0.0, "skipped"),
        ("final_distance", 99.0, 20.0, None, "skipped"),
    ],
)
def test_only_a_monotone_metric_past_its_bound_fails(
    metric: str, value: float | None, below: float | None, above: float | None, verdict: str
) -> None:
    (check,) = check_expectations([_expect(metric, below, above)], _metrics(**{metric: value}))
    assert check.verdict == verdict
    assert check.passed is (verdict != "FAIL")
    if verdict == "FAIL":
        assert check.value == value
        assert "already broken when the run was cut short at t=30 s" in check.describe()


def test_a_phase_never_reached_stays_skipped() -> None:
    metrics = _metrics(collisions=4)
    e = Expectation("collisions", 1, 1, None, 1)  # phase 1: the run stopped in phase 0
    (check,) = check_expectations([e], metrics)
    assert check.skipped
    assert check.passed
    assert check.why == "phase 1 not reached: the run ended at t=30 s"


def test_a_finished_phase_before_the_cut_is_judged_as_ever() -> None:
    metrics = {
        "simulated": 30.0,
        "overall": {"partial": True, "collisions": 0},
        "phases": [{"start": 0.0, "collisions": 0}, {"start": 20.0, "partial": True}],
    }
    (check,) = check_expectations([Expectation("collisions", 0, None, 0.5, 1)], metrics)
    assert check.verdict == "FAIL"
    assert not check.skipped


def test_the_replay_judges_the_failed_check_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The resolved scenario.yaml keeps a check the cut run failed for good (it leaves out
    only the checks the run did not judge), so replaying it fails the same check."""
    argv = ["run", str(SCENARIO1), "--headless", "--duration", "60", "--no-plot", "-q"]
    for text in CRASH:
        argv += ["--set", text]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 1
    resolved = (tmp_path / "o" / "scenario.yaml").read_text()
    assert "metric: collisions" in resolved
    assert "rms_error" not in resolved.split("\n", 1)[1]  # not judged: left out (named atop)
    capsys.readouterr()
    replay = ["run", str(tmp_path / "o" / "scenario.yaml"), "--headless", "--no-plot", "-q"]
    assert main([*replay, "--out", str(tmp_path / "r")]) == 1
    out, err = capsys.readouterr()
    assert "expect collisions = 1, below 1: FAIL\n" in out  # with the other verdicts
    assert err.splitlines()[-1] == "error: 2 checks of 2 failed: collisions, requirement no_contact"
