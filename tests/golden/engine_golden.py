"""Reference traces of the shipped scenarios keyed by the pymunk version that made them.

Why: the physics step calls Chipmunk (through pymunk) for every body and contact; a pymunk
upgrade can change contact resolution or rounding and so every result, silently. Each
shipped scenario that runs on its own (``scenarios/*.yaml`` but the sweeps) is run for its
first :data:`SECONDS` s and its trace kept, gzipped, in ``engine/pymunk-<version>/``, with
a manifest naming the versions. ``test_engine_golden.py`` runs them again and compares with
the traces of the installed pymunk's version when there are some (they must then match as
the golden traces do), else with the newest stored version's: it reports the largest
difference of every scenario and fails above :data:`TOLERANCE_M` (positions, m) — an
upgrade that moves results must be looked at and its traces added
(``python tests/golden/regenerate.py --engine``), not slip in.
"""

from __future__ import annotations

import gzip
import json
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
STORE = HERE / "engine"
#: How much of each shipped scenario is kept (s): long enough for the closed loops, the
#: obstacle course's contacts and the platoon's string to act, short enough to run in CI.
SECONDS = 30.0
#: Largest difference in any position column (m) between two pymunk versions that passes:
#: the golden traces' cross-platform tolerance (libm's last bits over a closed loop); a
#: change of Chipmunk's contact solver or integration moves positions far more.
TOLERANCE_M = 1e-6


def scenarios() -> list[Path]:
    """The shipped scenarios that run alone (a sweep's file holds a ``sweep:`` section)."""
    return [
        p for p in sorted((ROOT / "scenarios").glob("*.yaml")) if "\nsweep:" not in p.read_text()
    ]


def pymunk_version() -> str:
    import pymunk

    return str(pymunk.version)


def simulate(scenario: Path) -> tuple[list[str], np.ndarray]:
    """The first :data:`SECONDS` s of ``scenario``: trace header and values."""
    from amsa_phys.model.scenario import load_scenario
    from amsa_phys.runs.single import run_scenario

    out = Path(tempfile.mkdtemp(prefix="engine-golden-"))
    run_scenario(load_scenario(scenario, duration=SECONDS), out, plot=False, progress=False)
    text = (out / "trace.csv").read_text()
    return parse(text)


def parse(text: str) -> tuple[list[str], np.ndarray]:
    lines = text.splitlines()
    values = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return lines[0].split(","), values


def stored_versions() -> list[str]:
    """The pymunk versions traces are kept for, oldest first (the manifest's order)."""
    manifest = STORE / "manifest.json"
    if not manifest.exists():
        return []
    return list(json.loads(manifest.read_text())["versions"])


def load(version: str, scenario: Path) -> tuple[list[str], np.ndarray]:
    with gzip.open(STORE / f"pymunk-{version}" / f"{scenario.stem}.csv.gz", "rt") as f:
        return parse(f.read())


def largest_position_difference(
    old: tuple[list[str], np.ndarray], new: tuple[list[str], np.ndarray]
) -> tuple[float, str]:
    """(largest |difference| of any position column, that column) between two traces."""
    (h_old, a), (h_new, b) = old, new
    if h_old != h_new or a.shape != b.shape:
        return float("inf"), f"columns or rows changed: {a.shape} -> {b.shape}"
    worst, where = 0.0, ""
    for i, name in enumerate(h_new):
        if name.endswith(("posX", "posY")):
            d = float(np.abs(a[:, i] - b[:, i]).max())
            if d > worst:
                worst, where = d, name
    return worst, where


def write(version: str) -> list[str]:
    """Store every shipped scenario's trace for ``version`` (the installed pymunk's)."""
    folder = STORE / f"pymunk-{version}"
    folder.mkdir(parents=True, exist_ok=True)
    lines = []
    for scenario in scenarios():
        header, values = simulate(scenario)
        body = [",".join(header)] + [",".join(repr(float(v)) for v in row) for row in values]
        data = ("\n".join(body) + "\n").encode()
        with (
            open(folder / f"{scenario.stem}.csv.gz", "wb") as raw,
            gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as f,
        ):
            f.write(data)
        lines.append(f"  {scenario.stem}: {len(values)} rows")
    versions = [v for v in stored_versions() if v != version] + [version]
    (STORE / "manifest.json").write_text(
        json.dumps({"seconds": SECONDS, "versions": versions}, indent=1) + "\n"
    )
    return lines
