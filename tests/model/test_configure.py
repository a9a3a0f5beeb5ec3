"""Configuration as pure steps (model/configure.py) and the one trace-column check."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from amsa_phys.errors import ConfigError
from amsa_phys.model.configure import with_log_rate, with_overrides, with_seed, with_trace_columns
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
SCEN = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def test_each_option_is_a_new_scenario_and_the_given_one_is_untouched() -> None:
    base = load_scenario(SCEN)
    seeded = with_seed(base, 7)
    assert (seeded.seed, base.seed) == (7, load_scenario(SCEN).seed)
    faster = with_log_rate(base, 40)
    assert faster.log_rate == 40
    assert base.log_rate != 40
    traced = with_trace_columns(base, "Leader.*")
    assert traced.trace_columns == ("Leader.*",)
    assert base.trace_columns is None
    first = list(base.timeline.initial)
    more = with_overrides(base, ["MyFollowerController.Kv=0.2", "LeaderGPS.freq=8"], None)
    assert more.timeline.initial[-1].value == 0.2
    assert more.world.leaves["LeaderGPS"].freq == 8
    assert list(base.timeline.initial) == first
    assert base.world.leaves["LeaderGPS"].freq != 8


@pytest.mark.parametrize("seed", [-1, 2**63, True, 1.5])
def test_a_bad_seed_names_the_option(seed: object) -> None:
    with pytest.raises(ConfigError, match="must be an integer from 0 to") as info:
        with_seed(load_scenario(SCEN), seed)
    assert info.value.key == "--seed"


def test_trace_columns_are_judged_alike_in_the_file_and_on_the_command_line(
    tmp_path: Path,
) -> None:
    """One check (``scenariobuild.trace_problem``): the same message either way."""
    with pytest.raises(ConfigError) as option:
        with_trace_columns(load_scenario(SCEN), "Leader.*, Nobody.*")
    path = tmp_path / "s.yaml"
    text = SCEN.read_text().replace("world: ", "world: " + str(SCEN.parent) + "/", 1)
    path.write_text(text + 'trace_columns: "Leader.*, Nobody.*"\n')
    with pytest.raises(ConfigError) as in_file:
        load_scenario(path)
    assert option.value.message == in_file.value.message
    assert "Nobody.*" in option.value.message
    with pytest.raises(ConfigError, match="needs at least one pattern"):
        with_trace_columns(load_scenario(SCEN), " , ")


def test_shortening_keeps_the_plan_for_partial_phases() -> None:
    base = load_scenario(SCEN)
    cut = load_scenario(SCEN, duration=float(base.duration) / 2)
    assert cut.timeline.bounds()[-1] == base.duration
    assert cut.duration == Fraction(base.duration) / 2
