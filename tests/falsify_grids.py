"""The grids falsify's acceptance tests compare with, and the command that regenerates them.

    python tests/falsify_grids.py [fig5] [resonance] [-j N]

runs each problem's grid (the same points as the ``amsa-phys sweep`` command stored beside
it) and rewrites ``tests/fixtures/falsify_grids.json`` with its worst point and value and the
wall time it took. The dynamics change from time to time (another branch's physics): after
such a change, run this and commit the fixture; ``tests/falsify/test_falsify.py``'s slow test
recomputes a grid and compares it with the fixture.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
FIXTURE = ROOT / "tests" / "fixtures" / "falsify_grids.json"
sys.path.insert(0, str(ROOT))


def _steps(lo: int, hi: int, step: int) -> str:
    return ",".join(str(v) for v in range(lo, hi + 1, step))


#: Each problem: the scenario, the search's box (--range), its metric, the duration, and the
#: grid (sweep options) whose worst the search must come within 5 % of at its budget.
PROBLEMS: dict[str, dict[str, Any]] = {
    "fig5": {
        "scenario": "scenarios/paper_fig5_kv01.yaml",
        "duration": 120.0,
        "metric": "rms_error",
        "budget": 150,
        "ranges": [
            "MyNormalizePower.motorCoef=40:100",
            "Leader.cruisePower=3:12",
            "LeaderGPS.lostDataGPS=0:60",
        ],
        "grid": [
            "--grid",
            f"MyNormalizePower.motorCoef={_steps(40, 100, 5)}",
            "--range",
            "Leader.cruisePower=3:12:13",
            "--grid",
            f"LeaderGPS.lostDataGPS={_steps(0, 60, 5)}",
        ],
    },
    "resonance": {
        "scenario": "scenarios/falsify_resonance.yaml",
        "duration": None,
        "metric": "rms_error",
        "budget": 150,
        "ranges": ["Leader.changePeriod=2:40", "Leader.cruisePower=3:12"],
        "grid": [
            "--range",
            "Leader.changePeriod=2:40:77",
            "--range",
            "Leader.cruisePower=3:12:13",
        ],
    },
}


def grid_points(spec: dict[str, Any]) -> list[tuple[tuple[str, Any], ...]]:
    """The grid's points, parsed by the sweep's own --grid/--range parsers."""
    import itertools

    from amsa_phys.runs.sweep import parse_grid, parse_range

    opts = spec["grid"]
    axes = [
        parse_grid(text) if flag == "--grid" else parse_range(text)
        for flag, text in zip(opts[::2], opts[1::2], strict=True)
    ]
    return [
        tuple((a.key, v) for a, v in zip(axes, combo, strict=True))
        for combo in itertools.product(*[a.values for a in axes])
    ]


def grid_worst(name: str, workers: int) -> dict[str, Any]:
    """Run problem ``name``'s grid; its worst point, value, size and wall time."""
    from amsa_phys.model.scenario import load_scenario
    from amsa_phys.runs.evaluate import evaluate

    spec = PROBLEMS[name]
    path = ROOT / spec["scenario"]
    seed = load_scenario(path).seed
    points = grid_points(spec)
    t0 = time.perf_counter()
    rows = list(
        evaluate(path, [(p, seed) for p in points], duration=spec["duration"], workers=workers)
    )
    wall = time.perf_counter() - t0
    errors = [r["error"] for r in rows if r["error"]]
    if errors:
        raise SystemExit(f"{name}: {len(errors)} grid runs failed, e.g. {errors[0]}")
    worst = max(rows, key=lambda r: (r[spec["metric"]], -r["index"]))
    return {
        "point": dict(points[worst["index"]]),
        "value": worst[spec["metric"]],
        "runs": len(points),
        "wall_s": round(wall, 1),
        "workers": workers,
    }


def command(name: str) -> str:
    """The ``amsa-phys sweep`` command giving the same grid (for a reader of the fixture)."""
    spec = PROBLEMS[name]
    parts = ["amsa-phys sweep", spec["scenario"], *spec["grid"]]
    if spec["duration"] is not None:
        parts += ["--duration", f"{spec['duration']:g}"]
    return " ".join(parts)


def main(argv: list[str] | None = None) -> None:
    """Recompute the named grids (all by default) and rewrite the fixture."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help=f"problems (default all): {', '.join(PROBLEMS)}")
    ap.add_argument("-j", "--jobs", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args(argv)
    unknown = [n for n in args.names if n not in PROBLEMS]
    if unknown:
        ap.error(f"unknown problem {unknown[0]}; known: {', '.join(PROBLEMS)}")
    data = json.loads(FIXTURE.read_text()) if FIXTURE.exists() else {}
    for name in args.names or list(PROBLEMS):
        data[name] = {
            **PROBLEMS[name],
            "regenerate": f"python tests/falsify_grids.py {name}",
            "same_grid_as": command(name),
            "worst": grid_worst(name, args.jobs),
        }
        print(f"{name}: {data[name]['worst']}")
    FIXTURE.write_text(json.dumps(data, indent=1) + "\n")


if __name__ == "__main__":
    main()
