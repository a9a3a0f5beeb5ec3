"""``amsa-phys monitor RUNDIR FORMULA``: the run's own robustness, read from data only."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
DIST = "MyDistanceMonitor.distanceFollowerToLeader"
BAND = f"always[10:30](abs({DIST} - 15) <= 3.5)"


@pytest.fixture(scope="module")
def rundir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("mon")
    sc = tmp / "s.yaml"
    sc.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 30\nseed: 1\nlog_rate: 4\n"
        "set: {Leader.behavior: 1, MyFollowerController.Kv: 0.35}\n"
        f'expect:\n  - {{stl: "{BAND}", name: band}}\n'
    )
    out = tmp / "run"
    assert main(["run", str(sc), "--headless", "--out", str(out)]) == 0
    return out


def test_monitor_gives_the_runs_own_robustness_from_the_trace_alone(
    rundir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    want = json.loads((rundir / "metrics.json").read_text())["requirements"]["band"]
    bare = tmp_path / "bare"  # trace.csv only: the scenario is never read (no import)
    bare.mkdir()
    shutil.copy(rundir / "trace.csv", bare / "trace.csv")
    capsys.readouterr()
    assert main(["monitor", str(bare), BAND, "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["robustness"] == want["robustness"]
    assert got["instant"] == want["instant"]
    assert main(["monitor", str(bare), f"always({DIST} <= 15)"]) == 1
    assert "fail" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("formula", "words"),
    [
        (f"always({DIST} <= )", "does not parse"),
        ("always(Follower.sped > 0)", "did you mean Follower.speed?"),
        ("always[0:0.1](t >= 0)", "not a multiple of the log period 0.25 s"),
        ("always[0:31](t >= 0)", "after the run's end at 30 s"),
    ],
)
def test_bad_formulas_are_one_line_exit_2(
    rundir: Path, capsys: pytest.CaptureFixture[str], formula: str, words: str
) -> None:
    capsys.readouterr()
    assert main(["monitor", str(rundir), formula]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err
    assert "\n" not in err


def test_a_directory_without_a_trace_or_a_broken_trace_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["monitor", str(tmp_path), "always(t >= 0)"]) == 2
    (tmp_path / "trace.csv").write_text("t,a\n0,1\n0.5,x\n")
    assert main(["monitor", str(tmp_path), "always(a >= 0)"]) == 2
    (tmp_path / "trace.csv").write_text("t,a\n0,1\n0.5,2\n0.6,3\n")
    assert main(["monitor", str(tmp_path), "always(a >= 0)"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "not evenly spaced" in err
