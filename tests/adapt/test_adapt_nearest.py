"""adapt: a combination of estimator bands no swept context has gets the nearest cell's best.

The oracle that ``adapt --validate`` compares with sets, for a context the sweep never ran,
the best of the nearest swept cell; rules without a rule there leave whatever gain the
last context set in force (a random leader with very worn motors, when the sweep ran each
alone, kept the robust gain and won a third of what the oracle won).
"""

from __future__ import annotations

from pathlib import Path

from amsa_phys.adapt.derive import derive
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
KV = "MyFollowerController.Kv"
TURNING, DELIVERED = "LeaderMonitor.turning", "MotorMonitor.delivered"


def _sweep(tmp_path: Path, contexts: dict[str, tuple[dict, float]]) -> tuple[Path, Path]:
    """A sweep scenario and its results.csv: each context's ``best`` Kv scores 0.5, the
    robust 0.2 scores 0.7 and every other Kv 1.0 (two seeds)."""
    lines = [
        "world: " + str(ROOT / "worlds" / "mde_adaptive.yaml"),
        "duration: 10",
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}",
        "sweep:",
        "  contexts:",
    ]
    lines += [f"    {name}: {sets}" for name, (sets, _) in contexts.items()]
    scenario = tmp_path / "sweep.yaml"
    scenario.write_text("\n".join(lines) + "\n")
    rows = ["run,context,MyFollowerController.Kv,seed_index,seed,error,rms_error"]
    for name, (_, best) in contexts.items():
        for kv in (0.15, 0.2, 0.25, 0.35, 0.6):
            value = 0.5 if kv == best else 0.7 if kv == 0.2 else 1.0
            for s in (0, 1):
                rows.append(f"{len(rows) - 1},{name},{kv},{s},{s + 1},,{value}")
    results = tmp_path / "results.csv"
    results.write_text("\n".join(rows) + "\n")
    return scenario, results


def _nearest(tmp_path: Path, contexts: dict[str, tuple[dict, float]]) -> list[dict]:
    scenario, results = _sweep(tmp_path, contexts)
    found = derive(results, load_scenario(scenario), "rms_error", 10, float("inf"), 0.0)
    return [r for r in found.rules if r["label"].startswith("nearest")]


def test_uncovered_band_combinations_get_the_nearest_cells_best(tmp_path: Path) -> None:
    rules = _nearest(
        tmp_path,
        {
            "nominal": ({"Leader.behavior": 1}, 0.15),
            "very worn": ({"Leader.behavior": 1, "MyNormalizePower.motorCoef": 25}, 0.6),
            "random": ({"Leader.behavior": 4}, 0.2),
            "worn random": ({"Leader.behavior": 4, "MyNormalizePower.motorCoef": 50}, 0.35),
        },
    )
    sure = {"MotorMonitor.valid": {"above": 0.5}, "LeaderMonitor.valid": {"above": 0.5}}
    assert [(r["when"], r["set"]) for r in rules] == [
        # worn motors, straight leader: very worn is a third of the delivered span away
        ({DELIVERED: {"above": 0.4, "below": 0.7}, TURNING: {"below": 0.08}, **sure}, {KV: 0.6}),
        # very worn motors, random leader: worn random (a third away), not very worn
        ({DELIVERED: {"below": 0.35}, TURNING: {"above": 0.12}, **sure}, {KV: 0.35}),
    ]


def test_equally_near_cells_that_disagree_write_no_rule(tmp_path: Path) -> None:
    rules = _nearest(
        tmp_path,
        {
            "nominal": ({"Leader.behavior": 1}, 0.15),
            "worn": ({"Leader.behavior": 1, "MyNormalizePower.motorCoef": 50}, 0.35),
            "random": ({"Leader.behavior": 4}, 0.25),
        },
    )
    assert rules == []  # worn random: as near worn (0.35) as random (0.25)
