"""The box falsify searches: bounds judged up front, values rounded as the parameter's type,
the Latin hypercube's strata."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.errors import ConfigError
from amsa_phys.falsify.search import latin_hypercube, stratified_choices
from amsa_phys.falsify.space import Dim, build_space, parse_bounds
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
SCEN = ROOT / "scenarios" / "paper_fig5_kv01.yaml"


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(SCEN)


@pytest.mark.parametrize(
    ("ranges", "grids", "message"),
    [
        (
            ["Leader.cruisePower=12:3"],
            [],
            "--range Leader.cruisePower: the lower bound 12 must be below the upper bound 3",
        ),
        (
            ["Leader.cruisePower=5:5"],
            [],
            "--range Leader.cruisePower: the lower bound 5 must be below the upper bound 5",
        ),
        (
            ["Leader.cruisePower=3"],
            [],
            "--range: expected Comp.param=lo:hi, got 'Leader.cruisePower=3'",
        ),
        (
            ["Leader.cruisePowr=3:12"],
            [],
            "--range Leader.cruisePowr: unknown parameter of template freeRobot "
            "(did you mean cruisePower?)",
        ),
        (
            ["Leadr.cruisePower=3:12"],
            [],
            "--range Leadr.cruisePower: unknown component 'Leadr' (did you mean Leader?)",
        ),
        (
            ["MyNormalizePower.motorCoef=40:120"],
            [],
            "--range MyNormalizePower.motorCoef: 120 is above the maximum 100 (range [0, 100])",
        ),
        (
            ["LeaderGPS.lostDataGPS=-5:60"],
            [],
            "--range LeaderGPS.lostDataGPS: -5 is below the minimum 0 (range [0, 100])",
        ),
        (
            ["Leader.behavior=1:3"],
            [],
            "--range Leader.behavior: behavior is not a number (enum: one of 1, 2, 3, 4, 5, "
            "straight, circle, speedChanges, random, waypoints): give its values with --grid",
        ),
        (
            ["LeaderGPS.lostDataGPS=0.2:0.8"],
            [],
            "--range LeaderGPS.lostDataGPS: an integer parameter needs two integers in 0.2:0.8",
        ),
        (
            ["Leader.cruisePower=3:12", "Leader.cruisePower=4:5"],
            [],
            "falsify: Leader.cruisePower appears twice",
        ),
        (
            [],
            [],
            "falsify: nothing to search: give --range Comp.param=lo:hi"
            " or --grid Comp.param=a,b,...",
        ),
        (
            [],
            ["Leader.behavior=1,7"],
            "--grid Leader.behavior: expected one of 1, 2, 3, 4, 5, straight, circle, "
            "speedChanges, random, waypoints, got integer 7",
        ),
    ],
    ids=[
        "lo-above-hi",
        "lo-equals-hi",
        "no-colon",
        "unknown-param",
        "unknown-component",
        "above-max",
        "below-min",
        "enum-range",
        "no-integer-inside",
        "twice",
        "nothing",
        "bad-grid-value",
    ],
)
def test_bad_boxes_are_one_line_errors(scenario, ranges, grids, message) -> None:
    with pytest.raises(ConfigError, match=f"^{re.escape(message)}$"):
        build_space(scenario, ranges, grids)


def test_a_box_keeps_the_command_line_order_and_types(scenario) -> None:
    space = build_space(
        scenario,
        ["LeaderGPS.lostDataGPS=0.5:60", "Leader.cruisePower=3:12"],
        ["Leader.behavior=1,3"],
    )
    assert [(d.key, d.kind, d.lo, d.hi) for d in space.numeric] == [
        ("LeaderGPS.lostDataGPS", "int", 1.0, 60.0),  # integer bounds inside the range
        ("Leader.cruisePower", "float", 3.0, 12.0),
    ]
    assert space.categorical[0].choices == (1, 3)
    assert space.decode([0.5, 1 / 3], [1]) == (
        ("LeaderGPS.lostDataGPS", 30),  # 1 + 0.5 * 59 = 30.5, rounded half to even
        ("Leader.cruisePower", 6.0),
        ("Leader.behavior", 3),
    )


def test_values_are_rounded_to_the_parameter_and_clipped_to_the_box() -> None:
    width_60 = Dim("a.b", "float", 40.0, 100.0)
    assert width_60.value(0.123456789) == 47.4074  # six significant digits at the width
    assert width_60.value(-0.2) == 40.0
    assert width_60.value(1.7) == 100.0
    whole = Dim("a.n", "int", 0.0, 60.0)
    assert whole.value(0.51) == 31
    assert isinstance(whole.value(0.51), int)
    assert whole.is_integer
    assert whole.levels()[:3] == [0.0, 1 / 60, 2 / 60]
    assert not Dim("a.n", "int", 0.0, 5000.0).is_integer  # searched as continuous, rounded


def test_parse_bounds_reads_floats() -> None:
    assert parse_bounds(" Leader.cruisePower = -3.5:1e1") == ("Leader.cruisePower", -3.5, 10.0)


@pytest.mark.parametrize(("n", "dims"), [(10, 3), (7, 1), (30, 2)])
def test_latin_hypercube_has_one_point_in_every_stratum_of_every_axis(n: int, dims: int) -> None:
    u = latin_hypercube(np.random.default_rng(3), n, dims)
    assert u.shape == (n, dims)
    for j in range(dims):
        assert sorted(np.floor(u[:, j] * n).astype(int).tolist()) == list(range(n))


def test_categories_are_drawn_evenly() -> None:
    c = stratified_choices(np.random.default_rng(1), 10, [3, 2])
    assert sorted(np.bincount(c[:, 0]).tolist()) == [3, 3, 4]
    assert np.bincount(c[:, 1]).tolist() == [5, 5]
