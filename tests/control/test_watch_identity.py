"""An estimator watches a shipped template's Leaf by class, not by name.

``GPSLossMonitor`` declares that its loss rate estimates ``lostDataGPS`` of a ``GPS``. A
user's subclass of the shipped GPS has that parameter with that meaning, so it is watched;
a user's own template that only happens to be called ``GPS`` is another receiver, whose
parameters need not mean the shipped one's, so it is not (it was, by name).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.control.estimators.watches import watches
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]

USER_TEMPLATES = ROOT / "tests" / "fixtures" / "usertemplates"  # usergps.py


def _watched(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, template: str) -> dict[str, str]:
    monkeypatch.syspath_prepend(str(USER_TEMPLATES))
    world = (ROOT / "worlds" / "mde_adaptive.yaml").read_text()
    old = "  LeaderGPS:\n    template: GPS\n"
    assert old in world
    (tmp_path / "world.yaml").write_text(
        world.replace(old, f"  LeaderGPS:\n    template: {template}\n")
    )
    text = (ROOT / "scenarios" / "adaptive.yaml").read_text()
    text = text.replace("world: ../worlds/mde_adaptive.yaml", "world: world.yaml")
    text = text.replace("adapt: rules/adaptive_rules.yaml", "")
    (tmp_path / "s.yaml").write_text(text)
    found = watches(load_scenario(tmp_path / "s.yaml").world)
    return {w.signal: w.key for w in found}


def test_the_shipped_gps_and_a_subclass_are_watched(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for template in ("GPS", "usergps:BiasedGPS"):
        watched = _watched(tmp_path, monkeypatch, template)
        assert watched["LeaderGPSMonitor.lossRate"] == "LeaderGPS.lostDataGPS", template


def test_a_template_that_only_shares_the_name_is_not(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    watched = _watched(tmp_path, monkeypatch, "usergps:GPS")
    # the nearest shipped GPS instead (the follower's), never the look-alike
    assert watched["LeaderGPSMonitor.lossRate"] == "FollowerGPS.lostDataGPS"
    assert watched["MotorMonitor.delivered"] == "MyNormalizePower.motorCoef"  # others still
