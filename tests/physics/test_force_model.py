"""The force model's declared interface (``physics/force_model.py``) and the C layout check.

Every model the factory can hand out satisfies :class:`ForceModel`; the factory is the one
place choosing among them; a compiled step built from another ``_step.c`` layout is refused
at import instead of running on shifted constants (issue 32, item 4).
"""

from __future__ import annotations

import types

import numpy as np
import pymunk
import pytest

from amsa_phys.physics import compiled, fleet
from amsa_phys.physics.bodyio import BodyIO
from amsa_phys.physics.fewrovers import FewRovers
from amsa_phys.physics.force_model import ForceModel, make_force_model
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.rover import DiffDriveRover
from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.step_path import PURE_ENV, extension
from amsa_phys.physics.templates import rover_params

built = pytest.mark.skipif(extension() is None, reason="the compiled step was not built")


def rovers(n: int) -> tuple[pymunk.Space, list[DiffDriveRover]]:
    space = pymunk.Space()
    p = rover_params()
    out = [
        DiffDriveRover(
            space,
            f"R{k}",
            mass_kg=p.mass,
            length_m=p.length,
            width_m=p.width,
            track_m=p.track,
            wheel=wheel_model(p, 9.81),
            x=3.0 * k,
            y=0.0,
            heading=0.0,
            collision_type=1,
        )
        for k in range(n)
    ]
    return space, out


def model_for(n: int, **kw: bool) -> ForceModel:
    space, rs = rovers(n)
    io = BodyIO(space, [r.body for r in rs])
    ground = (0.8, 0.02)
    grounds = [ground_list(r, ground, ground) for r in rs]
    return make_force_model(io, rs, 0.01, (100.0, 1e4), grounds, **kw)


@pytest.mark.parametrize("pure", [False, True])
@pytest.mark.parametrize("n", [2, fleet.BATCH_MIN])
def test_every_model_the_factory_gives_satisfies_the_protocol(
    n: int, pure: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    if pure:
        monkeypatch.setenv(PURE_ENV, "1")
    model = model_for(n)
    assert isinstance(model, ForceModel)
    expected = {
        (2, True): FewRovers,
        (fleet.BATCH_MIN, True): fleet.Fleet,
        (2, False): compiled.CompiledFewRovers if compiled.active() else FewRovers,
        (fleet.BATCH_MIN, False): compiled.CompiledFleet if compiled.active() else fleet.Fleet,
    }[(n, pure)]
    assert type(model) is expected
    assert model.advance() is None
    assert len(model.kinematics(0)) == 6
    assert model.rim_array(np.arange(n)).shape == (n, 2)


def test_a_batch_gets_the_column_models() -> None:
    model = model_for(3, columns=True)
    assert isinstance(model, ForceModel)
    want = compiled.ColumnForces if compiled.columns_compiled() else fleet.Fleet
    assert type(model) is want


def test_a_model_missing_a_method_is_not_a_force_model() -> None:
    """The protocol check can fail: an object without ``rim_speeds`` is refused."""

    class Partial:
        rovers = ()
        dt = 0.01
        drives = None

        def refresh(self) -> None: ...
        def set_ground(self, k: int, terms: list[float]) -> None: ...
        def advance(self) -> None: ...
        def kinematics(self, k: int) -> list[float]:
            return []

        def kinematics_array(self, index: np.ndarray) -> np.ndarray:
            return index

        def rim_array(self, index: np.ndarray) -> np.ndarray:
            return index

    assert not isinstance(Partial(), ForceModel)


@built
def test_the_c_layout_is_checked_at_import() -> None:
    ext = extension()
    assert compiled.check_layout(ext) == tuple(ext.PLAN_FIELDS)  # type: ignore[union-attr]
    good = {
        "PLAN_FIELDS": ext.PLAN_FIELDS,  # type: ignore[union-attr]
        "PLAN_WIDTH": ext.PLAN_WIDTH,  # type: ignore[union-attr]
        "SLIP_SPEED_MIN": ext.SLIP_SPEED_MIN,  # type: ignore[union-attr]
        "GROUND_ROWS": ext.GROUND_ROWS,  # type: ignore[union-attr]
        "GROUND_TERMS": ext.GROUND_TERMS,  # type: ignore[union-attr]
    }
    stale = [
        {"PLAN_FIELDS": (*good["PLAN_FIELDS"][:-1], "nonsense")},
        {"PLAN_WIDTH": good["PLAN_WIDTH"] + 1},
        {"SLIP_SPEED_MIN": 0.2},
        {"GROUND_ROWS": (0, 1, 2, 3, 4, 5, 6)},
    ]
    for change in stale:
        with pytest.raises(ImportError, match="rebuild"):
            compiled.check_layout(types.SimpleNamespace(**{**good, **change}))
    with pytest.raises(ImportError, match="no Columns"):  # a build from before the batch step
        compiled.check_layout(types.SimpleNamespace(**good, SECOND_ORDER=1))
    with pytest.raises(ImportError, match="second-order"):  # before the trapezoid
        compiled.check_layout(types.SimpleNamespace(**good, Columns=ext.Columns))  # type: ignore[union-attr]
    assert compiled.check_layout(
        types.SimpleNamespace(**good, Columns=ext.Columns, SECOND_ORDER=1)  # type: ignore[union-attr]
    )
