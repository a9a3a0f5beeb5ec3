"""World ``data:`` names and a scenario's ``set: {Leaf.freq: Hz}`` (the values an imported
AMSA model carries or leaves to a scenario)."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from amsa_phys.errors import ConfigError
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.world import load_world
from amsa_phys.runs.resolve import resolved_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def world_with(tmp_path: Path, extra: str) -> Path:
    path = tmp_path / "w.yaml"
    path.write_text(WORLD.read_text() + extra)
    return path


def test_data_names_are_resolved_to_buffers(tmp_path: Path) -> None:
    world = load_world(world_with(tmp_path, "data: {posXLeader: Leader.posX}\n"))
    assert world.data_names == {"posXLeader": "Leader.posX"}


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ("data: {x: Leadr.posX}\n", "unknown component 'Leadr'"),
        ("data: {x: Leader.posZ}\n", "has no output 'posZ'"),
        ("data: {Leader.x: Leader.posX}\n", "'Leader' is not a Composite"),
        ("data: {x: 3}\n", "expected a string"),
    ],
)
def test_bad_data_names_are_one_line_with_the_key(tmp_path: Path, extra: str, message: str) -> None:
    with pytest.raises(ConfigError) as info:
        load_world(world_with(tmp_path, extra))
    assert message in str(info.value)
    assert "data" in str(info.value)


def scenario(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "s.yaml"
    path.write_text(f"world: {WORLD}\nduration: 10\n{body}")
    return path


def test_a_scenario_sets_a_leafs_frequency_for_the_whole_run(tmp_path: Path) -> None:
    s = load_scenario(scenario(tmp_path, 'set: {MyNormalizePower.freq: "10/3", Leader.x: 12.0}\n'))
    assert s.world.leaves["MyNormalizePower"].freq == Fraction(10, 3)
    assert [c.key for c in s.timeline.initial] == ["Leader.x"]  # not a parameter change
    resolved = resolved_scenario(s)
    assert "MyNormalizePower.freq" not in resolved["set"]
    assert resolved["world"]["components"]["MyNormalizePower"]["freq"] == 10 / 3
    s2 = load_scenario(scenario(tmp_path, ""), overrides=["MyNormalizePower.freq=8"])
    assert s2.world.leaves["MyNormalizePower"].freq == 8


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("set: {MyNormalizePower.freq: 0}\n", "a frequency must be in (0, 1e6] Hz"),
        ("set: {MyNormalizePower.freq: fast}\n", "expected a frequency in Hz"),
        ("set: {MyNormalizePower.freq: true}\n", "expected a frequency in Hz"),
        (
            "timeline:\n  - {at: 5, set: {MyNormalizePower.freq: 2}}\n",
            "set it in set:, not in the timeline",
        ),
    ],
)
def test_bad_frequencies_are_refused(tmp_path: Path, body: str, message: str) -> None:
    with pytest.raises(ConfigError) as info:
        load_scenario(scenario(tmp_path, body))
    assert message in str(info.value)
    assert "MyNormalizePower.freq" in str(info.value)
