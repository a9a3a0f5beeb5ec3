"""An exported node's first answer reaches a run its node had not discovered yet.

DDS discovery is not symmetric: ``ros2 lockstep`` can see a node's writer (and step the
node) before the node has seen lockstep's reader, and a RELIABLE, VOLATILE writer never
delivers a message to a reader it had not matched when it wrote. The first answer was then
lost and lockstep waited for it in vain (``no message on /MyDistanceMonitor/... within 10 s
of its inputs of t=0 s``, seen under load). The exported node holds its first answer until
its writers have matched a reader. The probe steps it before it has any reader at all.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from ros2net import EXPORT_ENV, PY, ROOT, amsa, in_private_network, ros2_missing

PROBE = Path(__file__).resolve().parent / "late_reader_probe.py"


@pytest.mark.ros2
def test_the_first_answer_waits_for_a_reader(tmp_path: Path) -> None:
    missing = ros2_missing()
    if missing:
        pytest.skip(missing)
    pkg = tmp_path / "pkg"
    amsa("export", "ros2", str(ROOT / "scenarios" / "scenario1.yaml"), "-o", str(pkg), "-q")
    script, log, out = tmp_path / "probe.sh", tmp_path / "probe.log", tmp_path / "probe.out"
    script.write_text(f"ip link set lo up\n{PY} {PROBE} {pkg} >{out}\n")
    rc, left = in_private_network(script, EXPORT_ENV, log)
    assert rc == 0, log.read_text()
    assert left == []
    # both answers, in order: the first one was held until a reader was there
    assert out.read_text().split() == ["3.0", "5.0"], log.read_text()
