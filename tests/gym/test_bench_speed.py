"""``benchmarks/bench_speed.py``, the speed table a user can run: its smoke run prints every
row with its baseline and verdict, and without ``--save`` writes nothing. Tier ``slow``: it
measures (a few seconds of CPU, more on a loaded machine), and figures are never asserted."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from deadlines import HANG_S

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "benchmarks" / "bench_speed.py"
RESULTS = ROOT / "benchmarks" / "results" / "perf.json"

#: every row of the table, as the benchmark names it
ROWS = [
    "single env / LunarLander-v3",
    "single env: garbage collector, % of its CPU",
    "vector env, 1 envs / SyncVectorEnv",
    "vector env, 4 envs / SyncVectorEnv",
    "vector env, 16 envs / SyncVectorEnv",
    "vector env, 64 envs / SyncVectorEnv",
    "vector env, 1000 envs, one thread, env-steps/s (CPU)",
    "vector env, 1000 envs: a reset (every env's new episode), s (CPU)",
    "vector env, 1000 envs, threads=2, env-steps/s (wall)",
    "ap.run scenario1 / C step alone",
    "run --headless --no-plot process CPU / python -c pass",
]
LINE = re.compile(r"^(PASS|MISS|INFO)  (.+?)\s{2,}(.*)   target ([<>]=? [\d.]+|-)$")


@pytest.mark.slow
def test_the_quick_run_prints_every_row_and_saves_nothing() -> None:
    before = RESULTS.read_bytes() if RESULTS.exists() else None
    out = subprocess.run(
        [sys.executable, str(BENCH), "--quick"],
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
        env={**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"},
    )
    rows = {}
    for line in out.stdout.splitlines():
        m = LINE.match(line)
        if m:
            rows[m[2].strip()] = (m[1], m[3], m[4])
    assert list(rows) == ROWS, out.stdout
    for figure, (_, measured, _) in rows.items():
        # a ratio or rate with its spread, or a row skipped with its reason
        assert re.match(r"[\d.e+]+ \(min ", measured) or measured.startswith("skipped; "), figure
    # the baseline's own figure beside the ratio
    assert "SyncVectorEnv" in rows["vector env, 1 envs / SyncVectorEnv"][1]
    assert "CartPole-v1" in rows["single env / LunarLander-v3"][1]
    assert "its resets" in rows["single env: garbage collector, % of its CPU"][1]
    threaded = rows["vector env, 1000 envs, threads=2, env-steps/s (wall)"]
    assert "x one thread's rate (one thread " in threaded[1]
    assert (RESULTS.read_bytes() if RESULTS.exists() else None) == before


def test_bad_options_stop_before_measuring() -> None:
    for argv in (["--reps", "0"], ["--only", "nothing"]):
        out = subprocess.run(
            [sys.executable, str(BENCH), *argv], capture_output=True, text=True, timeout=HANG_S
        )
        assert out.returncode == 2
        assert "Traceback" not in out.stderr
        assert "error:" in out.stderr.strip().splitlines()[-1]


def test_perf_runs_it_as_the_speed_target() -> None:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        import perf  # benchmarks/perf.py

        assert "speed" in perf.TARGETS
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
