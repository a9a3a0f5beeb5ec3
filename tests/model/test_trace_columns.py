"""``trace_columns:`` / ``--trace-columns``: a narrower trace.csv that changes nothing else,
and the size note before a run whose trace would pass a gigabyte."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

import amsa_phys
from amsa_phys.cli.main import main
from amsa_phys.cli.run import warn_if_trace_is_large
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
SHORT = ROOT / "tests" / "fixtures" / "mde_short.yaml"
SIGNAL = "MyDistanceMonitor.distanceFollowerToLeader"


def read(path: Path) -> tuple[list[str], list[list[str]]]:
    with path.open() as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def test_selected_columns_hold_the_full_traces_values(tmp_path: Path) -> None:
    """The selection keeps the matching buffers in world order, plus the quality signal
    the run reads back; every kept value is the full trace's, byte for byte."""
    argv = ["run", str(SHORT), "--headless", "--duration", "20", "-q", "--no-plot"]
    assert main([*argv, "--out", str(tmp_path / "all")]) == 0
    assert (
        main([*argv, "--out", str(tmp_path / "some"), "--trace-columns", "Follower.*,*.pos?"]) == 0
    )
    full_head, full = read(tmp_path / "all" / "trace.csv")
    head, rows = read(tmp_path / "some" / "trace.csv")
    assert head[0] == "t"
    assert SIGNAL in head  # not asked for, but the quality signal is always kept
    assert "LeaderGPS.gpsPosX" not in head
    assert {"Follower.posX", "Follower.heading", "Leader.posX", "Leader.posY"} <= set(head)
    assert head == [c for c in full_head if c in set(head)]  # world order
    idx = [full_head.index(c) for c in head]
    assert rows == [[r[i] for i in idx] for r in full]

    # metrics are computed from the run, not from the file: identical
    def measured(name: str) -> dict:
        m = json.loads((tmp_path / name / "metrics.json").read_text())
        return {k: m[k] for k in ("overall", "phases", "events", "simulated")}

    assert measured("all") == measured("some")


def test_the_resolved_scenario_replays_the_selection(tmp_path: Path) -> None:
    argv = ["run", "--headless", "--duration", "5", "-q", "--no-plot"]
    assert (
        main(
            [
                argv[0],
                str(SHORT),
                *argv[1:],
                "--out",
                str(tmp_path / "a"),
                "--trace-columns",
                "Leader.*",
            ]
        )
        == 0
    )
    resolved = tmp_path / "a" / "scenario.yaml"
    assert main([argv[0], str(resolved), *argv[1:], "--out", str(tmp_path / "b")]) == 0
    assert (tmp_path / "a" / "trace.csv").read_bytes() == (
        tmp_path / "b" / "trace.csv"
    ).read_bytes()


def run_with_columns(out: Path, patterns: str) -> int:
    """``amsa-phys run`` of the short scenario with ``--trace-columns patterns``."""
    return main(["run", str(SHORT), "--headless", "--out", str(out), "--trace-columns", patterns])


def test_a_pattern_that_keeps_nothing_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = run_with_columns(tmp_path / "o", "Leadr.*")
    err = capsys.readouterr().err
    assert code == 2
    assert (
        err.strip()
        == "error: --trace-columns: 'Leadr.*' matches no Data buffer (did you mean Leader.posY?)"
        or (err.count("\n") == 1 and "'Leadr.*' matches no Data buffer" in err)
    )
    assert not (tmp_path / "o").exists()


def test_the_python_api_takes_a_list_of_patterns() -> None:
    run = amsa_phys.run(SHORT, duration=2, trace_columns=["Follower.posX"])
    assert run.columns == ["t", "Follower.posX", SIGNAL]


def test_a_wide_long_run_says_how_large_its_trace_will_be(
    capsys: pytest.CaptureFixture[str],
) -> None:
    long = load_scenario(SHORT, duration=400_000)  # ~30 columns at 20 Hz: ~4.7 GB
    warn_if_trace_is_large(long)
    err = capsys.readouterr().err
    assert err.startswith("amsa-phys: note: trace.csv will be about ")
    assert "--trace-columns" in err
    assert err.count("\n") == 1
    narrow = load_scenario(SHORT, duration=400_000, trace_columns="Leader.posX")
    warn_if_trace_is_large(narrow)  # 2 columns: ~0.4 GB, no note
    short = load_scenario(SHORT, duration=300)
    warn_if_trace_is_large(short)
    assert capsys.readouterr().err == ""


def test_the_file_takes_the_options_comma_string_too(tmp_path: Path) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 1\n"
        'trace_columns: "Leader.pos?, Follower.posX"\n'
    )
    assert load_scenario(scen).trace_columns == ("Leader.pos?", "Follower.posX")


def test_a_pattern_in_the_wrong_case_is_named_with_what_it_would_match(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code = run_with_columns(tmp_path / "o", "leader.*")
    assert code == 2
    assert capsys.readouterr().err == (
        "error: --trace-columns: 'leader.*' matches no Data buffer: patterns are case-sensitive "
        "(it would match Leader.posX ignoring case)\n"
    )


def test_the_api_refuses_patterns_that_are_not_strings() -> None:
    with pytest.raises(amsa_phys.ConfigError, match=r"^trace_columns=: expected glob patterns"):
        amsa_phys.run(SHORT, duration=1, trace_columns=5)  # type: ignore[arg-type]
