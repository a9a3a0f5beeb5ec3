"""The compiled step computes rovers two at a time where both take the wheel model's usual
path (``_step.c``, ``rover_pair``: the two rovers' chains side by side, so the CPU overlaps
them) and one at a time otherwise. Held here: over rovers in every regime (rims at rest,
stuck or breaking away, reversed, current-limited, tyres saturated on ice and mud, slopes,
holding brakes), mixed so that a usual rover is paired with an unusual one as often as with
another usual one, the forces and rims of a batch computed two by two are those of each
rover computed alone, to the last bit, step after step as the rims move on."""

from __future__ import annotations

import numpy as np
import pytest
from regimes import DT, every_regime

from amsa_phys.physics import compiled
from amsa_phys.physics.columns import _ColumnIO
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.step_path import PURE_ENV, extension

pytestmark = pytest.mark.skipif(
    extension() is None, reason="the compiled step was not built (no C compiler at install)"
)


def _unusual(n: int) -> dict[str, np.ndarray]:
    """The force model's arrays of ``n`` rovers in every regime (``regimes.every_regime``),
    some on slopes and some with a holding brake."""
    _space, rovers, rims, grounds = every_regime(n)
    terms = [ground_list(r, *g) for r, g in zip(rovers, grounds, strict=True)]
    model = compiled.ColumnForces(
        _ColumnIO(np.zeros((n, 6)), np.ones(n), np.ones(n)), rovers, DT, (100.0, 1e4), terms
    )
    model.rims[...] = np.array(rims).T
    plan = model._plan.copy()
    ground = np.array(model.ground, dtype=np.float64)
    for k in range(0, n, 7):  # on a slope: gravity's pull in the plane (ground rows 7, 8)
        ground[7, k], ground[8, k] = 0.4, -0.3
    plan[3::11, compiled.PLAN_FIELDS.index("brake")] = 2.5  # a zero command is a brake
    drives = np.array(model.drives, dtype=np.float64)
    drives[:, 5::9] = 0.0
    pose = [[r.body.position.x, r.body.position.y, r.body.angle] for r in rovers]
    velocity = [[*r.body.velocity, r.body.angular_velocity] for r in rovers]
    return {
        "plan": plan,
        "drives": drives,
        "rims": np.array(model.rims, dtype=np.float64),
        "ground": ground,
        "state": np.hstack([pose, velocity]),
    }


def _usual(envs: int) -> dict[str, np.ndarray]:
    """The arrays of a vector env's rovers driven a while by random actions: the wheel
    model's usual path, mostly.

    The env runs on the compiled step even under ``AMSA_PHYS_PURE=1``: what is held is the C
    step's pairing, and these arrays (its plan, drives, ground rows) are the compiled force
    model's; the pure step has none to give (the two steps' equality is
    ``test_compiled_step.py``'s)."""
    pytest.importorskip("gymnasium", reason="the gym extra is not installed")
    from amsa_phys.gym.vector import FollowVecEnv

    with pytest.MonkeyPatch.context() as m:
        m.delenv(PURE_ENV, raising=False)
        env = FollowVecEnv(envs, stepping="batch")
        try:
            env.reset(seed=3)
            rng = np.random.default_rng(3)
            for _ in range(12):
                env.step(rng.uniform(-1.0, 1.0, (envs, 2)))
            columns = env._episode.columns  # type: ignore[union-attr]
            # mid-period: the tyres settled on the command
            columns._fused.advance_many(12, True)
            model = columns._model
            return {
                "plan": model._plan.copy(),
                "drives": np.array(model.drives, dtype=np.float64),
                "rims": np.array(model.rims, dtype=np.float64),
                "ground": np.array(model.ground, dtype=np.float64),
                "state": columns._io.state.copy(),
            }
        finally:
            env.close()


def _batch() -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Usual and unusual rovers mixed so that the pairs (0, 1), (2, 3), ... are usual and
    usual, usual and unusual, unusual and usual, unusual and unusual, in turn; and which
    rovers are the usual ones."""
    usual, unusual = _usual(24), _unusual(48)
    order = []  # (source, rover) for each place in the batch
    u = v = 0
    for kinds in ["uu", "ux", "xu", "xx"] * 12:
        for kind in kinds:
            order.append((usual, u) if kind == "u" else (unusual, v))
            u, v = (u + 1, v) if kind == "u" else (u, v + 1)
    out = {}
    for key in ("plan", "state"):
        out[key] = np.array([src[key][k] for src, k in order])
    for key in ("drives", "rims", "ground"):  # (rows, rovers) arrays
        out[key] = np.ascontiguousarray(np.array([src[key][:, k] for src, k in order]).T)
    return out, np.array([src is usual for src, _ in order])


def _forces(a: dict[str, np.ndarray], rims: np.ndarray) -> np.ndarray:
    """``_step.column_forces`` over the whole batch (two by two where it can); ``rims``
    advanced in place."""
    out = np.zeros((len(a["state"]), 3))
    compiled._step.column_forces(a["plan"], a["drives"], rims, a["ground"], a["state"], out, DT)
    return out


def _alone(a: dict[str, np.ndarray], rims: np.ndarray) -> np.ndarray:
    """The same, each rover in a batch of its own (one at a time)."""
    out = np.zeros((len(a["state"]), 3))
    for k in range(len(out)):
        one = {
            "plan": a["plan"][k : k + 1].copy(),
            "drives": np.ascontiguousarray(a["drives"][:, k : k + 1]),
            "ground": np.ascontiguousarray(a["ground"][:, k : k + 1]),
            "state": a["state"][k : k + 1].copy(),
        }
        rim = np.ascontiguousarray(rims[:, k : k + 1])
        out[k : k + 1] = _forces(one, rim)
        rims[:, k] = rim[:, 0]
    return out


def test_two_by_two_is_one_by_one_in_every_regime() -> None:
    a, usual = _batch()
    rng = np.random.default_rng(2)
    seen_at_rest = 0
    for step in range(40):
        pairs, alone = a["rims"].copy(), a["rims"].copy()
        got, expected = _forces(a, pairs), _alone(a, alone)
        for k in range(len(got)):
            assert got[k].tobytes() == expected[k].tobytes(), f"step {step}, rover {k} forces"
            assert pairs[:, k].tobytes() == alone[:, k].tobytes(), f"step {step}, rover {k} rims"
        seen_at_rest += int((pairs == 0.0).all(axis=0).sum())
        a["rims"] = pairs
        # the bodies move on: the usual ones a little, the others more
        scale = np.where(usual, 1e-4, 0.05)[:, None]
        a["state"][:, 2:] += rng.normal(0.0, 1.0, (len(got), 4)) * scale
    assert seen_at_rest > 0  # the rims-at-rest branch was in the mix
