"""``adapt --validate`` judges rules on held-out sequences: rules built on a lying sweep (it
claims the unstable Kv 0.8 is best with healthy motors) lose to the robust gain, and the
command says so with exit 1; held-out sequences are drawn between the sweep's levels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from sweepfiles import two_context_sweep

from amsa_phys.adapt.validate import Row, loses
from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.tune.contexts import Sequence, box, sequences

ROOT = Path(__file__).resolve().parents[2]
WORLD = str(ROOT / "worlds" / "mde_adaptive.yaml")


def _lying_sweep(tmp_path: Path) -> tuple[Path, Path]:
    return two_context_sweep(
        tmp_path,
        {("healthy", 0.2): 0.5, ("healthy", 0.8): 0.3, ("worn", 0.2): 0.5, ("worn", 0.8): 0.6},
    )


def test_rules_that_lose_on_held_out_sequences_exit_1(tmp_path, capsys) -> None:
    path, sweep = _lying_sweep(tmp_path)
    out = tmp_path / "rules.yaml"
    argv = ["adapt", str(sweep), "--scenario", str(path), "-o", str(out), "--validate"]
    argv += ["--margin", "inf"]  # told: without it the margin already refuses Kv 0.8
    code = main([*argv, "--sequences", "2", "--seeds", "1", "--duration", "240"])
    captured = capsys.readouterr()
    assert "robust | oracle | rules" in captured.out
    assert code == 1, captured.out
    assert "warning: the rules lose to the robust fixed choice" in captured.err


def test_loses_is_the_tolerance_against_the_robust_mean() -> None:
    seq = Sequence(((0.0, {}),))
    rows = [Row(seq, 1.0, 0.5, 1.019), Row(seq, 1.0, 0.5, 1.021), Row(seq, 2.0, 1.0, 1.0)]
    assert loses(rows, 0.02) == [rows[1]]


def test_held_out_contexts_fall_between_the_sweep_levels() -> None:
    scenario = load_scenario(ROOT / "scenarios" / "adaptive_sweep.yaml")
    contexts = scenario.data["sweep"]["contexts"]
    axes = {a.key: a for a in box(scenario, contexts)}
    assert axes["Leader.behavior"].choices == (1, 4)
    coefs = [
        sets["MyNormalizePower.motorCoef"]
        for seq in sequences(list(axes.values()), 40, 600, seed=3)
        for _, sets in seq.segments
    ]
    assert min(coefs) >= 25
    assert max(coefs) <= 100
    assert sum(c not in (25, 50, 100) for c in coefs) > len(coefs) // 2  # mostly between
    starts = [[at for at, _ in s.segments] for s in sequences(list(axes.values()), 40, 600, 3)]
    assert all(np.all(np.diff(s) >= 60) for s in starts)  # segments at least a minute
