"""``amsa-phys adapt`` trusts nothing it reads: results.csv cells, names, the sweep's own
scenario.yaml; and it says when switching is not worth it instead of writing rules."""

from __future__ import annotations

import sys
import tracemalloc
from fractions import Fraction
from pathlib import Path

import pytest
import yaml

from amsa_phys.adapt.table import read_table
from amsa_phys.cli.main import main
from amsa_phys.engine import adapt as engine_adapt
from amsa_phys.engine.adapt import AdaptRules
from amsa_phys.model.adaptrules import Condition, Rule
from amsa_phys.model.scenario import Change, load_scenario

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "adapt"
LOOSE = ["--margin", "inf", "--min-gain", "0"]


def _sweep(tmp_path: Path, rows: str | None = None) -> Path:
    out = tmp_path / "sweep"
    out.mkdir()
    text = (FIXTURE / "results.csv").read_text()
    out.joinpath("results.csv").write_text(rows if rows is not None else text)
    return out


def _adapt(sweep: Path, out: Path, *extra: str) -> int:
    argv = ["adapt", str(sweep), "--scenario", str(FIXTURE / "sweep.yaml"), "-o", str(out)]
    return main([*argv, *extra])


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        (",0.1,0,1,,0.8,", ",inf,0,1,,0.8,", "MyFollowerController.Kv"),
        (",0.1,0,1,,0.8,", ",1e300,0,1,,0.8,", "MyFollowerController.Kv"),
        (",0.1,0,1,,0.8,", ",fast,0,1,,0.8,", "MyFollowerController.Kv"),
        (",0.1,0,1,,0.8,", ",0.1,0,1,,nan,", "rms_error"),
        (",0.1,0,1,,0.8,", ",0.1,0,1,,text,", "rms_error"),
        ("0,nominal,", "0,nowhere,", "context"),
    ],
    ids=["inf", "1e300", "text", "nan-metric", "text-metric", "unknown-context"],
)
def test_a_bad_cell_is_one_line_naming_file_row_column(tmp_path, capsys, old, new, words):
    sweep = _sweep(tmp_path, (FIXTURE / "results.csv").read_text().replace(old, new, 1))
    out = tmp_path / "rules.yaml"
    assert _adapt(sweep, out, *LOOSE) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert "results.csv:2:" in err, err
    assert words in err, err
    assert not out.exists()


@pytest.mark.parametrize("metric", ["seed", "run", "MyFollowerController.Kv", "nope"])
def test_only_a_metric_column_is_a_metric(tmp_path, capsys, metric):
    out = tmp_path / "rules.yaml"
    assert _adapt(_sweep(tmp_path), out, "--metric", metric, *LOOSE) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert "--metric" in err, err


def test_names_with_newlines_and_escapes_stay_names(tmp_path, capsys):
    """A context named with a newline, YAML and ESC: the rules file loads, the terminal is safe."""
    evil = "worn\n- adapt: x\x1b[2J"
    scenario = yaml.safe_load((FIXTURE / "sweep.yaml").read_text())
    scenario["world"] = str(ROOT / "worlds" / "mde_adaptive.yaml")
    scenario["sweep"]["contexts"][evil] = scenario["sweep"]["contexts"].pop("worn")
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(scenario))
    rows = (FIXTURE / "results.csv").read_text().replace(",worn,", ',"' + evil + '",')
    sweep = _sweep(tmp_path, rows)
    out = tmp_path / "rules.yaml"
    argv = ["adapt", str(sweep), "--scenario", str(path), "-o", str(out), *LOOSE]
    assert main(argv) == 0
    printed = capsys.readouterr()
    assert "\x1b" not in printed.out + printed.err
    user = tmp_path / "s.yaml"
    user.write_text(
        yaml.safe_dump({"world": scenario["world"], "duration": 5, "adapt": "rules.yaml"})
    )
    labels = [r.label for r in load_scenario(user).adapt]
    assert evil in labels  # the name itself, as data, not YAML


def test_not_worth_adapting_writes_no_rules(tmp_path, capsys):
    """Every cell's best is the same gain: the oracle gains nothing, no file is written."""
    rows = (FIXTURE / "results.csv").read_text().splitlines()
    same = [rows[0]]
    for row in rows[1:]:
        cells = row.split(",")
        cells[6] = "0.5" if cells[2] == "0.2" else "0.6"
        same.append(",".join(cells))
    out = tmp_path / "rules.yaml"
    assert _adapt(_sweep(tmp_path, "\n".join(same) + "\n"), out) == 0
    text = capsys.readouterr().out
    assert "no rules written: not worth adapting" in text
    assert "would lower the mean rms_error by" in text  # a robustness.NAME: "raise"
    assert "MyFollowerController.Kv=0.2" in text
    assert not out.exists()


def test_a_gain_next_to_an_unstable_one_is_not_chosen(tmp_path, capsys):
    """worn's lowest (Kv 0.4) has a failed neighbour run at 0.2: its best is the robust."""
    text = (
        (FIXTURE / "results.csv")
        .read_text()
        .replace("8,worn,0.2,0,1,,1.0,20", "8,worn,0.2,0,1,diverged,,")
    )
    out = tmp_path / "rules.yaml"
    assert _adapt(_sweep(tmp_path, text), out, "--min-gain", "0") == 0
    rules = yaml.safe_load(out.read_text())["adapt"]
    assert not any(
        r["label"] == "worn" and r["set"]["MyFollowerController.Kv"] == 0.4 for r in rules
    )
    assert "(not 0.4 at 0.6: a neighbour is unstable or far worse)" in capsys.readouterr().out


