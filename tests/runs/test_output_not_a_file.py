"""An output file given by name (``runs/outfile.py``) that is a FIFO, a socket or a device is
refused even with ``--force``: the writer renames over the name, so ``adapt -o /dev/null
--force`` (or ``test --junit /dev/null``) run as root replaced the machine's ``/dev/null``
by a regular file. A FIFO stands in for a device here (making one needs no privilege)."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


@pytest.mark.parametrize("suffix", ["dot", "png"])
def test_graph_force_keeps_a_fifo(
    tmp_path: Path, suffix: str, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / f"g.{suffix}"
    os.mkfifo(out)
    assert main(["graph", str(WORLD), "-o", str(out), "--force"]) == 2
    assert capsys.readouterr().err == (
        f"error: {out}: --output: is a FIFO, not a file; amsa-phys writes only files "
        "(choose a file name)\n"
    )
    assert stat.S_ISFIFO(os.lstat(out).st_mode)


def test_junit_keeps_a_fifo(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        f"world: {WORLD}\nduration: 1\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "expect:\n  - {metric: collisions, below: 1}\n"
    )
    out = tmp_path / "report.xml"
    os.mkfifo(out)
    assert main(["test", str(scen), "--junit", str(out), "-j", "1"]) == 2
    assert "--junit: is a FIFO, not a file" in capsys.readouterr().err
    assert stat.S_ISFIFO(os.lstat(out).st_mode)
