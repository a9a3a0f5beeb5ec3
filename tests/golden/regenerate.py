"""Regenerate the golden traces after an intended change, printing what moved.

Usage: ``python tests/golden/regenerate.py`` (from the repository root); with ``--engine``
it stores the shipped scenarios' traces for the installed pymunk instead. For each golden
scenario it runs the simulation, compares with the stored trace column by column, prints the
largest change of every column that moved, then overwrites the stored trace.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def simulate(scenario: Path) -> Path:
    """Run ``scenario`` into a temporary run directory; return its trace."""
    from amsa_phys.model.scenario import load_scenario
    from amsa_phys.runs.single import run_scenario

    out = Path(tempfile.mkdtemp(prefix="golden-"))
    run_scenario(load_scenario(scenario), out, plot=False, progress=False)
    return out / "trace.csv"


def load(path: Path) -> tuple[list[str], np.ndarray]:
    """Header and values of a trace."""
    header = path.read_text().splitlines()[0].split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def differences(old: Path, new: Path) -> list[str]:
    """Lines describing what moved between two traces."""
    h_old, a = load(old)
    h_new, b = load(new)
    if h_old != h_new or a.shape != b.shape:
        return [f"  columns or rows changed: {len(h_old)}x{len(a)} -> {len(h_new)}x{len(b)}"]
    lines = []
    for i, name in enumerate(h_new):
        delta = np.abs(a[:, i] - b[:, i])
        if delta.max() > 0:
            lines.append(f"  {name}: max |change| {delta.max():.3g} at t={a[delta.argmax(), 0]:g}")
    return lines


def main() -> int:
    """Regenerate every golden trace (``--engine``: the shipped scenarios' traces for the
    installed pymunk, ``engine_golden.py``)."""
    if "--engine" in sys.argv[1:]:
        from engine_golden import pymunk_version, write

        version = pymunk_version()
        print(f"engine traces for pymunk {version}:")
        print("\n".join(write(version)))
        return 0
    for scenario in sorted(HERE.glob("golden_*.yaml")):
        stored = scenario.with_suffix(".csv")
        fresh = simulate(scenario)
        if stored.exists():
            moved = differences(stored, fresh)
            print(f"{scenario.name}: " + ("unchanged" if not moved else "moved"))
            print("\n".join(moved)) if moved else None
        else:
            print(f"{scenario.name}: new")
        stored.write_bytes(fresh.read_bytes())
    return 0


if __name__ == "__main__":
    sys.exit(main())