def test_results_are_streamed_in_bounded_memory(tmp_path):
    """50,000 rows (2.5 MB; as rows ~35 MB) keep a few hundred kB: sums per grid point."""
    lines = ["run,context,MyFollowerController.Kv,seed_index,seed,error,rms_error"]
    ctx = ["nominal", "worn", "random", "speed changes"]
    lines += [f"{i},{ctx[i % 4]},{0.1 * (1 + i % 3):.1f},{i},{i},,0.5" for i in range(50_000)]
    path = tmp_path / "results.csv"
    path.write_text("\n".join(lines) + "\n")
    scenario = load_scenario(FIXTURE / "sweep.yaml")
    contexts = scenario.data["sweep"]["contexts"]
    tracemalloc.start()
    table = read_table(path, "rms_error", scenario.world, contexts, set())
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert table.rows == 50_000
    assert peak < 2_000_000, peak


def test_a_sweep_dir_records_its_scenario_and_never_imports_a_module(tmp_path, capsys):
    sweep = _sweep(tmp_path)
    assert main(["adapt", str(sweep), "-o", str(tmp_path / "r.yaml")]) == 2
    assert "--scenario" in capsys.readouterr().err
    marker = tmp_path / "h43marker.py"
    marker.write_text("import pathlib\npathlib.Path(__file__).with_suffix('.ran').touch()\n")
    data = yaml.safe_load((FIXTURE / "sweep.yaml").read_text())
    data["world"] = yaml.safe_load((ROOT / "worlds" / "mde_adaptive.yaml").read_text())
    data["world"]["components"]["Extra"] = {"template": "h43marker:Thing", "freq": 1}
    sweep.joinpath("scenario.yaml").write_text(yaml.safe_dump(data))
    sys.path.insert(0, str(tmp_path))
    try:
        assert main(["adapt", str(sweep), "-o", str(tmp_path / "r.yaml")]) == 2
    finally:
        sys.path.remove(str(tmp_path))
    err = capsys.readouterr().err
    assert "h43marker:Thing" in err
    assert "not imported" in err
    assert not (tmp_path / "h43marker.ran").exists()
    assert "h43marker" not in sys.modules


def test_a_real_sweep_is_adapted_without_scenario(tmp_path, capsys):
    scenario = tmp_path / "s.yaml"
    data = yaml.safe_load((FIXTURE / "sweep.yaml").read_text())
    data["world"] = str(ROOT / "worlds" / "mde_adaptive.yaml")
    data["sweep"]["contexts"] = {
        "nominal": {"Leader.behavior": 1},
        "random": {"Leader.behavior": 4},
    }
    data["sweep"]["grid"] = {"MyFollowerController.Kv": [0.1, 0.2]}
    scenario.write_text(yaml.safe_dump(data))
    out = tmp_path / "sweep"
    assert main(["sweep", str(scenario), "--out", str(out), "--executor", "batch", "-j", "1"]) == 0
    assert (out / "scenario.yaml").is_file()
    rules = tmp_path / "rules.yaml"
    assert main(["adapt", str(out), "-o", str(rules), *LOOSE]) == 0
    assert rules.is_file()


def test_switches_are_counted_all_and_kept_bounded(monkeypatch):
    monkeypatch.setattr(engine_adapt, "KEPT_FIRINGS", 5)
    rules = [
        Rule(1, (Condition("S.x", below=0.5),), (Change("C", "Kv", 0.1),), Fraction(0)),
        Rule(2, (Condition("S.x", above=0.5),), (Change("C", "Kv", 0.2),), Fraction(0)),
    ]
    params = {"Kv": 0.0}
    state = AdaptRules(rules, lambda leaf, p: params[p])
    for k in range(100):
        f = state.due(Fraction(k, 4), {"S.x": float(k % 2)})
        if f is not None:
            params["Kv"] = f.rule.changes[0].value
    assert state.switches == 100
    assert len(state.fired) == 5


def test_metrics_say_when_switch_events_are_cut():
    from amsa_phys.engine.context import Event, RunResult
    from amsa_phys.model.metrics import _event_counts

    events = [Event(float(i), "adapt", "rule 1") for i in range(1000)]
    result = RunResult(0.0, None, None, events, adapt_switches=3601)  # type: ignore[arg-type]
    assert _event_counts(result) == {"adapt_switches": 3601, "events_truncated": True}
    whole = RunResult(0.0, None, None, events[:10], adapt_switches=10)  # type: ignore[arg-type]
    assert _event_counts(whole) == {"adapt_switches": 10}
    from amsa_phys.cli.report import adapt_line

    line = adapt_line([{"t": e.t, "detail": "rule 1 (a): L.Kv=1 (E.x=1)"} for e in events], 3601)
    assert line.startswith("adapt: 3601 switches:")
    assert "2601 more not listed" in line
