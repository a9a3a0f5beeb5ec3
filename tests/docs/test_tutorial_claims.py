"""What the tutorials' prose says a command does, checked (their commands run in
test_docs_examples.py; the sentences around them are checked here)."""

from __future__ import annotations

from pathlib import Path

import pytest

import amsa_phys as ap

ROOT = Path(__file__).resolve().parents[2]
FIRST = ROOT / "docs" / "examples" / "first_scenario.yaml"
#: the timeline stops the wheels at 27 s, after the set= value has done its work: expected
pytestmark = pytest.mark.filterwarnings("ignore:Pilot.right is given by set=")


def test_a_stronger_right_wheel_curves_into_the_obstacle_at_52_percent() -> None:
    """tutorial-world.md: `--set Pilot.right=52` takes the rover into the box at (10, 4) at
    t = 12.6 s, and the scenario's collision check then fails."""
    run = ap.run(FIRST, set={"Pilot.right": 52})
    hits = [e for e in run.events if e.kind == "collision"]
    assert [(round(e.t, 1), e.detail) for e in hits] == [(12.6, "Rover-obstacle[0]")]
    assert not run.passed


def test_at_60_percent_it_turns_circles_near_its_start() -> None:
    """tutorial-world.md: at `--set Pilot.right=60` the rover turns circles of about 3 m
    radius near its start (it never reaches the obstacle or the goal)."""
    run = ap.run(FIRST, set={"Pilot.right": 60})
    x, y = run.trace["Rover.posX"], run.trace["Rover.posY"]
    assert 5.0 < y.max() < 7.0  # a circle's diameter: ~6 m
    assert x.max() < 5.0
    assert x.min() > -5.0
    assert not [e for e in run.events if e.kind == "collision"]
