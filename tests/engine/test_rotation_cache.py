"""The compiled step takes a rover's cos and sin from Chipmunk's rotation of its body
(``_step.c``'s rotation cache) only for the very angle they belong to: a state written
between steps (a reset, a teleport) gets the forces of its own angle."""

from __future__ import annotations

import pytest
from regimes import DT, every_regime

from amsa_phys.physics import bodyio, compiled
from amsa_phys.physics.bodyio import BodyIO
from amsa_phys.physics.fewrovers import FewRovers
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.step_path import extension

pytestmark = pytest.mark.skipif(
    extension() is None or not compiled.active(),
    reason="the compiled step was not built (no C compiler at install)",
)


def test_chipmunks_rotation_is_this_libms_cos_and_sin() -> None:
    assert compiled._rotation_is_libms(2000)  # so the cache is on here (eight functions)
    assert len(compiled._functions() or ()) == len(compiled._FUNCTIONS) + 1


def test_a_state_written_between_steps_gets_the_forces_of_its_own_angle() -> None:
    space, rovers, rims, grounds = every_regime(20)
    terms = [ground_list(r, *g) for r, g in zip(rovers, grounds, strict=True)]
    alone = compiled.CompiledFewRovers(
        BodyIO(space, [r.body for r in rovers]), rovers, DT, (100.0, 1e4), terms
    )
    alone.rims = [u for pair in rims for u in pair]
    for _ in range(3):  # the cache now holds the bodies' angles after a step
        alone.advance()
    state = list(alone.state)
    for k in range(len(rovers)):
        state[alone.offsets[k] + 2] += 0.25 * (k + 1)  # every rover turned, bodies not
    alone.state = state
    pure = FewRovers(BodyIO(space, [r.body for r in rovers]), rovers, DT, (100.0, 1e4), terms)
    pure.rims = list(alone.rims)
    pure.apply(state)
    alone._stepper.apply()  # the C step's forces for the state written
    for k, r in enumerate(rovers):
        o = pure.rows[k] * bodyio.FORCE
        assert (r.body.force.x, r.body.force.y, r.body.torque) == tuple(pure.io.forces[o : o + 3])
