"""``tune`` judges its objective and its ranges before any run, and a requirement's
robustness is an objective it can reach, found trying it as a user: ``--metric
robustness.NAME`` scored every point -inf (the cases dropped the scenario's requirements),
a misspelt metric spent the whole budget on nothing, and a parameter given twice was tuned
twice."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
ARGS = ["tune", str(SWEEP), "--range", "MyFollowerController.Kv=0.05:0.8", "--seeds", "1"]


def test_a_requirements_robustness_is_tuned_for(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*ARGS, "--budget", "2", "--metric", "robustness.no_contact"]) == 0
    out = capsys.readouterr().out
    assert "worst -inf" not in out
    assert "robust choice: MyFollowerController.Kv=" in out
    worsts = [float(line.rsplit(" ", 1)[1]) for line in out.splitlines() if ": worst " in line]
    assert len(worsts) == 2
    assert all(w > 0 for w in worsts)  # no collision: the distance stays above 3 m


@pytest.mark.parametrize(
    ("extra", "said"),
    [
        (
            ["--metric", "rms_err"],
            "error: --metric: unknown objective 'rms_err' (did you mean rms_error?)",
        ),
        (
            ["--metric", "robustness.nope"],
            "error: --metric: unknown requirement 'nope'; known: no_contact, path_speed",
        ),
        (
            ["--range", "MyFollowerController.Kv=0.1:0.2"],
            "error: --range: MyFollowerController.Kv appears twice",
        ),
    ],
)
def test_what_no_run_could_answer_is_refused_before_any(
    extra: list[str], said: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*ARGS, "--budget", "2", *extra]) == 2
    out, err = capsys.readouterr()
    assert err.startswith(said)
    assert len(err.splitlines()) == 1
    assert "worst" not in out  # nothing ran


def test_a_search_of_more_runs_than_a_sweep_may_have_is_refused_before_any(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each bound within its own, together 10^10 runs (centuries): refused as a sweep of
    more than 1,000,000 runs is, before the first run (which would fail this test)."""

    def no_run(*_: object) -> float:
        raise AssertionError("a run started")

    monkeypatch.setattr("amsa_phys.cli.tune.evaluate", no_run)
    assert main([*ARGS, "--budget", "10000", "--box", "1000", "--seeds", "1000"]) == 2
    err = capsys.readouterr().err
    assert err == (
        "error: --budget: 10,000 evaluations x 1000 contexts x 1000 seeds is "
        "10,000,000,000 runs; a search has at most 1,000,000, as a sweep\n"
    )


def test_contexts_that_are_not_a_sweep_offer_what_tune_takes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``tune`` has no ``--scenario``: a directory that records no sweep scenario says to
    give the contexts in the scenario (the message was ``adapt``'s, offering the flag)."""
    assert main([*ARGS, "--budget", "2", "--contexts", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"error: {tmp_path}: records no scenario.yaml (not a sweep directory, or made before "
        "sweeps recorded their scenario?); give the contexts in the scenario's sweep: "
        "contexts instead\n"
    )
