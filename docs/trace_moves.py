"""How far a change of the physics moved the paper's worlds' traces: this code against a git
revision's, scenario by scenario.

Usage (from the repository root)::

    python docs/trace_moves.py REV                      # the paper's scenarios
    python docs/trace_moves.py REV scenarios/scenario1.yaml --duration 300

Each scenario runs twice with its own seed and duration (or ``--duration``): with the code of
``REV`` (taken out with ``git archive`` into a temporary directory and run there on the pure
Python step, which gives the compiled step's traces bit for bit, so nothing needs building)
and with this checkout's. Printed per scenario: the largest distance between the two runs'
positions of any rover over the run (m), the largest heading difference (rad), and the
column that moved most. Why a script: ``docs/physics.md`` quotes these numbers, and a
reader can check them (or measure the next change) instead of trusting a typed figure.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
#: the paper's worlds (docs/physics.md quotes these)
PAPER = (
    "scenarios/scenario1.yaml",
    "scenarios/scenario2.yaml",
    "scenarios/paper_fig5_kv035.yaml",
    "scenarios/paper_fig6.yaml",
    "scenarios/paper_fig6_sensed.yaml",
)
#: runs one scenario into a run directory with whichever amsa_phys is first on the path
RUN = """
import sys
from pathlib import Path
from amsa_phys.model.scenario import load_scenario
from amsa_phys.runs.single import run_scenario
scenario = load_scenario(Path(sys.argv[1]), duration=float(sys.argv[3]) if sys.argv[3] else None)
run_scenario(scenario, Path(sys.argv[2]), plot=False, progress=False)
"""


def run(code: Path, scenario: Path, out: Path, duration: float | None, pure: bool) -> Path:
    """Run ``scenario`` with the package under ``code``; return its trace."""
    out.mkdir(parents=True)
    env = {**os.environ, "PYTHONPATH": str(code), "MPLBACKEND": "Agg"}
    if pure:
        env["AMSA_PHYS_PURE"] = "1"
    args = [
        sys.executable,
        "-c",
        RUN,
        str(scenario),
        str(out),
        "" if duration is None else str(duration),
    ]
    subprocess.run(args, check=True, env=env, cwd=code)
    return out / "trace.csv"


def load(path: Path) -> tuple[list[str], np.ndarray]:
    header = path.read_text().splitlines()[0].split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def compare(old: Path, new: Path) -> str:
    """One line: largest position and heading differences, and the column that moved most."""
    h_old, a = load(old)
    h_new, b = load(new)
    if h_old != h_new or a.shape != b.shape:
        return f"columns or rows changed: {a.shape} -> {b.shape}"
    col = {name: i for i, name in enumerate(h_new)}
    pos = head = 0.0
    for name in h_new:
        if name.endswith(".posX") and name[:-1] + "Y" in col:
            i, j = col[name], col[name[:-1] + "Y"]
            pos = max(pos, float(np.hypot(a[:, i] - b[:, i], a[:, j] - b[:, j]).max()))
        if name.endswith(".heading"):
            d = np.angle(np.exp(1j * (a[:, col[name]] - b[:, col[name]])))
            head = max(head, float(np.abs(d).max()))
    moved = np.abs(a - b).max(axis=0)
    worst = int(moved.argmax())
    return f"position {pos:.3g} m, heading {head:.3g} rad; most: {h_new[worst]} {moved[worst]:.3g}"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rev", help="the git revision to compare with (a commit, a branch)")
    ap.add_argument("scenarios", nargs="*", default=list(PAPER))
    ap.add_argument(
        "--duration", type=float, default=None, help="seconds (default: each scenario's)"
    )
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="trace-moves-") as tmp:
        old_code = Path(tmp) / "old"
        old_code.mkdir()
        archive = subprocess.run(
            ["git", "archive", args.rev], cwd=ROOT, check=True, capture_output=True
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(old_code)], input=archive, check=True)
        for k, name in enumerate(args.scenarios):
            scenario = (ROOT / name).resolve()
            old = run(old_code, scenario, Path(tmp) / f"{k}-old", args.duration, pure=True)
            new = run(ROOT, scenario, Path(tmp) / f"{k}-new", args.duration, pure=False)
            print(f"{name}: {compare(old, new)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
