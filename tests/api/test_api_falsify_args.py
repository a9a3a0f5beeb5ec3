"""``ap.falsify``'s wrong arguments: each a one-line ConfigError naming the argument as it
was passed, raised before the search starts, with the command's bounds (``--budget``,
``--trials``, ``--seed``, ``--duration``, ``--metric``, ``-j``). They met the search deep
inside: a numpy TypeError, a ZeroDivisionError, every run an error row, a search that never
ended (``duration=1e9``), or the whole budget spent on a misspelt metric."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

import amsa_phys as ap
from amsa_phys.api import falsify as falsify_module

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = str(ROOT / "scenarios" / "falsify_resonance.yaml")
BOX = {"Leader.changePeriod": (2, 40), "Leader.cruisePower": (3, 12)}
TOP = 2**63 - 1

CASES: dict[str, tuple[dict[str, Any], str]] = {
    "budget-float": ({"budget": 1.5}, "budget=: must be an integer from 1 to 1,000,000, got 1.5"),
    "budget-str": ({"budget": "10"}, "budget=: must be an integer from 1 to 1,000,000, got '10'"),
    "trials-float": ({"trials": 1.5}, "trials=: must be an integer from 1 to 1,000, got 1.5"),
    "seed-str": ({"seed": "a"}, f"seed=: must be an integer from 0 to {TOP} (2**63 - 1), got 'a'"),
    "seed-top": (
        {"seed": TOP - 1, "trials": 3},
        f"seed=: must be an integer from 0 to {TOP - 2} (2**63 - 1 less the 2 more trials), "
        f"got {TOP - 1}",
    ),
    "duration-negative": ({"duration": -1}, "duration=: must be a positive finite number"),
    "duration-nan": ({"duration": float("nan")}, "duration=: must be a positive finite number"),
    "duration-too-long": ({"duration": 1e9}, "duration=: must be at most 1,000,000 s"),
    "metric-misspelt": (
        {"metric": "rms_eror"},
        "metric=: unknown metric 'rms_eror' (did you mean rms_error?)",
    ),
    "box-list": ({"box": [("Leader.changePeriod", (2, 40))]}, "box=: expected a mapping"),
    "box-words": (
        {"box": {"Leader.changePeriod": ("a", "b")}},
        'box={"Leader.changePeriod": ...}: a range\'s bounds must be finite numbers',
    ),
    "box-empty": ({"box": {}}, "box=: nothing to search: give at least one"),
    "box-unknown-component": (
        {"box": {"Nobody.x": (0, 1)}},
        "box={\"Nobody.x\": ...}: unknown component 'Nobody'",
    ),
    "box-bounds-reversed": (
        {"box": {"Leader.changePeriod": (40, 2)}},
        'box={"Leader.changePeriod": ...}: the lower bound 40 must be below the upper bound 2',
    ),
    "executor-dask": ({"executor": "dask"}, "executor=: expected one of batch, local"),
    "workers-zero": ({"workers": 0}, "workers=: must be an integer >= 1, got 0"),
    "cost-not-callable": ({"cost": 3}, "cost=: expected a function of a result row, got 3"),
}


@pytest.fixture
def no_search(monkeypatch: pytest.MonkeyPatch) -> None:
    """The search refuses to start: a wrong argument must be said before it."""

    def search(*_: Any, **__: Any) -> Any:
        raise AssertionError("the search started with a wrong argument")

    monkeypatch.setattr(falsify_module, "search", search)


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_wrong_argument_is_one_line_naming_it_before_the_search(
    case: str, no_search: None
) -> None:
    given, said = CASES[case]
    kwargs: dict[str, Any] = {"budget": 5, **given}
    box = kwargs.pop("box", BOX)
    with pytest.raises(ap.ConfigError) as refused:
        ap.falsify(SCENARIO, box, **kwargs)
    text = str(refused.value)
    assert text.startswith(said)
    assert "\n" not in text


def test_a_mapping_is_a_type_error_saying_a_file_is_searched(no_search: None) -> None:
    with pytest.raises(TypeError, match="expected a scenario file path, got dict"):
        ap.falsify({"world": "worlds/mde_challenge.yaml"}, BOX, budget=5)  # type: ignore[arg-type]


def test_right_arguments_still_search(tmp_path: Path) -> None:
    """A whole-number duration, a phase's metric and one worker: the search runs."""
    found = ap.falsify(SCENARIO, BOX, budget=2, metric="phase0.rms_error", duration=4, workers=1)
    assert found.summary["objective"] == "phase0.rms_error"
    assert len(found.rows[0]) == 2


def test_a_cost_of_nan_counts_as_the_worst_and_falsifies() -> None:
    """As the falsification page says: a cost function that gives NaN (a metric it divides
    by zero, say) is judged as a faulted run is, the worst there is."""
    found = ap.falsify(SCENARIO, BOX, budget=2, duration=4, cost=lambda row: math.nan)
    assert found.falsified
    assert found.trials[0].simulations == 1  # stopped at the first run


def test_the_commands_warnings_are_search_warnings_worded_for_python() -> None:
    """The command prints them on ``warning:`` lines; ``ap.falsify`` dropped them all (a
    cut requirement window, ``search_on`` without a requirement, a timeline axis)."""
    with pytest.warns(ap.SearchWarning) as said:
        ap.falsify(SCENARIO, BOX, budget=2, duration=4, search_on=True)
    texts = [str(w.message) for w in said if issubclass(w.category, ap.SearchWarning)]
    assert "search_on=True only matters with requirement=: the whole budget is spent" in texts
    assert not any("--" in t for t in texts)
