"""The README's falsification figure and table: a search of the resonance example beside its
grid (from ``tests/fixtures/falsify_grids.json``).

    python benchmarks/falsify_figure.py [--seed 1] [-j 2]

writes ``assets/falsify_resonance.png`` and prints, per search seed, the worst found, the run
that first came within 5 % of the grid's worst and the wall time.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("MPLBACKEND", "Agg")

from amsa_phys.cli.main import main as cli  # noqa: E402
from amsa_phys.plots.convergence import plot_convergence  # noqa: E402


def main() -> None:
    """Run the searches, print the table rows, draw the first seed's convergence."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    args = ap.parse_args()
    spec = json.loads((ROOT / "tests" / "fixtures" / "falsify_grids.json").read_text())
    res = spec["resonance"]
    grid = res["worst"]["value"]
    ranges = [x for r in res["ranges"] for x in ("--range", r)]
    for n, seed in enumerate(args.seeds.split(",")):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "f"
            t0 = time.perf_counter()
            cli(["falsify", str(ROOT / res["scenario"]), *ranges, "--budget", "150",
                 "--seed", seed, "-j", str(args.jobs), "--out", str(out)])  # fmt: skip
            wall = time.perf_counter() - t0
            with open(out / "results.csv", newline="") as fh:
                rows = list(csv.DictReader(fh))
        values = [float(r["rms_error"]) for r in rows]
        first = next(i + 1 for i, v in enumerate(values) if v >= 0.95 * grid)
        k = max(range(len(values)), key=lambda i: values[i])
        print(
            f"| search, seed {seed} | {len(rows)} (within 5 % at run {first}) | "
            f"{values[k]:.4f} | changePeriod {rows[k]['Leader.changePeriod']} s, cruisePower "
            f"{rows[k]['Leader.cruisePower']} % | {wall:.0f} s |"
        )
        if n == 0:
            plot_convergence(
                values,
                [int(r["generation"]) for r in rows],
                "rms_error (m)",
                True,
                ROOT / "assets" / "falsify_resonance.png",
                f"falsify_resonance.yaml, search seed {seed}: worst rms_error so far",
                threshold=1.2,
                reference=(grid, f"grid's worst, {res['worst']['runs']:,} runs"),
            )
    point = res["worst"]["point"]
    print(
        f"| grid {res['same_grid_as'].split(' ', 2)[2]} | {res['worst']['runs']:,} | "
        f"{grid:.4f} | changePeriod {point['Leader.changePeriod']} s, cruisePower "
        f"{point['Leader.cruisePower']} % | {res['worst']['wall_s']:.0f} s |"
    )


if __name__ == "__main__":
    main()
