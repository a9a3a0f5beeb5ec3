"""The batch's compiled column forces (``compiled.ColumnForces``, ``_step.column_forces``).

A batched sweep computes its rovers' forces with the C force model of a run made alone, over
the Fleet's arrays and without a Space. Held here: in every regime of the wheel model (rims
stuck, breaking away, current-limited, reversed, tyres saturated on ice and mud), forces and
rims equal those of the compiled single-run step (``_step.Stepper``) to the last bit, step
after step as the regimes change, and the pure scalar model's; and wrong arrays are
refused, not read out of bounds.
"""

from __future__ import annotations

import numpy as np
import pytest
from regimes import DT, every_regime

from amsa_phys.physics import bodyio, compiled
from amsa_phys.physics.bodyio import BodyIO
from amsa_phys.physics.columns import _ColumnIO
from amsa_phys.physics.fewrovers import FewRovers
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.step_path import PURE_ENV, extension

built = pytest.mark.skipif(
    extension() is None, reason="the compiled step was not built (no C compiler at install)"
)


def single_run_forces(model: compiled.CompiledFewRovers) -> list[tuple[float, ...]]:
    """The forces the compiled single-run step writes into the bodies this step (its rims put
    back: ``advance`` then applies the same step again)."""
    rims = list(model.rims)
    model._stepper.apply()
    model.rims = rims
    return [(r.body.force.x, r.body.force.y, r.body.torque) for r in model.rovers]


@built
def test_column_forces_are_the_single_runs_compiled_forces_in_every_regime() -> None:
    """Bit for bit the compiled single run's forces and rims (the batched row equals the run
    made alone) and the pure scalar model's (``FewRovers``). The forces, not only the states
    they lead to: a force a few ulps off can vanish in the integration (a direct
    ``pow(x, 2.0)`` in ``_step.c``, folded by GCC into ``x * x``, did that at one rover and
    step of these 40; the states stayed equal)."""
    space, rovers, rims, grounds = every_regime(60)
    terms = [ground_list(r, *g) for r, g in zip(rovers, grounds, strict=True)]
    io_alone = BodyIO(space, [r.body for r in rovers])
    alone = compiled.CompiledFewRovers(io_alone, rovers, DT, (100.0, 1e4), terms)
    alone.rims = [u for pair in rims for u in pair]
    n = len(rovers)
    io = _ColumnIO(np.zeros((n, 6)), np.ones(n), np.ones(n))
    columns = compiled.ColumnForces(io, rovers, DT, (100.0, 1e4), terms)
    columns.rims[...] = np.array(rims).T
    pure = FewRovers(BodyIO(space, [r.body for r in rovers]), rovers, DT, (100.0, 1e4), terms)
    at_rest = set()
    for _ in range(40):  # the single run steps its Space; the columns get the same state
        io.state[...] = [alone.kinematics(k) for k in range(n)]
        pure.rims = [u for k in range(n) for u in alone.rim_speeds(k)]
        expected = single_run_forces(alone)
        columns.apply(io.state)
        pure.apply([x for k in range(n) for x in alone.kinematics(k)])
        alone.advance()
        for k in range(n):
            got = tuple(io.forces[3 * k : 3 * k + 3].tolist())
            assert got == expected[k], f"rover {k}"
            assert columns.rim_speeds(k) == alone.rim_speeds(k), f"rover {k}"
            scalar = pure.io.forces[pure.rows[k] * bodyio.FORCE :][:3]
            assert got == tuple(scalar), f"rover {k}"
            if 0.0 in columns.rim_speeds(k):
                at_rest.add(k)
    assert len(at_rest) >= 5  # rims at rest were in the mix (the rare branches ran)


@built
def test_column_forces_refuse_arrays_of_the_wrong_size() -> None:
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    n = 4
    plan = np.zeros((n, len(compiled.PLAN_FIELDS)))
    good = [plan, np.zeros((2, n)), np.zeros((2, n)), np.zeros((9, n)), np.zeros((n, 6))]
    with pytest.raises(ValueError, match="forces: 12 floats expected for 4 rovers, got 9"):
        _step.column_forces(*good, np.zeros((3, 3)), DT)
    with pytest.raises(ValueError, match="ground: 36 floats expected"):
        _step.column_forces(*good[:3], np.zeros((6, n)), good[4], np.zeros((n, 3)), DT)
    with pytest.raises(ValueError, match="rims: float64"):
        _step.column_forces(
            *good[:2], np.zeros((2, n), np.float32), *good[3:], np.zeros((n, 3)), DT
        )


def test_the_pure_switch_keeps_batches_on_the_pure_fleet(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(PURE_ENV, "1")
    assert not compiled.columns_compiled()
    monkeypatch.delenv(PURE_ENV)
    assert compiled.columns_compiled() == (extension() is not None)
