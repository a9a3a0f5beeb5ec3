"""``benchmarks.adapt_seeds --resume``: an interrupted run's saved draws are kept, not run again.

The full benchmark scores five draws of 600 s cases for hours and saves its results file after
each draw, so that a run stopped part way (Ctrl-C, a closed terminal) can go on with
``--resume`` from the first draw it had not finished. Held here with the scoring of a draw
replaced by a stand-in that records which draws it was asked for (the sweep's rules too: what
is resumed does not depend on them): the second run scores only the draws the first did not
save, keeps the saved ones as they were, and a resume over other seeds keeps nothing.
"""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import yaml

from amsa_phys.adapt import derive
from benchmarks import adapt_seeds
from benchmarks import results as bench_results


class Stop(Exception):
    """The stand-in's interruption, part way through the draws."""


def _rows(draw: int, count: int, seeds: list[int], run: int) -> list[dict[str, Any]]:
    """``count`` sequences as ``score_draw`` gives them, their values marking the ``run`` that
    made them (the rules as good as the robust gain: nothing lost)."""
    value = float(draw + run)
    return [
        {
            "index": i,
            "sequence": f"0 s {{behavior 1, motorCoef {50 + i}}}",
            "segments": [[0.0, {"Leader.behavior": 1}]],
            "seeds": {w: [value] * len(seeds) for w in adapt_seeds.WAYS},
            "stalls": {w: [[] for _ in seeds] for w in adapt_seeds.WAYS},
        }
        for i in range(count)
    ]


@pytest.fixture
def bench(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> SimpleNamespace:
    """The benchmark with its results file in ``tmp_path``, no docs page rewritten, the rules
    the committed ones, and each draw's scoring recorded (``scored``) and made by ``run``."""
    state = SimpleNamespace(
        out=tmp_path / "adapt_seeds.json",
        sweep=tmp_path / "sweep",
        scored=[],
        run=1,
        stop_at=None,
    )
    state.sweep.mkdir()
    (state.sweep / "results.csv").write_text("run\n")
    rules = yaml.safe_load(adapt_seeds.RULES.read_text())["adapt"]

    def score_draw(scenario, found, draw, count, seeds):  # type: ignore[no-untyped-def]
        if draw == state.stop_at:
            raise Stop
        state.scored.append(draw)
        return _rows(draw, count, seeds, state.run)

    monkeypatch.setattr(adapt_seeds, "OUT", state.out)
    monkeypatch.setattr(adapt_seeds, "score_draw", score_draw)
    monkeypatch.setattr(derive, "derive", lambda results, scenario: SimpleNamespace(rules=rules))
    monkeypatch.setattr(bench_results, "write_pages", lambda: [])
    return state


def _saved(out: Path) -> dict[int, list[dict[str, Any]]]:
    return {d["draw"]: d["rows"] for d in json.loads(out.read_text())["draws"]}


def test_resume_keeps_the_saved_draws_and_scores_the_rest(bench: SimpleNamespace) -> None:
    order = [draw for draw, _ in adapt_seeds.DRAWS]
    bench.stop_at = order[2]  # interrupted while scoring the third draw
    with pytest.raises(Stop):
        adapt_seeds.main([str(bench.sweep), "--seeds", "2"])
    assert bench.scored == order[:2]
    first = _saved(bench.out)
    assert sorted(first) == sorted(order[:2])  # saved after each draw, not only at the end

    bench.scored, bench.stop_at, bench.run = [], None, 2
    assert adapt_seeds.main([str(bench.sweep), "--seeds", "2", "--resume"]) == 0
    assert bench.scored == order[2:]  # the saved draws were not run again
    resumed = _saved(bench.out)
    assert sorted(resumed) == sorted(order)
    for draw in order[:2]:
        assert resumed[draw] == first[draw]  # kept as the first run saved them
    for draw in order[2:]:
        assert resumed[draw][0]["seeds"]["robust"] == [draw + 2.0] * 2  # the second run's


def test_resume_over_other_seeds_scores_every_draw_again(bench: SimpleNamespace) -> None:
    """Draws saved with other seeds are not the ones asked for: a mean over seeds 1-2 kept
    beside draws over seeds 1-3 would mix the two in one table."""
    order = [draw for draw, _ in adapt_seeds.DRAWS]
    bench.stop_at = order[2]
    with pytest.raises(Stop):
        adapt_seeds.main([str(bench.sweep), "--seeds", "2"])
    bench.scored, bench.stop_at = [], None
    assert adapt_seeds.main([str(bench.sweep), "--seeds", "3", "--resume"]) == 0
    assert bench.scored == order
    assert json.loads(bench.out.read_text())["seeds"] == [1, 2, 3]
