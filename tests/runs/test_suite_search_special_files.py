"""``test FOLDER`` searches a folder someone may hand over: a file there is read as the
loader reads it. A FIFO named ``x.yaml`` hung the search (nobody writes to it), a link to
``/dev/zero`` filled the memory; each is now an ERROR row naming the file in one line, and
the folder's other scenarios run."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from deadlines import HANG_S

ROOT = Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def test_a_fifo_and_a_device_in_the_folder_are_error_rows(tmp_path: Path) -> None:
    folder = tmp_path / "suite"
    folder.mkdir()
    (folder / "ok.yaml").write_text(
        f"world: {WORLD}\nduration: 1\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "expect:\n  - {metric: collisions, below: 1}\n"
    )
    os.mkfifo(folder / "fifo.yaml")
    (folder / "zero.yaml").symlink_to("/dev/zero")
    done = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "test", str(folder), "-j", "1"],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert done.returncode == 1, done.stderr
    errors = sorted(line for line in done.stderr.splitlines() if line.startswith("error: "))
    tail = "expected a YAML file"
    assert errors == [
        f"error: fifo: {folder / 'fifo.yaml'}: is not a regular file (a FIFO), {tail}",
        f"error: zero: {folder / 'zero.yaml'}: is not a regular file (a device), {tail}",
    ]
    assert "1 passed" in done.stdout
