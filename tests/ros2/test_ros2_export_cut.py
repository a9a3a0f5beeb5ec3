"""``export ros2 --duration S``: the package's lockstep run is ``run --duration S``'s.

The package keeps the file's whole scenario (a check of a phase the cut never reaches still
names a phase of that file, so it validates) and the cut in ``config/amsa.yaml``;
``ros2 lockstep`` applies it as ``run --duration`` does: the same trace, byte for byte, and
the same checks skipped. ROS 2 runs in ``unshare -n`` (``ros2net.py``).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from ros2net import EXPORT_ENV, PY, ROOT, amsa, in_private_network, ros2_missing

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

ENV = EXPORT_ENV
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"  # 4 phases, checks of phase 3; 100 s: 1


def test_a_cut_package_validates_and_locksteps_as_run_duration(tmp_path: Path) -> None:
    pkg, ref, out = tmp_path / "pkg", tmp_path / "ref", tmp_path / "lock"
    amsa("export", "ros2", str(SCENARIO), "-o", str(pkg), "--duration", "100")
    checked = amsa("validate", str(pkg / "config" / "scenario1.yaml"), check=False)
    assert checked.returncode == 0, checked.stderr
    amsa("run", str(SCENARIO), "--headless", "--no-plot", "-q", "--out", str(ref), "--duration=100")
    script = tmp_path / "netns.sh"
    script.write_text(
        f"ip link set lo up\n{PY} -m amsa_phys ros2 lockstep {pkg} --out {out} --no-plot\n"
    )
    log = tmp_path / "netns.log"
    rc, left = in_private_network(script, ENV, log)
    text = log.read_text()
    assert rc == 0, text
    # what it starts and waits for, said before the run (not a silent minute)
    assert f"starting 6 nodes of {pkg} (LeaderGPS, FollowerGPS," in text
    assert "then 100 simulated s in lockstep" in text
    assert "waiting up to 60 s for ROS 2 node /MyFollowerController (ROS_DOMAIN_ID=" in text
    assert left == []
    assert (out / "trace.csv").read_bytes() == (ref / "trace.csv").read_bytes()
    # the same checks judged and skipped (phase 3's never reached), the same replay file
    want = json.loads((ref / "metrics.json").read_text())
    got = json.loads((out / "metrics.json").read_text())
    for key in ("phases", "overall", "requirements"):
        assert got[key] == want[key], key
    assert (out / "scenario.yaml").read_bytes() == (ref / "scenario.yaml").read_bytes()
