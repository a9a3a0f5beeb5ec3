"""The C column step's contact screening marks exactly the runs the numpy screening marks
(``ColumnPhysics._near``), at the edges too: speeds a hair either side of a run's limit,
rovers a hair either side of their reaches in x, in y and on the diagonal, boxes likewise,
and NaN or infinite states. The C step skips its ``hypot`` calls where a cheaper bound
already decides; these cases are the ones a wrong bound would decide wrongly."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from amsa_phys.physics import compiled
from amsa_phys.physics.columns import REACH_M, ColumnPhysics
from amsa_phys.physics.step_path import extension

pytestmark = pytest.mark.skipif(
    extension() is None or not compiled.columns_compiled(),
    reason="the compiled step was not built (no C compiler at install)",
)

DT = 0.01
RADIUS = 0.6
SUB = 20.0
BOX = (10.0, -1.0, 12.0, 1.0)  # left, bottom, right, top


def marks_in_c(state: np.ndarray, boxes: np.ndarray) -> set[int]:
    """The runs the C step marks before its first step: each run one pair of rovers."""
    from amsa_phys.physics import _step  # type: ignore[attr-defined]

    n = len(state)
    runs = n // 2
    touched = np.zeros(runs, dtype=np.uint8)
    columns = _step.Columns(
        plan=np.zeros((n, len(compiled.PLAN_FIELDS))),
        drives=np.zeros((2, n)),
        rims=np.zeros((2, n)),
        ground=np.zeros((9, n)),
        state=state.copy(),
        forces=np.zeros((n, 3)),
        m_inv=np.ones(n),
        i_inv=np.ones(n),
        dt=DT,
        max2=math.inf,
        extent=math.inf,
        run=np.repeat(np.arange(runs, dtype=np.int64), 2),
        radius=np.full(n, RADIUS),
        sub=np.full(n, SUB),
        reach=REACH_M,
        pairs_a=np.arange(0, n, 2, dtype=np.int64),
        pairs_b=np.arange(1, n, 2, dtype=np.int64),
        boxes=boxes,
        touched=touched,
    )
    with np.errstate(all="ignore"):  # the zero plan's forces: whatever they are
        columns.advance()
    return set(np.flatnonzero(touched).tolist())


def marks_in_numpy(state: np.ndarray, boxes: np.ndarray) -> set[int]:
    """``ColumnPhysics._near`` (the pure path's screening) over the same columns."""
    n = len(state)
    view: Any = SimpleNamespace(
        _radius=np.full(n, RADIUS),
        _sub=np.full(n, SUB),
        _run=np.repeat(np.arange(n // 2), 2),
        _pa=np.arange(0, n, 2),
        _pb=np.arange(1, n, 2),
        _boxes=boxes,
    )
    with np.errstate(all="ignore"):
        return ColumnPhysics._near(view, state, DT)


def edge_states() -> np.ndarray:
    """Pairs of rovers at the edges of every test: (x, y, angle, vx, vy, w) rows."""
    rng = np.random.default_rng(7)
    limit = 0.99 * SUB
    rows: list[list[float]] = []

    def pair(a: list[float], b: list[float]) -> None:
        rows.extend([a, b])

    far = 1000.0
    for nudge in (-1e-12, -1e-15, 0.0, 1e-15, 1e-12):
        speed = limit * (1 + nudge)
        for turn in (0.0, 0.3, math.pi / 4, 1.2):  # the speed along x, on a diagonal, ...
            vx, vy = speed * math.cos(turn), speed * math.sin(turn)
            pair([0.0, 0.0, 0, vx, vy, 0], [far, far, 0, 0, 0, 0])
    for vel in ((0.0, 0.0), (3.0, -4.0), (12.5, 7.25)):
        reach = RADIUS + REACH_M + 2.0 * DT * math.hypot(*vel)
        gap = 2 * reach
        for nudge in (-1e-12, -1e-15, 0.0, 1e-15, 1e-12):
            for turn in (0.0, math.pi / 2, math.pi / 4, 0.7):
                d = gap * (1 + nudge)
                dx, dy = d * math.cos(turn), d * math.sin(turn)
                x0, y0 = -40.0, 25.0  # away from the box
                pair([x0, y0, 0, *vel, 0], [x0 + dx, y0 + dy, 0, *vel, 0])
            # a rover at its reach from the box's right side, top side and corner
            for ex, ey in ((1.0, 0.0), (0.0, 1.0), (math.sqrt(0.5), math.sqrt(0.5))):
                d = reach * (1 + nudge)
                x = BOX[2] + d * ex if ex else 11.0
                y = BOX[3] + d * ey if ey else 0.0
                pair([x, y, 0, *vel, 0], [far, -far, 0, 0, 0, 0])
    for bad in (math.nan, math.inf, -math.inf):
        pair([0.0, 0.0, 0, bad, 0.0, 0], [far, far, 0, 0, 0, 0])
        pair([bad, 0.0, 0, 0.0, 0.0, 0], [far, far, 0, 0, 0, 0])
        pair([0.0, 0.0, 0, 0.0, 0.0, 0], [bad, bad, 0, 0, 0, 0])
    # and a crowd: random places and speeds, some near each other and the box
    for _ in range(300):
        a = [*rng.uniform(-5, 20, 2), 0, *rng.normal(0, 8, 2), 0]
        b = [a[0] + rng.normal(0, 2), a[1] + rng.normal(0, 2), 0, *rng.normal(0, 8, 2), 0]
        pair(a, b)
    return np.array(rows, dtype=np.float64)


@pytest.mark.parametrize("with_box", [False, True])
def test_the_c_screening_marks_the_runs_the_numpy_screening_marks(with_box: bool) -> None:
    state = edge_states()
    boxes = np.array([BOX], dtype=np.float64) if with_box else np.zeros((0, 4))
    in_c = marks_in_c(state, boxes)
    in_numpy = marks_in_numpy(state, boxes)
    assert in_c == in_numpy, (
        f"C only: {sorted(in_c - in_numpy)[:10]}, numpy only: {sorted(in_numpy - in_c)[:10]}"
    )
    # the cases reach both sides of every test: some runs marked, some not
    assert 0 < len(in_c) < len(state) // 2
