"""benchmarks.adapt_seeds --set: rules derived and scored with a fixed setting.

The full run is thousands of 600 s cases; these tests cover what a user types (``--set``
and a sweep run without that setting), that the setting reaches every way's case (the
robust gain, the rules, the oracle), and that the docs' block says what was fixed.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml
from refusal import assert_one_line_refusal

from benchmarks import adapt_seeds
from benchmarks.adapt_seeds import (
    SpecError,
    check_sweep_set,
    fix,
    markdown,
    parse_set,
)

KW = "MyFollowerController.Kw"


def test_set_parses_numbers() -> None:
    assert parse_set([f"{KW}=0.1", "Leader.behavior=4"]) == {KW: 0.1, "Leader.behavior": 4.0}
    assert parse_set([]) == {}


@pytest.mark.parametrize(
    ("texts", "says"),
    [
        (["Kw=0.1"], "not Component.param=VALUE"),
        ([KW], "not Component.param=VALUE"),
        ([f"{KW}=fast"], "'fast' is not a number"),
        ([f"{KW}=nan"], "not a finite number"),
        ([f"{KW}=0.1", f"{KW}=0.2"], "given twice"),
    ],
)
def test_bad_set_says_why(texts: list[str], says: str) -> None:
    with pytest.raises(SpecError, match=r"^--set:") as e:
        parse_set(texts)
    assert says in str(e.value)


def _sweepdir(tmp_path: Path, sets: dict | None) -> Path:
    data = {"duration": 200, **({"set": sets} if sets is not None else {})}
    (tmp_path / "scenario.yaml").write_text(yaml.safe_dump(data))
    (tmp_path / "results.csv").write_text("run\n")
    return tmp_path


def test_the_sweep_must_have_been_run_with_the_setting(tmp_path) -> None:
    check_sweep_set(_sweepdir(tmp_path, {KW: 0.1}), {KW: 0.1})  # the same: accepted
    with pytest.raises(SpecError, match=r"set: no MyFollowerController.Kw"):
        check_sweep_set(_sweepdir(tmp_path, None), {KW: 0.1})
    with pytest.raises(SpecError, match=r"is 0.04, not 0.1"):
        check_sweep_set(_sweepdir(tmp_path, {KW: 0.04}), {KW: 0.1})


@pytest.mark.parametrize(
    ("sets", "argv", "says"),
    [
        ({KW: 0.04}, [f"{KW}=0.1"], "is 0.04, not 0.1"),
        (None, [f"{KW}=0.1"], "set: no MyFollowerController.Kw"),
        ({KW: 0.1}, ["Kw=0.1"], "not Component.param=VALUE"),
    ],
)
def test_cli_errors_are_one_line_exit_2_and_write_nothing(
    tmp_path, capsys, monkeypatch, sets, argv, says
) -> None:
    out = tmp_path / "out.json"
    monkeypatch.setattr(adapt_seeds, "OUT_SET", out)
    (tmp_path / "sweep").mkdir()
    sweep = _sweepdir(tmp_path / "sweep", sets)
    code = adapt_seeds.main([str(sweep), "--seeds", "1", *(a for s in argv for a in ("--set", s))])
    assert_one_line_refusal(code, capsys.readouterr().err, says, "adapt_seeds: ")
    assert not out.exists()


def test_the_setting_reaches_every_way() -> None:
    """The robust gain's, the rules' and the oracle's cases all run with the fixed setting,
    and the sequence's contexts and the way's own gain still apply on top of it."""
    from amsa_phys.cli.adapt import load_scenario
    from amsa_phys.tune.contexts import box, sequences
    from amsa_phys.tune.evaluate import add_timeline_settings, case_data

    scenario = fix(load_scenario(str(adapt_seeds.SWEEP)), {KW: 0.1})
    axes = box(scenario, dict(scenario.data["sweep"]["contexts"]))
    (sequence,) = sequences(axes, 1, 600.0, 1000)
    kv = "MyFollowerController.Kv"
    robust = case_data(scenario, sequence, {kv: 0.2}, 600.0, None)
    rules = case_data(scenario, sequence, {kv: 0.2}, 600.0, [{"when": "x", "set": {}}])
    oracle = case_data(scenario, sequence, {}, 600.0, None)
    add_timeline_settings(oracle, [(0.0, {kv: 0.3})])
    for data in (robust, rules, oracle):
        assert data["set"][KW] == 0.1
        assert all(data["set"][k] == v for k, v in sequence.segments[0][1].items())
    assert robust["set"][kv] == rules["set"][kv] == 0.2
    assert oracle["set"][kv] == 0.3
    # without --set the shipped world's turning gain stays: nothing is set
    plain = load_scenario(str(adapt_seeds.SWEEP))
    assert KW not in case_data(fix(plain, {}), sequence, {kv: 0.2}, 600.0, None)["set"]


def test_the_block_says_what_was_fixed() -> None:
    doc = {
        "seeds": [1, 2, 3],
        "command": f"python -m benchmarks.adapt_seeds DIR --set {KW}=0.1 --seeds 3",
        "draws": [],
        "load": [1.0, 1.0, 1.0],
        "date": "2026-11-29T15:00:00+00:00",
        "set": {KW: 0.1},
    }
    text = markdown(doc)
    assert f"Rules derived from a sweep with {KW} 0.1 vs the robust Kv 0.2" in text
    assert f"every way with {KW} 0.1" in text
    del doc["set"]
    assert "*Rules vs the robust Kv 0.2, 600 s" in markdown(doc)


def _row(robust: list[float], rules: list[float]) -> dict:
    return {
        "index": 0,
        "sequence": "0 s {behavior 1, motorCoef 50}",
        "segments": [[0.0, {"Leader.behavior": 1}]],
        "seeds": {"robust": robust, "rules": rules, "oracle": robust},
        "stalls": {w: [[] for _ in robust] for w in ("robust", "rules", "oracle")},
    }


@pytest.mark.parametrize(("seeds", "columns"), [([1, 2, 3], 1), ([1, 2, 3, 4], 2)])
def test_three_seeds_are_one_column_not_two(seeds: list[int], columns: int) -> None:
    """Scored on seeds 1-3 only, the per-draw and lost tables do not repeat the same figures
    under two headings; with more seeds both the seeds 1-3 and the all-seeds columns show."""
    lost = _row([1.0] * len(seeds), [1.1] * len(seeds))  # 10 % worse: a lost sequence
    doc = {"seeds": seeds, "draws": [{"draw": 1000, "rows": [lost]}]}
    found = adapt_seeds.tables(doc)
    for key in ("per_draw", "lost"):
        heads = found[key]["columns"]
        per_seeds = [h for h in heads if re.fullmatch(r"(change ± s\.e\., )?seeds [0-9–]+", h)]
        assert len(per_seeds) == columns
        assert all(len(r) == len(heads) for r in found[key]["rows"])
