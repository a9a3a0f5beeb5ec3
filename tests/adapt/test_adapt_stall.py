"""benchmarks.adapt_stall: its options' errors and what the docs' figures are computed from.

The full benchmark runs every held-out sequence for several turning gains; these tests cover
what a user types (``--budget``, a missing ``adapt_seeds`` results file) and the counts the
table shows (which sequences stalled, the stalled seeds averaged apart from the others, the
sequences gained and lost against the shipped gains).
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

from benchmarks import adapt_stall  # noqa: E402
from benchmarks.adapt_stall import stalled_cases, summarise  # noqa: E402


def _doc() -> dict:
    """Two seeds, one draw of three sequences: the second stalls in seed 2 only."""
    none = [[], []]
    return {
        "seeds": [1, 2],
        "draws": [
            {
                "draw": 1000,
                "rows": [
                    {"index": 0, "seeds": {"robust": [1.0, 1.0]}, "stalls": {"robust": none}},
                    {
                        "index": 1,
                        "seeds": {"robust": [1.0, 5.0]},
                        "stalls": {"robust": [[], [[300.0, 400.0]]]},
                    },
                    {"index": 2, "seeds": {"robust": [2.0, 2.0]}, "stalls": {"robust": none}},
                ],
            }
        ],
    }


def test_stalled_cases_are_the_sequences_with_a_robust_stall_and_their_seeds() -> None:
    found = stalled_cases(_doc())
    assert [(c["draw"], c["index"], c["stalled"]) for c in found] == [(1000, 1, [2])]


def test_summary_keeps_stalled_seeds_apart_and_counts_gains_and_losses() -> None:
    cases = adapt_stall.held_out(_doc())
    # a stronger turning gain: no stall, the stalled seed recovers, one sequence 10 % worse,
    # one 1 % better (within the 2 % bound: neither gained nor lost)
    runs = [
        {**cases[0], "rms": [1.1, 1.1], "stalls": [[], []]},
        {**cases[1], "rms": [0.9, 1.2], "stalls": [[], []]},
        {**cases[2], "rms": [1.98, 1.98], "stalls": [[], []]},
    ]
    s = summarise(runs, [1, 2])
    assert s["stalled_runs"] == 0
    assert s["runs"] == 6
    assert s["sequences"] == 3
    assert s["stalled_seeds_rms"] == pytest.approx(1.2)  # seed 2 of sequence 1 alone
    assert s["other_seeds_rms"] == pytest.approx(0.9)  # seed 1 of sequence 1 alone
    assert (s["gained"], s["lost"]) == (1, 1)
    assert s["losses"] == [[1000, 0, pytest.approx(0.1)]]  # which one, by how much
    assert s["mean_rms"] == pytest.approx((1.1 * 2 + 0.9 + 1.2 + 1.98 * 2) / 6)
    stalled = summarise([{**runs[1], "stalls": [[[1.0, 30.0]], []]}], [1, 2])
    assert (stalled["stalled_runs"], stalled["stalled_sequences"]) == (1, 1)


def test_bad_budget_is_one_line_and_exit_2(monkeypatch, tmp_path, capsys) -> None:
    # the seeds file missing too: without the budget check the run would stop there, on
    # another message
    monkeypatch.setattr(adapt_stall, "SEEDS_FILE", tmp_path / "none.json")
    assert adapt_stall.main(["--budget", "0", "--no-save"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert err.startswith("adapt_stall: --budget:")


def test_missing_seeds_file_is_one_line_and_exit_2(monkeypatch, tmp_path, capsys) -> None:
    monkeypatch.setattr(adapt_stall, "SEEDS_FILE", tmp_path / "none.json")
    monkeypatch.setattr(adapt_stall, "ROOT", tmp_path)
    assert adapt_stall.main(["--no-save"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert "none.json: no such file" in err
