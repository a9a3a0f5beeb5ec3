"""The GNSS receiver in the ROS 1 export: it reads the world's geometry, so it runs inside the
simulator node (as the lidar does), never as a remote node without a world."""

from __future__ import annotations

from pathlib import Path

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.graph import classify

ROOT = Path(__file__).resolve().parent.parent.parent


def test_gnss_receivers_run_beside_the_physics() -> None:
    world = load_scenario(ROOT / "scenarios" / "paper_fig6_urban.yaml").world
    local = classify(world)
    assert local == ["Leader", "Follower", "LeaderGPS", "FollowerGPS"]
