"""A box of ``--grid`` axes only holds a finite number of points: the search runs each once
and stops when all are run, saying so, however large its budget. It used to run the first
generation's repeats, then restart the optimizer for ever on points already run (the
population doubling each time), ignoring Ctrl-C, and never write its results."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.falsify import search
from amsa_phys.falsify.space import build_space
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"


def test_a_grid_box_is_run_point_by_point_and_the_search_ends(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "f"
    argv = ["falsify", str(SCENARIO), "--budget", "40", "-j", "1", "--duration", "5"]
    argv += ["--grid", "MyFollowerController.Kv=0.1,0.2", "--grid", "Leader.cruisePower=40,60"]
    assert main([*argv, "--out", str(out)]) == 0
    with (out / "results.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    points = {(r["MyFollowerController.Kv"], r["Leader.cruisePower"]) for r in rows}
    assert len(rows) == len(points) == 4  # each point once, then nothing left to run
    err = capsys.readouterr().err
    assert "the search stopped after 4 of its 40 runs: every point of the box was run" in err


def test_the_box_counts_its_points() -> None:
    scenario = load_scenario(SCENARIO)
    grid = build_space(scenario, [], ["MyFollowerController.Kv=0.1,0.2,0.3", "Leader.behavior=1,4"])
    assert search.box_points(grid) == 6
    mixed = build_space(scenario, ["MyFollowerController.Kv=0.1:0.3"], ["Leader.behavior=1,4"])
    assert search.box_points(mixed) == float("inf")


def test_resuming_a_finished_search_says_what_it_found(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--resume`` of a search that had finished printed nothing at all."""
    out = tmp_path / "f"
    argv = ["falsify", str(SCENARIO), "--budget", "3", "-j", "1", "--duration", "5"]
    argv += ["--range", "MyFollowerController.Kv=0.05:0.3", "--out", str(out)]
    assert main(argv) == 0
    before = (out / "results.csv").read_bytes()
    capsys.readouterr()
    assert main([*argv, "--resume"]) == 0
    said = capsys.readouterr().out
    assert said == f"already finished: 3 runs, no violation; results in {out} (nothing run again)\n"
    assert (out / "results.csv").read_bytes() == before
