"""A runtime changes what the engine does through its plugs (``engine/plugs.py``), not by
overriding its methods: the ROS simulator's timeline values from the parameter server, the
adapt node's firings and the pipeline's drain at the end all go through these points, so
each is checked here without ROS: called where and when the engine would act, and what it
returns is what the run does."""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from pathlib import Path

from amsa_phys.engine.adapt import AdaptRules
from amsa_phys.engine.plugs import Plugs
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.adaptrules import RULE_COLUMN, Rule
from amsa_phys.model.scenario import Change, Scenario, load_scenario

ROOT = Path(__file__).resolve().parents[2]
KV = "MyFollowerController"


def _scenario(tmp_path: Path, extra: str = "") -> Scenario:
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 4\nseed: 1\n"
        f"set: {{{KV}.Kv: 0.35}}\n"
        f"timeline:\n  - {{at: 2, set: {{{KV}.Kv: 0.15}}, new_phase: false}}\n{extra}"
    )
    return load_scenario(path)


class ServerValues(Plugs):
    """A timeline value from elsewhere (as the ROS simulator takes the parameter server's)."""

    def __init__(self) -> None:
        self.asked: list[tuple[Change, Fraction]] = []
        self.ended = 0

    def timeline_change(self, change: Change, at: Fraction) -> Change:
        self.asked.append((change, at))
        return Change(change.leaf, change.param, 0.6)

    def run_ended(self) -> None:
        self.ended += 1


def _kv_over_time(sim: Simulation) -> dict[float, float]:
    seen: dict[float, float] = {}
    sim.add_log_listener(lambda t, _v: seen.setdefault(t, sim.components[KV].p.Kv))
    sim.run()
    return seen


def test_a_timeline_change_takes_the_value_its_plug_gives(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path)
    own = _kv_over_time(Simulation.from_scenario(scenario))
    plugs = ServerValues()
    sim = Simulation.from_scenario(scenario, plugs=plugs)
    plugged = _kv_over_time(sim)
    # asked once, at the change's own instant, with the timeline's change
    assert [(c.key, c.value, at) for c, at in plugs.asked] == [(f"{KV}.Kv", 0.15, Fraction(2))]
    assert own[1.95] == plugged[1.95] == 0.35
    assert own[2.0] == 0.15
    assert plugged[2.0] == 0.6
    assert sim.change_log[-1][1].value == 0.6  # recorded as applied (scenario.yaml's replay)


def test_the_end_of_the_run_is_told_once(tmp_path: Path) -> None:
    plugs = ServerValues()
    sim = Simulation.from_scenario(_scenario(tmp_path), plugs=plugs)
    sim.initialize()
    sim.advance(sim.grid.ticks(Fraction(1)))
    assert plugs.ended == 0  # not at a chunk's end, only at the run's
    sim.advance(sim.grid.ticks(Fraction(4)))
    assert plugs.ended == 1


RULES = f"""adapt:
  - when: {{MyDistanceMonitor.distanceFollowerToLeader: {{above: -1000}}}}
    set: {{{KV}.Kv: 0.5}}
    hold: 1
"""


class Told(Plugs):
    """The rules decided elsewhere (as ``rules:=node`` asks the adapt node)."""

    def __init__(self) -> None:
        self.put: list[Change] = []

    def rule_due(
        self, rules: AdaptRules, now: Fraction, values: Mapping[str, float]
    ) -> tuple[Rule, str] | None:
        if now != Fraction(3):
            return None
        rules.switches += 1
        return rules.rules[0], "told by a node"

    def rule_change(self, change: Change) -> None:
        self.put.append(change)


def test_a_rule_fires_where_its_plug_says(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path, RULES)
    own = Simulation.from_scenario(scenario)
    own_result = own.run()
    own_fired = [e.t for e in own_result.events if e.kind == "adapt"]
    assert own_fired
    assert own_fired[0] < 3
    plugs = Told()
    sim = Simulation.from_scenario(scenario, plugs=plugs)
    result = sim.run()
    adapt = [(e.t, e.detail) for e in result.events if e.kind == "adapt"]
    assert adapt == [(3.0, "told by a node")]
    assert [c.key for c in plugs.put] == [f"{KV}.Kv"]  # put before the Leaf was told
    assert sim.components[KV].p.Kv == 0.5
    assert sim.read(RULE_COLUMN) == 1.0
    assert result.adapt_switches == 1
