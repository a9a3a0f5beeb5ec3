"""``runs.evaluate``: arbitrary points give the rows a sweep gives for them, byte for byte,
whichever executor runs them, each tagged with its position."""

from __future__ import annotations

import csv
import re
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.errors import ConfigError
from amsa_phys.runs.evaluate import evaluate

ROOT = Path(__file__).resolve().parent.parent.parent
SCEN = ROOT / "scenarios" / "paper_fig5_kv01.yaml"


def test_rows_equal_the_sweeps_rows_for_the_same_points(tmp_path: Path) -> None:
    out = tmp_path / "s"
    grid = ["--grid", "MyNormalizePower.motorCoef=40,70", "--grid", "Leader.cruisePower=3.5,9.25"]
    assert main(["sweep", str(SCEN), *grid, "--duration", "15", "-j", "1", "--out", str(out)]) == 0
    with open(out / "results.csv", newline="") as fh:
        swept = list(csv.DictReader(fh))
    points = [
        (
            (
                ("MyNormalizePower.motorCoef", int(r["MyNormalizePower.motorCoef"])),
                ("Leader.cruisePower", float(r["Leader.cruisePower"])),
            ),
            int(r["seed"]),
        )
        for r in swept
    ]
    points.reverse()  # any order: the index says which point a row is
    for executor, workers in [("batch", 1), ("batch", 2), ("local", 2)]:
        rows = list(evaluate(SCEN, points, duration=15, executor=executor, workers=workers))
        assert sorted(r["index"] for r in rows) == [0, 1, 2, 3]
        for row in rows:
            want = swept[len(points) - 1 - row["index"]]
            got = {k: "" if row[k] is None else str(row[k]) for k in want}
            assert got == {**want, "run": str(row["index"])}, executor  # run: its position


def test_bad_executor_settings_fail_before_anything_runs() -> None:
    with pytest.raises(ConfigError, match=re.escape("--executor: expected one of batch")):
        evaluate(SCEN, [], executor="threads")
    with pytest.raises(ConfigError, match=re.escape("--executor: the Dask executor needs")):
        evaluate(SCEN, [], executor="dask")
    with pytest.raises(ConfigError, match=re.escape("--jobs: must be at least 1")):
        evaluate(SCEN, [], workers=0)
    assert list(evaluate(SCEN, [])) == []
