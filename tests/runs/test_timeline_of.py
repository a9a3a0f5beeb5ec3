"""A run directory's timeline, read as data, is the Timeline the run ran.

``runs.rundata.timeline_of`` reads the resolved ``scenario.yaml``'s ``set:`` and
``timeline:`` without building the world (nothing it names is imported), and the plots ask it
instead of walking the YAML themselves: phases, steps inside a phase (``new_phase: false``)
and exact instants (``"61/4"``) as the loader reads them.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.timeline import Timeline
from amsa_phys.plots.zones import zones_of
from amsa_phys.runs.rundata import timeline_of
from amsa_phys.templatemarks import Zone

ROOT = Path(__file__).resolve().parents[2]
WORLD = (ROOT / "tests" / "fixtures" / "mud_track_world.yaml").read_text()
SCENARIO = """\
world: w.yaml
duration: 30
set: {Mud.friction: 0.5}
timeline:
  - {at: 2, set: {Mud.friction: 0.1, Mud.rollingResistance: 0.3}, label: ice}
  - {at: "61/4", set: {Ctl.left: 50}, new_phase: false}
  - {at: 20, set: {Mud.friction: 0.9}, label: dry}
"""


def _points(timeline: Timeline) -> list[tuple]:
    return [
        (p.at, p.phase, p.starts_phase, p.label, [(c.key, c.value) for c in p.changes])
        for p in timeline.points()
    ]


def test_the_timeline_read_as_data_is_the_loaders(tmp_path: Path) -> None:
    (tmp_path / "w.yaml").write_text(WORLD)
    (tmp_path / "s.yaml").write_text(SCENARIO)
    loaded = load_scenario(tmp_path / "s.yaml").timeline
    read = timeline_of(yaml.safe_load(SCENARIO))
    assert _points(read) == _points(loaded)
    assert [(c.key, c.value) for c in read.initial] == [("Mud.friction", 0.5)]
    assert read.duration == loaded.duration
    assert read.starts == loaded.starts  # the step at 61/4 s starts no phase


def test_a_hand_edited_entry_is_left_out_not_fatal() -> None:
    data = yaml.safe_load(SCENARIO)
    data["timeline"].insert(1, {"at": "soon", "set": {"Mud.friction": 2}})
    data["timeline"].append("not an entry")
    del data["duration"]
    read = timeline_of(data)
    assert [p.at for p in read.points()] == [2, 15.25, 20]
    assert read.duration == 20  # none readable: the run ends at its last change
    assert timeline_of(None).points() == ()


def test_a_zones_label_says_its_ground_from_the_timeline() -> None:
    data = yaml.safe_load(SCENARIO)
    world = yaml.safe_load(WORLD)["components"]
    mark = Zone()
    (zone,) = zones_of({"Mud": world["Mud"]["params"]}, {"Mud": mark}, timeline_of(data))
    # set: gives the value at t = 0 (the world's 0.8 never ran); each later change is said
    assert zone.friction == 0.5
    assert zone.label == "Mud: μ 0.5, Crr 0.02; from 2 s μ 0.1, Crr 0.3; from 20 s μ 0.9"
