"""A context sweep written by hand: the scenario and a ``results.csv`` whose table the test
chooses, so that ``adapt`` derives (and ``--validate`` scores) rules a test knows in advance."""

from __future__ import annotations

from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
WORLD = str(ROOT / "worlds" / "mde_adaptive.yaml")


def two_context_sweep(tmp_path: Path, table: dict[tuple[str, float], float]) -> tuple[Path, Path]:
    """(scenario, sweep directory) of a healthy/worn motor sweep whose rms_error per (context,
    Kv) is ``table``."""
    scenario = {
        "world": WORLD,
        "duration": 200,
        "quality": {"signal": "MyDistanceMonitor.distanceFollowerToLeader", "reference": 15},
        "sweep": {
            "contexts": {
                "healthy": {"MyNormalizePower.motorCoef": 100},
                "worn": {"MyNormalizePower.motorCoef": 50},
            }
        },
    }
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(scenario))
    rows = ["run,context,MyFollowerController.Kv,seed_index,seed,error,rms_error"]
    for i, ((ctx, kv), value) in enumerate(table.items()):
        rows.append(f"{i},{ctx},{kv},0,1,,{value}")
    sweep = tmp_path / "sweepdir"
    sweep.mkdir()
    sweep.joinpath("results.csv").write_text("\n".join(rows) + "\n")
    return path, sweep
