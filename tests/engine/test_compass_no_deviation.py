"""A compass group whose copies have no deviation terms skips the four sines and cosines
(``sensors/compass.py``): its headings must be the numpy path's to the bit, and a change of a
copy's deviation during the run must bring the terms back at once (what the group keeps
about its parameters may not go stale)."""

from __future__ import annotations

import importlib.util
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import batch_bodies
from amsa_phys.engine.batch import ParamArrays
from amsa_phys.sensors.compass import Compass

BUILT = importlib.util.find_spec("amsa_phys.engine._groupbodies") is not None
needs_c = pytest.mark.skipif(
    not BUILT or batch_bodies.compass_heading() is None,
    reason="the group bodies were not built, or the pure path was asked for",
)

#: no deviation terms; unrounded (so a term's last bits would show), a bias, a rounded one
MEMBERS: list[dict[str, Any]] = [
    {"stddev": 0.01, "mean": 0.05, "precision": 0.0},
    {"stddev": 0.02, "bias_mean": 0.01, "bias_stddev": 0.005, "precision": 0.0},
    {"stddev": 0.0, "precision": 0.0, "mean": -0.3},
    {"stddev": 0.01, "lostData": 20.0, "precision": 0.0017},
]
#: true headings: zeros of both signs (the one place a skipped +-0.0 term could show),
#: ordinary ones, wrapped ones
READINGS = [0.0, -0.0, 1.0, -2.5, 3.1, -3.14159, 0.5, 6.0, -7.5, 2.0] * 3
#: at this step copy 2 gets a deviation term, as a timeline's ``set`` would give it
CHANGE_AT = 12


class Ctx:
    def __init__(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)


def _steps(compiled: bool, change: bool) -> list[tuple[bytes, bytes]]:
    comps = []
    for k, params in enumerate(MEMBERS):
        comp = Compass(f"C{k}", params)
        comp.initialize(Ctx(70 + k))
        comps.append(comp)
    params, state = ParamArrays(comps), {}
    n = len(comps)
    seen = []
    with pytest.MonkeyPatch.context() as mp:
        if not compiled:  # the numpy path: no body found
            mp.setattr(batch_bodies, "_body", lambda name: None)
        for k, value in enumerate(READINGS):
            if change and k == CHANGE_AT:  # as the engine applies a live or timeline change
                comps[2].p.deviationB = 0.04
                params.invalidate()
            heading = np.full(n, value) * (1.0 + np.arange(n) / 8)
            out, published = Compass.step_many(
                comps, Fraction(k, 4), {"heading": heading}, params, state
            )
            seen.append((out["compassHeading"][published].tobytes(), published.tobytes()))
    return seen


@needs_c
def test_no_deviation_steps_as_the_numpy_path() -> None:
    assert _steps(True, False) == _steps(False, False)


@needs_c
def test_a_deviation_set_during_the_run_applies_at_once() -> None:
    compiled, numpy_path = _steps(True, True), _steps(False, True)
    assert compiled == numpy_path
    # the term shows from the change on (copy 2 is unrounded and never lost)
    unchanged = _steps(True, False)
    assert compiled[:CHANGE_AT] == unchanged[:CHANGE_AT]
    assert compiled[CHANGE_AT] != unchanged[CHANGE_AT]
