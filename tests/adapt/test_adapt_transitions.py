"""``benchmarks.adapt_transitions``: the screening set is recoveries, and a losing rule set
is caught (exit 1, the sequence printed) while one that never switches is not."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import adapt_transitions


def test_every_sequence_is_motors_that_recover() -> None:
    found = adapt_transitions.transitions()
    assert len(found) == 64
    assert len({s.describe() for s in found}) == 64
    for s in found:
        (_, first), (at, then) = s.segments
        assert 150 <= at <= 210
        assert first["MyNormalizePower.motorCoef"] <= 50
        assert then["MyNormalizePower.motorCoef"] > first["MyNormalizePower.motorCoef"]


@pytest.mark.parametrize(("kv", "code"), [(0.2, 0), (0.8, 1)])
def test_a_losing_rule_set_is_caught(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys, kv: float, code: int
) -> None:
    """One sequence, rules that set ``kv`` after 5 s: the robust gain again (level), or a
    gain that swings on the recovered motors (a loss)."""
    one = adapt_transitions.transitions()[:1]
    monkeypatch.setattr(adapt_transitions, "transitions", lambda: one)
    rules = tmp_path / "rules.yaml"
    rules.write_text(
        "adapt:\n"
        "  - when: {MotorMonitor.delivered: {above: -1}}\n"
        f"    set: {{MyFollowerController.Kv: {kv}}}\n"
        "    hold: 5\n"
    )
    assert adapt_transitions.main(["--rules", str(rules)]) == code
    out = capsys.readouterr().out
    assert f"on {code} of 1" in out
    assert (one[0].describe() in out) == bool(code)


def test_a_bad_setting_is_refused() -> None:
    with pytest.raises(SystemExit) as info:
        adapt_transitions.main(["--set", "MotorMonitor.recentWindow=five"])
    assert info.value.code == 2
