"""``amsa-phys adapt`` on a sweep directory someone handed over: its ``results.csv`` is data.

A file larger than the limit is refused before a byte of it is read, and a line longer than
any row is refused when reached (memory holds one line, never the file): one line, exit 2.
"""

from __future__ import annotations

import os
import tracemalloc
from pathlib import Path

import pytest
from refusal import assert_one_line_refusal
from sweepfiles import two_context_sweep

from amsa_phys.adapt.table import read_table
from amsa_phys.cli.main import main
from amsa_phys.errors import ConfigError
from amsa_phys.model.scenario import load_scenario
from amsa_phys.runs.results import MAX_LINE_CHARS, MAX_RESULTS_BYTES

TABLE = {("healthy", 0.2): 0.5, ("healthy", 0.35): 0.9, ("worn", 0.2): 0.9, ("worn", 0.35): 0.5}


def _sweep(tmp_path: Path) -> tuple[Path, Path]:
    return two_context_sweep(tmp_path, TABLE)


def _peak_reading(results: Path, scenario: Path) -> tuple[str, int]:
    """What reading ``results`` raised, and the most memory the read held."""
    loaded = load_scenario(scenario)
    contexts = dict(loaded.data["sweep"]["contexts"])
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError) as caught:
            read_table(results, "rms_error", loaded.world, contexts, set())
        return str(caught.value), tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_a_huge_results_csv_is_refused_before_it_is_read(tmp_path: Path) -> None:
    scenario, sweep = _sweep(tmp_path)
    os.truncate(sweep / "results.csv", MAX_RESULTS_BYTES + (64 << 20))  # sparse
    why, peak = _peak_reading(sweep / "results.csv", scenario)
    assert "file too large" in why
    assert peak < 8 << 20


def test_a_line_longer_than_any_row_is_refused_unheld(tmp_path: Path) -> None:
    scenario, sweep = _sweep(tmp_path)
    with open(sweep / "results.csv", "a") as fh:
        fh.write("9,worn," + "1" * (4 * MAX_LINE_CHARS) + ",0,1,,0.5\n")
    why, peak = _peak_reading(sweep / "results.csv", scenario)
    assert "a line longer than 1024 KiB" in why
    assert peak < 3 * MAX_LINE_CHARS  # the line was never held whole


def test_adapt_refuses_a_huge_results_csv_in_one_line(tmp_path: Path, capsys) -> None:
    scenario, sweep = _sweep(tmp_path)
    os.truncate(sweep / "results.csv", 1 << 30)
    argv = ["adapt", str(sweep), "--scenario", str(scenario), "-o", str(tmp_path / "r.yaml")]
    code = main(argv)
    assert_one_line_refusal(code, capsys.readouterr().err, "file too large", "error: ")


def test_a_scenario_yaml_that_is_a_fifo_is_named_as_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Not "records no scenario.yaml": the file is there, and is not a file."""
    _, sweep = _sweep(tmp_path)
    os.mkfifo(sweep / "scenario.yaml")
    assert main(["adapt", str(sweep), "-o", str(tmp_path / "r.yaml")]) == 2
    assert capsys.readouterr().err == (
        f"error: {sweep / 'scenario.yaml'}: is not a regular file (a FIFO), expected a YAML file\n"
    )
