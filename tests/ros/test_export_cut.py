"""``export ros --duration S`` without ROS: the package runs what ``run --duration S`` runs.

The package keeps the file's whole scenario (its checks of later phases name phases that
exist there) and the cut as the launch file's ``duration:=`` default, which the simulator
applies with ``records.cut``, the cut of ``run --duration``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.runtime import records

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"  # 4 phases; checks of phase 3


def _export(tmp_path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> Path:
    out = tmp_path / "pkg"
    assert main(["export", "ros", str(SCENARIO), "-o", str(out), *extra]) == 0
    capsys.readouterr()
    return out


def _duration_default(pkg: Path) -> str:
    root = ET.parse(pkg / "launch" / "scenario1.launch").getroot()
    return next(a.get("default") for a in root.iter("arg") if a.get("name") == "duration")


def test_a_cut_package_validates_and_its_run_is_run_duration(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = _export(tmp_path, capsys, "--duration", "100")
    config = pkg / "config" / "scenario1.yaml"
    assert main(["validate", str(config)]) == 0, capsys.readouterr().err
    default = _duration_default(pkg)
    ran = records.cut(load_scenario(config), default)  # what the simulator node does
    want = load_scenario(SCENARIO, duration=100)
    assert ran.timeline == want.timeline  # same phases, same end, phase 0 cut short
    assert [e.phase for e in ran.expect] == [e.phase for e in want.expect]


def test_an_uncut_package_runs_the_whole_scenario(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert _duration_default(_export(tmp_path, capsys)) == ""


def test_the_export_says_how_long_the_package_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "pkg"
    assert main(["export", "ros", str(SCENARIO), "-o", str(out), "--duration", "100"]) == 0
    said = capsys.readouterr().out
    assert "it runs 100 s (the launch files' duration:= default" in said
    assert "the scenario file keeps its 500 s" in said
