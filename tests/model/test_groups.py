"""Like components of repeated Composites stepped as arrays (``engine/batch.py``).

A grouped run must read what the leaf-by-leaf run reads: same lost fixes, same parameter
changes, trajectories equal to ~1e-12 (numpy's last-bit rounding), and a world that would
read differently is not grouped at all.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from amsa_phys.cli.main import main
from amsa_phys.engine import batch
from amsa_phys.engine.rng import Drawn, DrawnMany
from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import RunFault
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
CARS = batch.MIN_GROUP + 4


def platoon(tmp_path: Path, **car_edits: Any) -> Path:
    """A platoon of ``CARS`` noisy, lossy cars with mid-run changes to two of them."""
    data = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    car = data["components"]["Car"]
    car["count"] = CARS
    # every GPS and compass feature on, in both the paper's names and Gazebo's
    car["components"]["Gps"]["params"] = {
        "noise": 0.3,
        "lostDataGPS": 20,
        "bias_mean": 0.2,
        "bias_stddev": 0.1,
        "dynamic_bias_stddev": 0.05,
        "dynamic_bias_correlation_time": 20.0,
        "precision": 0.01,
        "latency": 0.3,
        "burstLoss": 10.0,
        "burstLength": 3.0,
    }
    car["components"]["AheadGps"]["params"] = {
        "stddev": 0.3,
        "bias": 0.1,
        "lostDataGPS": 10,
        "dynamic_bias_stddev": 0.02,  # correlation time 0: a random walk
        "burstLoss": 5.0,
        "latency": 0.5,
    }
    car["components"]["Compass"]["params"] = {
        "noise": 0.01,
        "deviationB": 0.02,
        "deviationE": 0.01,
        "bias_mean": 0.01,
        "bias_stddev": 0.01,
        "dynamic_bias_stddev": 0.002,
        "dynamic_bias_correlation_time": 30.0,
        "precision": 0.0017,
        "lostData": 5.0,
    }
    for leaf, edit in car_edits.items():
        car["components"][leaf].update(edit)
    (tmp_path / "w.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    scen = tmp_path / "s.yaml"
    scen.write_text(
        "world: w.yaml\nduration: 40\nseed: 5\n"
        "timeline:\n"
        "  - {at: 10, set: {Car7.Pilot.Kv: 0.05, Car3.Drive.motorCoef: 70}}\n"
        "  - {at: 20.25, set: {Car9.Gps.lostDataGPS: 90, Car4.Gps.latency: 1.0,\n"
        "                      Car5.Compass.deviationB: 0.05, Car6.AheadGps.burstLength: 8}}\n"
    )
    return scen


def run(scen: Path, grouped: bool) -> tuple[Simulation, np.ndarray]:
    rows: list[list[float]] = []
    sim = Simulation.from_scenario(
        load_scenario(scen), trace=lambda t, v: rows.append([t, *v]), grouping=grouped
    )
    sim.run()
    return sim, np.array(rows)


def groups(sim: Simulation) -> set[str]:
    """The leaf names stepped in groups (``Pilot`` for Car1.Pilot .. CarN.Pilot)."""
    return {
        item.paths[0].split(".")[-1]
        for entry in sim._table
        for _, item in entry[1]
        if isinstance(item, batch.Group)
    }


def lost(sim: Simulation) -> dict[str, int]:
    return {path: c.lost for path, c in sim.components.items() if hasattr(c, "lost")}


def test_grouped_copies_run_like_the_leaf_by_leaf_run(tmp_path: Path) -> None:
    scen = platoon(tmp_path)
    fast, a = run(scen, grouped=True)
    slow, b = run(scen, grouped=False)
    assert groups(fast) == {"Robot", "Drive", "Pilot", "Gps", "AheadGps", "Compass", "Gap"}
    assert groups(slow) == set()
    assert lost(fast) == lost(slow)
    assert lost(fast)["Car9.Gps"] > lost(fast)["Car8.Gps"] + 40  # the 90 % from t = 20.25
    assert a.shape == b.shape
    assert np.abs(a - b).max() < 1e-9
    col = fast.columns.index("Car7.Pilot.LeftPower") + 1
    assert np.abs(a[:, col] - b[:, col]).max() < 1e-9
    # the changes reached the copies they name, and only those
    assert fast.components["Car7.Pilot"].p.Kv == 0.05
    assert (
        fast.components["Car8.Pilot"].p.Kv == 0.01
    )  # the world's value: the change reached Car7 only
    last = {name: a[-1, fast.columns.index(name) + 1] for name in fast.columns}
    assert last["Car3.Drive.normalizedPowerL"] != pytest.approx(0.0)


def test_groups_that_would_change_a_read_are_not_formed(tmp_path: Path) -> None:
    # each Pilot reads the gap the car ahead measured, and Gap runs after Pilot in a car:
    # car by car, Car(i).Pilot sees Car(i-1).Gap's new value; grouped it would see the old
    scen = platoon(
        tmp_path,
        Pilot={
            "inputs": {
                "xLeader": "AheadGps.gpsPosX",
                "yLeader": "AheadGps.gpsPosY",
                "xFollower": "Gps.gpsPosX",
                "yFollower": "Gps.gpsPosY",
                "headingFollower": "Compass.compassHeading",
                "distanceLeaderFollower": "Car{i-1}.Gap.distanceFollowerToLeader",
            }
        },
    )
    data = yaml.safe_load((tmp_path / "w.yaml").read_text())
    first = data["components"]["Car"]["first"]
    first["Pilot"] = {"inputs": {"distanceLeaderFollower": "Car1.Gap.distanceFollowerToLeader"}}
    (tmp_path / "w.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    fast, a = run(scen, grouped=True)
    _, b = run(scen, grouped=False)
    # Pilot and Gap step car by car; so must the sensors the Pilots read (moved ahead of a
    # later car's Pilot, a grouped Gps would change what it reads); Robot and Drive still group
    assert groups(fast) == {"Robot", "Drive"}
    assert np.abs(a - b).max() < 1e-9


def test_a_grouped_run_replays_from_its_resolved_scenario(tmp_path: Path) -> None:
    scen = platoon(tmp_path)
    a, b = tmp_path / "a", tmp_path / "b"
    args = ["--headless", "-q", "--no-plot", "--duration", "8"]
    assert main(["run", str(scen), "--out", str(a), *args]) == 0
    assert main(["run", str(a / "scenario.yaml"), "--out", str(b), *args]) == 0
    assert (a / "trace.csv").read_bytes() == (b / "trace.csv").read_bytes()


def test_many_streams_at_once_yield_what_each_yields_alone() -> None:
    def streams() -> list[Drawn]:
        return [Drawn(np.random.default_rng(k).standard_normal, block=5) for k in range(3)]

    alone = [[d() for _ in range(12)] for d in streams()]
    many = DrawnMany(streams(), block=5)
    columns = [many() for _ in range(12)]  # kept: a refill must not overwrite them
    assert np.array(columns).T.tolist() == alone
    # uniform draws, and a callable that is no Generator method (filled by stacking)
    for draw in (np.random.default_rng(8).random, lambda n: np.random.default_rng(8).random(n)):
        many = DrawnMany([Drawn(draw, block=5)], block=5)
        assert [float(many()[0]) for _ in range(3)] == np.random.default_rng(8).random(3).tolist()
    used = streams()
    used[1]()
    with pytest.raises(RuntimeError, match="drawn from before"):
        DrawnMany(used)


def test_a_fault_in_a_group_names_the_copy_and_the_time(tmp_path: Path) -> None:
    # copy 13's factor becomes 0 at t = 1.5: 1 / 0 is inf, which no buffer accepts
    boxes: dict[str, Any] = {
        f"Box{i}": {
            "components": {
                "Div": {"template": "toys:Divider", "freq": 2, "inputs": {"x": "Src.count"}}
            }
        }
        for i in range(1, CARS + 1)
    }
    world = {"components": {"Src": {"template": "toys:Source", "freq": 2}, **boxes}}
    (tmp_path / "w.yaml").write_text(yaml.safe_dump(world))
    scen = tmp_path / "s.yaml"
    scen.write_text("world: w.yaml\nduration: 5\ntimeline:\n  - {at: 1.5, set: {Box13.Div.k: 0}}\n")
    for grouped in (True, False):
        sim = Simulation.from_scenario(load_scenario(scen), grouping=grouped)
        sim.initialize()
        assert ("Div" in groups(sim)) is grouped
        with pytest.raises(RunFault) as exc:
            sim.run()
        assert exc.value.component.startswith("Box13.Div")
        assert exc.value.t == 1.5
        assert "output y is inf" in exc.value.cause


def test_copies_with_latency_and_a_phase_still_group_copies_with_jitter_do_not(
    tmp_path: Path,
) -> None:
    scen = platoon(
        tmp_path,
        Pilot={"latency": 0.5},  # every copy's commands 0.5 s late: one delay line
        Gps={"phase": 0.1},  # every copy's GPS timer shifted alike
        Drive={"jitter": 0.1},  # each copy's messages at their own instants
    )
    fast, a = run(scen, grouped=True)
    slow, b = run(scen, grouped=False)
    assert groups(fast) == {"Robot", "Pilot", "Gps", "AheadGps", "Compass", "Gap"}
    assert lost(fast) == lost(slow)
    assert np.abs(a - b).max() < 1e-9
    # the latency is there: a Pilot's first command (at 0.25 s: at t = 0 its Gap, which runs
    # after it, has measured nothing yet) reaches its buffer 0.5 s later
    col = fast.columns.index("Car3.Pilot.LeftPower") + 1
    first = a[np.flatnonzero(a[:, col] != 0.0)[0], 0]
    assert first == 0.75
