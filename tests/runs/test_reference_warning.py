"""A controller's setpoint moved away from ``quality.reference`` is warned, not silently judged
against the old reference (the metrics would measure the distance from a value the controller
no longer aims at)."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import amsa_phys as ap
from amsa_phys.model.scenario import load_scenario
from amsa_phys.runs.references import reference_notes

ROOT = Path(__file__).resolve().parents[2]
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def test_a_set_setpoint_is_named_with_both_values() -> None:
    (note,) = reference_notes(load_scenario(SCENARIO1, ["MyFollowerController.distanceRef=20"]))
    assert note.startswith("MyFollowerController.distanceRef is 20 m")
    assert "quality.reference 15 m" in note


def test_a_timeline_entry_is_named_with_its_time(tmp_path: Path) -> None:
    text = (
        SCENARIO1.read_text()
        .replace("world: ../worlds/", f"world: {ROOT}/worlds/")
        .replace(
            "{at: 250, set: {MyFollowerController.Kv: 0.1}}",
            "{at: 250, set: {MyFollowerController.Kv: 0.1, MyFollowerController.distanceRef: 12}}",
        )
    )
    path = tmp_path / "s.yaml"
    path.write_text(text)
    (note,) = reference_notes(load_scenario(path))
    assert "is 12 m from t = 250 s" in note


def test_agreeing_values_are_quiet(tmp_path: Path) -> None:
    text = SCENARIO1.read_text().replace("world: ../worlds/", f"world: {ROOT}/worlds/")
    text = text.replace("reference: 15,", "reference: 20,")
    path = tmp_path / "s.yaml"
    path.write_text(text)
    assert reference_notes(load_scenario(path, ["MyFollowerController.distanceRef=20"])) == []


@pytest.mark.parametrize("path", sorted((ROOT / "scenarios").glob("*.yaml")), ids=lambda p: p.name)
def test_no_shipped_scenario_warns(path: Path) -> None:
    assert reference_notes(load_scenario(path)) == []


def test_the_api_warns_at_the_callers_line() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ap.load(str(SCENARIO1), set={"MyFollowerController.distanceRef": 20})
    (warning,) = [w for w in caught if issubclass(w.category, ap.ReferenceWarning)]
    assert warning.filename == __file__


def test_the_cli_warns_on_one_line(tmp_path: Path) -> None:
    argv = [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO1), "--headless", "--no-plot"]
    argv += ["--duration", "1", "--out", str(tmp_path / "r"), "-q"]
    argv += ["--set", "MyFollowerController.distanceRef=20"]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=300, check=False)
    lines = [x for x in done.stderr.splitlines() if "distanceRef" in x]
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("warning: ")
