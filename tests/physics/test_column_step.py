"""The batch's physics step in C (``_step.Columns``, ``compiled.ColumnForces.columns``) is
the numpy step it replaced (``physics/columns.py``: the compiled forces, then the numpy
integration, contact screening and safety check), bit for bit: after every step of a batch
the same states, rims and forces, and the same runs marked as about to touch — through a
static box in the lane, a follower running into its leader and a leader too fast for a
single step."""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine.multirun import MultiRun
from amsa_phys.physics import compiled
from amsa_phys.physics.columns import ColumnPhysics
from amsa_phys.physics.step_path import extension
from amsa_phys.runs.sweep import Axis, SweepPlan, prepare_job

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(
    extension() is None or not compiled.columns_compiled(),
    reason="the compiled step was not built (no C compiler at install)",
)


def scenarios(tmp_path: Path, rate: int) -> list[Any]:
    """MDE challenge runs: a box in the leader's lane, followers from gentle to ramming, a
    leader from slow to fast (at a coarse physics ``rate``, faster than one step resolves)."""
    path = tmp_path / f"s{rate}.yaml"
    path.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 12\nseed: 3\n"
        f"physics:\n  rate: {rate}\n"
        "  obstacles: [{type: box, x: 30, y: 0.5, width: 1, height: 3}]\n"
    )
    axes = [
        Axis("MyFollowerController.Kv", (0.05, 0.6, 2.5)),
        Axis("MyFollowerController.distanceRef", (15.0, 1.0)),
        Axis("Leader.cruisePower", (10.0, 60.0, 100.0)),
    ]
    return [prepare_job(job) for job in SweepPlan(path, axes, seeds=1, base_seed=3).jobs()]


def digests(runs: list[Any], fused: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[list, set]:
    """A digest of every rover's state, rims and forces after each step, and the runs
    marked as touching, with the step in C (``fused``) or in numpy."""
    seen: list[str] = []
    step = ColumnPhysics.step

    def spy(self: ColumnPhysics) -> None:
        step(self)
        model, io = self._model, self._io
        h = hashlib.sha1(io.state.tobytes())
        for arr in (model.rims, io.forces, self._touched):
            h.update(np.ascontiguousarray(arr).tobytes())
        seen.append(h.hexdigest())

    with monkeypatch.context() as m:
        m.setattr(ColumnPhysics, "step", spy)
        # one step a call, so that the spy sees each (``step_many`` has its own tests)
        m.setattr(ColumnPhysics, "step_many", lambda self, count, seek: 0)
        if not fused:
            m.delattr(compiled.ColumnForces, "columns")
        sim = MultiRun(runs, columns=ColumnPhysics())
        sim.run()
    assert (sim.column_physics._fused is not None) == fused
    return seen, sim.column_physics.touched


@pytest.mark.parametrize("rate", [100, 10])
def test_the_c_column_step_is_the_numpy_step_bit_for_bit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, rate: int
) -> None:
    runs = scenarios(tmp_path, rate)
    in_c, touched_c = digests(runs, True, monkeypatch)
    in_numpy, touched_numpy = digests(runs, False, monkeypatch)
    assert len(in_c) == len(in_numpy) == 12 * rate
    first = next((k for k, (a, b) in enumerate(zip(in_c, in_numpy, strict=True)) if a != b), None)
    assert first is None, f"the steps part at step {first}"
    assert touched_c == touched_numpy
    # what the screening must have seen: some runs touch, some never come near
    assert 0 < len(touched_c) < len(runs)


def test_the_c_column_step_refuses_arrays_it_would_read_out_of_bounds() -> None:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    n = 3
    f64 = np.float64

    def args(**change: Any) -> dict[str, Any]:
        good = {
            "plan": np.zeros((n, len(compiled.PLAN_FIELDS))),
            "drives": np.zeros((2, n)),
            "rims": np.zeros((2, n)),
            "ground": np.zeros((9, n)),
            "state": np.zeros((n, 6)),
            "forces": np.zeros((n, 3)),
            "m_inv": np.ones(n),
            "i_inv": np.ones(n),
            "dt": 0.01,
            "max2": 100.0,
            "extent": 1e4,
            "run": np.array([0, 0, 1], dtype=np.int64),
            "radius": np.ones(n),
            "sub": np.full(n, np.inf),
            "reach": 0.5,
            "pairs_a": np.array([0], dtype=np.int64),
            "pairs_b": np.array([1], dtype=np.int64),
            "boxes": np.zeros((0, 4)),
            "touched": np.zeros(2, dtype=np.uint8),
        }
        return {**good, **change}

    assert _step.Columns(**args()).advance() is True
    bad = [
        ({"run": np.array([0, 0, 2], dtype=np.int64)}, "run: a rover's run beyond"),
        ({"pairs_b": np.array([3], dtype=np.int64)}, "pairs: a rover index out of range"),
        ({"rims": np.zeros((2, n + 1))}, "rims: 6 items"),
        ({"m_inv": np.ones(n, dtype=np.float32)}, "m_inv: 3 items"),
        ({"run": np.array([0.0, 0.0, 1.0], dtype=f64)}, "run: 3 items of 8 bytes .int64"),
        ({"touched": np.zeros(2, dtype=np.int64)}, "touched: 2 items of 1 bytes"),
    ]
    for change, why in bad:
        with pytest.raises(ValueError, match=why):
            _step.Columns(**args(**change))
