"""Trace rows kept in memory a block at a time (``log.RowBlock``) are the rows the row-by-row
path writes, bit for bit, and a read in the middle of a run sees every row logged so far."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from amsa_phys.api.source import load
from amsa_phys.engine.log import RowBlock
from amsa_phys.engine.runner import Simulation
from amsa_phys.engine.tracemem import TraceMemory
from amsa_phys.model.scenario import Scenario

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def simulation(scenario: Scenario, trace: Any, columns: list[str] | None) -> Simulation:
    kwargs = Simulation.scenario_kwargs(scenario)
    if columns is not None:
        kwargs["columns"] = columns
    return Simulation(scenario.world, trace=trace, **kwargs)


def reference(columns: list[str] | None, duration: float) -> np.ndarray:
    """The trace written row by row through a plain callable (no blocks)."""
    scenario = load(str(SCENARIO1), duration=duration)
    rows: list[list[float]] = []
    sim = simulation(scenario, lambda t, row: rows.append([t, *row]), columns)
    sim.run()
    return np.array(rows, dtype=np.float64)


@pytest.mark.parametrize("subset", [False, True], ids=["all columns", "some columns"])
def test_rows_taken_in_blocks_are_the_rows_written_one_by_one(subset: bool) -> None:
    scenario = load(str(SCENARIO1), duration=60)  # 1,201 rows: two full blocks and a part
    columns = list(scenario.world.buffers)
    if subset:
        columns = columns[3::2]
    memory = TraceMemory(columns)
    sim = simulation(scenario, memory.write, columns)
    assert sim.log._block is not None  # the block path is the one under test
    logged = 0
    for stop in (1_700, 5_000, 10**9):  # reads in mid-run see every row logged so far
        sim.advance(stop)
        logged = int(min(stop, sim._end) // sim._log_period) + 1
        assert memory.rows == logged
    memory.close()
    assert logged > 2 * RowBlock.SIZE
    got = memory.matrix()
    want = reference(columns, 60)
    assert got.shape == want.shape
    assert got.tobytes() == want.tobytes()
