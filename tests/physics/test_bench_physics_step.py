"""``benchmarks/bench_physics_step.py``: it times the compiled column step against another
build and stops at the first bit that differs between them. What it must never do is call a
build that computes other floats the same: a build against itself is identical at every
call, a build that moves one rover by one ulp is caught at that call, naming the array."""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from amsa_phys.physics import compiled

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_physics_step as bench  # noqa: E402  (benchmarks/bench_physics_step.py)

pytest.importorskip("gymnasium", reason="the gym extra is not installed")
needs_c = pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step is not built (or AMSA_PHYS_PURE)"
)


def _arrays() -> dict[str, Any]:
    rng = np.random.default_rng(0)
    return {
        "state": rng.normal(size=(4, 6)),
        "rims": rng.normal(size=(2, 4)),
        "forces": rng.normal(size=(4, 3)),
        "touched": np.zeros(2, dtype=np.uint8),
    }


def test_first_difference_finds_one_ulp_in_every_written_array() -> None:
    a = _arrays()
    assert bench.first_difference(a, {k: v.copy() for k, v in a.items()}) is None
    for key in ("state", "rims", "forces", "touched"):  # everything a step writes
        b = {k: v.copy() for k, v in a.items()}
        flat = b[key].reshape(-1)
        if flat.dtype == np.uint8:
            flat[1] = 1
        else:
            flat[5] = np.nextafter(flat[5], np.inf)
        found = bench.first_difference(a, b)
        assert found is not None, key
        assert found.startswith(f"{key}["), (key, found)


class _OneUlpOff:
    """A baseline build whose step moves rover 1's x by one ulp after its third call."""

    def __init__(self, inner: Any, state: np.ndarray) -> None:
        self.inner, self.state, self.calls = inner, state, 0

    def advance_many(self, count: int, freeze: bool) -> Any:
        out = self.inner.advance_many(count, freeze)
        self.calls += 1
        if self.calls == 3:
            self.state[1, 0] = np.nextafter(self.state[1, 0], np.inf)
        return out


@needs_c
def test_a_build_against_itself_is_identical_and_a_changed_one_is_caught(
    monkeypatch: Any,
) -> None:
    from amsa_phys.physics import _step

    itself = bench.load_step(_step.__file__)  # the same build, loaded a second time
    sitting = bench.measure(2, 4, itself)
    assert sitting.steps == 4 * bench.STEPS_PER_CALL
    assert len(sitting.ratios()) == 4
    assert all(r > 0 for r in sitting.ratios())

    def columns(*args: Any, **kwargs: Any) -> _OneUlpOff:
        return _OneUlpOff(_step.Columns(*args, **kwargs), args[4])

    changed = SimpleNamespace(Columns=columns)
    with pytest.raises(AssertionError, match=r"2 envs, call 3: the builds differ: state\[6\]"):
        bench.measure(2, 4, changed)  # type: ignore[arg-type]


def test_a_missing_baseline_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert bench.main(["--baseline", str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "nowhere" in err
    assert bench.main(["--baseline", str(tmp_path)]) == 2  # a directory without a build
    assert "build_ext --inplace" in capsys.readouterr().err


@needs_c
def test_save_writes_the_table_with_its_sitting(tmp_path: Path, monkeypatch: Any) -> None:
    import results

    monkeypatch.setattr(bench, "OUT", tmp_path / "physics_step.json")
    monkeypatch.setattr(results, "write_pages", lambda: [])  # the docs stay as they are
    assert bench.main(["--envs", "2", "--rounds", "2", "--save"]) == 0
    doc = results.json.loads((tmp_path / "physics_step.json").read_text())
    assert doc["columns"] == bench.ALONE
    assert [row[0] for row in doc["rows"]] == ["2"]
    assert doc["command"] == "python benchmarks/bench_physics_step.py --save"
    assert "| 2 |" in results.table_markdown(doc)
