"""``count:`` Composites (the platoon) and the batch physics path that carries many rovers."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

import amsa_phys.physics.fleet as fleet
from amsa_phys.cli.main import main
from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import ConfigError, RunFault
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.world import load_world

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "platoon.yaml"
SCENARIO = ROOT / "scenarios" / "platoon.yaml"


def test_count_instantiates_the_cars_and_links_each_to_the_one_ahead() -> None:
    world = load_world(WORLD)
    cars = sorted({p.split(".")[0] for p in world.leaves if p.startswith("Car")})
    assert len(cars) == 10
    assert world.leaves["Car1.AheadGps"].inputs == {"posX": "Leader.posX", "posY": "Leader.posY"}
    assert world.leaves["Car3.AheadGps"].inputs == {
        "posX": "Car2.Robot.posX",
        "posY": "Car2.Robot.posY",
    }
    assert world.leaves["Car3.Pilot"].inputs["xFollower"] == "Car3.Gps.gpsPosX"
    assert [world.leaves[f"Car{i}.Robot"].params["x"] for i in (1, 2, 10)] == [-12, -24, -120]
    # each car's own schedule, written out per copy, orders its loop
    order = world.order
    assert order.index("Car4.Robot") < order.index("Car4.Drive") < order.index("Car4.Pilot")


def write_world(tmp_path: Path, edit: dict) -> Path:
    data = yaml.safe_load(WORLD.read_text())
    car = data["components"]["Car"]
    for key, value in edit.items():
        car[key] = value
    path = tmp_path / "w.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        ({"first": {"Pilt": {"inputs": {}}}}, "Car.first.Pilt: no component 'Pilt' in this"),
        ({"schedule": ["Robot", "Drvie"]}, "Car.schedule[1]: no component 'Drvie'"),
        ({"count": 0}, "components.Car.count: must be >= 1, got 0"),
    ],
)
def test_count_mistakes_are_one_line_errors(tmp_path: Path, edit: dict, message: str) -> None:
    with pytest.raises(ConfigError) as exc:
        load_world(write_world(tmp_path, edit))
    assert message in str(exc.value)
    assert "\n" not in str(exc.value)


def test_a_link_to_a_car_that_does_not_exist_names_it(tmp_path: Path) -> None:
    path = write_world(tmp_path, {"first": {}})  # Car1 would read Car0
    with pytest.raises(ConfigError) as exc:
        load_world(path)
    assert "unknown component 'Car0.Robot'" in str(exc.value)


def test_platoon_run_replays_from_its_resolved_scenario(tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    args = ["--headless", "-q", "--no-plot", "--duration", "20"]
    assert main(["run", str(SCENARIO), "--out", str(a), *args]) == 0
    resolved = yaml.safe_load((a / "scenario.yaml").read_text())
    assert "Car10" in resolved["world"]["components"]
    assert "Car" not in resolved["world"]["components"]
    assert main(["run", str(a / "scenario.yaml"), "--out", str(b), *args]) == 0
    assert (a / "trace.csv").read_bytes() == (b / "trace.csv").read_bytes()


def final_poses(monkeypatch: pytest.MonkeyPatch, batch_min: int) -> list[tuple[float, ...]]:
    monkeypatch.setattr(fleet, "BATCH_MIN", batch_min)
    sim = Simulation.from_scenario(load_scenario(SCENARIO, duration=60))
    sim.run()
    return [(*r.pose, r.forward_speed, *r.wheel_speeds()) for r in sim.shared["physics"].rovers]


def test_batch_physics_matches_the_per_rover_path(monkeypatch: pytest.MonkeyPatch) -> None:
    per_rover = final_poses(monkeypatch, 10**9)
    batch = final_poses(monkeypatch, 2)
    assert len(batch) == 11
    for a, b in zip(per_rover, batch, strict=True):
        assert a == pytest.approx(b, abs=1e-9)
    assert per_rover[-1][0] > -60  # the last car really drove (it started at x = -120)


def test_batch_physics_reports_a_blow_up_like_the_per_rover_path(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    faults = []
    for batch_min in (10**9, 2):
        monkeypatch.setattr(fleet, "BATCH_MIN", batch_min)
        sc = load_scenario(SCENARIO, duration=30)
        sc.world.physics["max_speed"] = 1.0  # the leader cruises faster than this
        with pytest.raises(RunFault) as exc:
            Simulation.from_scenario(sc).run()
        faults.append((exc.value.component, exc.value.t, exc.value.cause))
    assert faults[0] == faults[1]
    assert "exceeds physics.max_speed 1 m/s" in faults[0][2]
