"""Which gain a cell's rule sets: not merely the lowest mean of the cell.

A held-out context lies between the sweep's levels and its estimate is never exact, so a
gain that wins little in its own cell loses where the rule misplaces the context. A cell
keeps the robust gain unless another wins there by ``cell_gain``, and of the gains level
with its best (within ``near``) it takes the one fewest grid steps from the robust gain.
"""

from __future__ import annotations

from pathlib import Path

from sweepfiles import two_context_sweep

from amsa_phys.adapt.derive import derive
from amsa_phys.model.scenario import load_scenario


def _best(tmp_path: Path, table: dict[tuple[str, float], float], **kw: float) -> dict[str, float]:
    tmp_path.mkdir(exist_ok=True)
    scenario, sweep = two_context_sweep(tmp_path, table)
    # no safety margin: these tables test the choice among gains, not the margin
    found = derive(sweep / "results.csv", load_scenario(scenario), margin=float("inf"), **kw)
    assert found.robust == {"MyFollowerController.Kv": 0.2}
    return {c.name: c.best["MyFollowerController.Kv"] for c in found.cells}


#: healthy motors: Kv 0.15 is 8 % better than the robust 0.2; worn: 0.3 and 0.4 are level
#: (1 %), both half the robust gain's error
TABLE = {
    ("healthy", 0.15): 0.92,
    ("healthy", 0.2): 1.0,
    ("healthy", 0.3): 2.2,
    ("healthy", 0.4): 3.0,
    ("worn", 0.15): 3.0,
    ("worn", 0.2): 2.0,
    ("worn", 0.3): 1.01,
    ("worn", 0.4): 1.0,
}


def test_a_cell_keeps_the_robust_gain_unless_another_wins_enough_there(tmp_path: Path) -> None:
    best = _best(tmp_path, TABLE, cell_gain=0.15, near=0.0)
    assert best == {"healthy": 0.2, "worn": 0.4}
    # asked for any gain at all, the healthy cell takes its 8 %
    assert _best(tmp_path / "any", TABLE, cell_gain=0.0, near=0.0)["healthy"] == 0.15


def test_of_gains_level_with_the_best_the_one_nearest_the_robust_gain(tmp_path: Path) -> None:
    assert _best(tmp_path, TABLE, near=0.05)["worn"] == 0.3
    # 1 % apart is level within 5 %, not within 0.5 %
    assert _best(tmp_path / "tight", TABLE, near=0.005)["worn"] == 0.4


def test_the_table_says_why_the_lowest_mean_was_not_chosen(tmp_path: Path) -> None:
    scenario, sweep = two_context_sweep(tmp_path, TABLE)
    found = derive(sweep / "results.csv", load_scenario(scenario), margin=float("inf"))
    why = {c.name: (c.unsafe, c.why) for c in found.cells}
    assert why["healthy"] == (
        ({"MyFollowerController.Kv": 0.15}, 0.92),
        "less than 15 % better than the robust point",
    )
    assert why["worn"] == (
        ({"MyFollowerController.Kv": 0.4}, 1.0),
        "level within 5 % and nearer the robust point",
    )
