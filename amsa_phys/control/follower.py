"""FollowerController: the paper's proportional leader-following law.

The error between the follower and its desired place (``distanceRef`` behind the leader on
the line joining them) is decomposed along and across the follower's heading: with ``alpha``
the bearing of the leader seen from the follower (from the GPS fixes and the compass) and
``e = distance - distanceRef``,

* forward power  = (100 * Kv * e + Kff * ff(v_leader)) * cos(alpha)         [%]
* turning power  = 100 * Kw * alpha                                          [%]
* left = forward - turning, right = forward + turning.

``Kv`` is in fractions of full power per metre of distance error and ``Kw`` per radian of
bearing error. The feed-forward term uses the leader's speed estimated from its GPS fixes
(a least-squares slope over ``speedWindow`` seconds of *new* fixes: a lost fix leaves the
buffer unchanged and is not mistaken for a stop; a jump faster than twice ``maxSpeed``, such as
the first real fix after the buffer's initial 0, restarts the estimate). The paper's controller
"considers the rovers' distance and speed"; without it a proportional law can only hold the
distance with a standing error proportional to the leader's speed. ``ff(v) = frictionPower + 100 v /
maxSpeed`` (for v > 0) is the controller's calibrated model of its own rover: the power that
holds speed ``v`` on flat ground (``frictionPower`` overcomes rolling resistance). Worn motors
(``motorCoef`` < 100) make that model wrong, which is exactly what the degraded context tests.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..engine import batch_bodies, libm
from ..engine.clock import seconds
from ..model.params import Param
from ..model.template import Kind, Port, Template


class FollowerController(Template):
    """Proportional follower law: Kv on the distance error, Kw on the bearing error."""

    kind = Kind.CONTROLLER
    uses_random = False
    setpoints = frozenset({"distanceRef"})
    inputs = (
        Port("xLeader", 0.0, "leader x (GPS)", "m"),
        Port("yLeader", 0.0, "leader y (GPS)", "m"),
        Port("xFollower", 0.0, "follower x (GPS)", "m"),
        Port("yFollower", 0.0, "follower y (GPS)", "m"),
        Port("headingFollower", 0.0, "follower heading (compass)", "rad"),
        Port("distanceLeaderFollower", 0.0, "leader-follower distance", "m"),
    )
    outputs = (
        Port("LeftPower", 0.0, "left wheel power", "%"),
        Port("RightPower", 0.0, "right wheel power", "%"),
        Port("leaderSpeed", 0.0, "estimated leader speed", "m/s"),
    )
    params = (
        Param(
            "Kv",
            "float",
            "gain on the distance error (power fraction per metre)",
            0.1,
            0.0,
            10.0,
            "1/m",
        ),
        Param(
            "Kw",
            "float",
            "gain on the bearing error (power fraction per radian)",
            0.04,
            0.0,
            10.0,
            "1/rad",
        ),
        Param("distanceRef", "float", "reference distance to the leader", 15.0, 0.0, 1000.0, "m"),
        Param(
            "Kff", "float", "weight of the leader-speed feed-forward (0 disables it)", 0.0, 0.0, 2.0
        ),
        Param(
            "maxSpeed",
            "float",
            "speed gained per 100 % of power, as the controller believes it",
            5.5,
            0.01,
            100.0,
            "m/s",
        ),
        Param(
            "frictionPower",
            "float",
            "power needed to overcome rolling resistance, as the controller believes it",
            6.5,
            0.0,
            100.0,
            "%",
        ),
        Param(
            "speedWindow", "float", "time window of the leader-speed estimate", 3.0, 0.1, 600.0, "s"
        ),
    )

    def initialize(self, ctx: Any) -> None:
        """Start with no speed estimate."""
        self.fixes: deque[tuple[float, float, float]] = deque()
        self.v_leader = 0.0

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one control update."""
        p = self.p
        if inp["distanceLeaderFollower"] <= 0.0:
            # no distance measured yet (or the rovers touch): command nothing
            return {"LeftPower": 0.0, "RightPower": 0.0, "leaderSpeed": self.v_leader}
        xl, yl = inp["xLeader"], inp["yLeader"]
        # float(t) without ``Fraction.__float__``'s calls (numerator / denominator, as it does)
        self._update_speed(
            t._numerator / t._denominator if t.__class__ is Fraction else float(t), xl, yl
        )
        dx = xl - inp["xFollower"]
        dy = yl - inp["yFollower"]
        alpha = math.atan2(dy, dx) - inp["headingFollower"]
        alpha = (alpha + math.pi) % (2 * math.pi) - math.pi
        e = inp["distanceLeaderFollower"] - p.distanceRef
        ff = p.frictionPower + 100.0 * self.v_leader / p.maxSpeed if self.v_leader > 0 else 0.0
        forward = (100.0 * p.Kv * e + p.Kff * ff) * math.cos(alpha)
        turn = 100.0 * p.Kw * alpha
        return {
            "LeftPower": forward - turn,
            "RightPower": forward + turn,
            "leaderSpeed": self.v_leader,
        }

    def _update_speed(self, t: float, x: float, y: float) -> None:
        fixes = self.fixes
        if fixes and fixes[-1][1] == x and fixes[-1][2] == y:
            return  # no new fix (lost sample): keep the estimate
        if fixes:
            lt, lx, ly = fixes[-1]
            if math.hypot(x - lx, y - ly) > 2 * self.p.maxSpeed * max(t - lt, 0.25):
                fixes.clear()  # an impossible jump: the first real fix, or a GPS glitch
        fixes.append((t, x, y))
        while fixes and fixes[0][0] < t - self.p.speedWindow:
            fixes.popleft()
        n = len(fixes)
        if n < 2:
            return
        # least-squares slope, two passes (means, then centred sums) in plain loops: the
        # controller runs every step and generator expressions cost twice as much
        st = sx = sy = 0.0
        for ft, fx, fy in fixes:
            st += ft
            sx += fx
            sy += fy
        mt, mx, my = st / n, sx / n, sy / n
        stt = stx = sty = 0.0
        for ft, fx, fy in fixes:
            d = ft - mt
            stt += d * d
            stx += d * (fx - mx)
            sty += d * (fy - my)
        if stt <= 0:
            return
        self.v_leader = math.hypot(stx / stt, sty / stt)

    @classmethod
    def step_many(
        cls,
        comps: Sequence[FollowerController],
        t: Fraction,
        inp: Mapping[str, Any],
        p: Any,
        state: dict[str, Any],
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once (``engine/batch.py``).

        The fixes of every copy live in a (copies, slots) array, newest in the last column,
        with a mask of the slots in use; the update follows ``_update_speed`` step by step
        (skip a repeated fix, restart after an impossible jump, append, drop old fixes) and
        the slope is the same two-pass least squares, summed along the rows.
        """
        n = len(comps)
        ts = seconds(t)
        if "fixes" not in state:
            state["fixes"] = _grow(None, n, 16)
            state["v"] = np.zeros(n)
            #: the whole step as one compiled call, where built (``engine/batch_bodies.py``)
            state["body"] = batch_bodies.follower()
        v_leader = state["v"]
        xl, yl, d = inp["xLeader"], inp["yLeader"], inp["distanceLeaderFollower"]
        if state["body"] is not None:
            return _step_compiled(state, n, ts, inp, p), None
        active = d > 0.0
        # _update_speed, for the active copies whose leader fix is new
        T, X, Y, used = state["fixes"]
        has = used[:, -1]
        same = has & (X[:, -1] == xl) & (Y[:, -1] == yl)
        upd = active & ~same
        if upd.any():
            jump = libm.hypot_exceeds(
                xl - X[:, -1], yl - Y[:, -1], 2 * p.maxSpeed * np.maximum(ts - T[:, -1], 0.25)
            )
            used[upd & has & jump] = False
            rows = np.flatnonzero(upd)
            # all copies at once (the usual case: their fixes arrive together) use views, a
            # subset gathers copies; the arithmetic is the same either way
            sel: slice | np.ndarray = slice(None) if len(rows) == n else rows
            if used[sel, 0].any():  # a window longer than the slots: double them
                state["fixes"] = _grow(state["fixes"], n, 2 * T.shape[1])
                T, X, Y, used = state["fixes"]
            for arr, new in ((T, ts), (X, xl[sel]), (Y, yl[sel])):
                arr[sel, :-1] = arr[sel, 1:]
                arr[sel, -1] = new
            used[sel, :-1] = used[sel, 1:]
            used[sel, -1] = True
            used[sel] &= T[sel] >= (ts - p.speedWindow[sel])[:, None]
            m = used[sel]
            t_, x_, y_ = T[sel], X[sel], Y[sel]
            k = m.sum(axis=1)
            count = np.maximum(k, 1)  # rows with no fix are masked out below
            mt = _in_order(np.where(m, t_, 0.0)) / count
            mx = _in_order(np.where(m, x_, 0.0)) / count
            my = _in_order(np.where(m, y_, 0.0)) / count
            dt = np.where(m, t_ - mt[:, None], 0.0)
            stt = _in_order(dt * dt)
            stx = _in_order(dt * (x_ - mx[:, None]))
            sty = _in_order(dt * (y_ - my[:, None]))
            ok = (k >= 2) & (stt > 0)
            safe = np.where(ok, stt, 1.0)
            v_leader[rows[ok]] = libm.hypot(stx / safe, sty / safe)[ok]
        dx = xl - inp["xFollower"]
        dy = yl - inp["yFollower"]
        alpha = libm.atan2(dy, dx) - inp["headingFollower"]
        alpha = (alpha + math.pi) % (2 * math.pi) - math.pi
        e = d - p.distanceRef
        moving = v_leader > 0
        ff = np.where(moving, p.frictionPower + 100.0 * v_leader / p.maxSpeed, 0.0)
        forward = (100.0 * p.Kv * e + p.Kff * ff) * np.cos(alpha)
        turn = 100.0 * p.Kw * alpha
        zero = np.zeros(n)
        return {
            "LeftPower": np.where(active, forward - turn, zero),
            "RightPower": np.where(active, forward + turn, zero),
            "leaderSpeed": v_leader.copy(),
        }, None


def _step_compiled(
    state: dict[str, Any], n: int, ts: float, inp: Mapping[str, Any], p: Any
) -> dict[str, np.ndarray]:
    """``step_many``'s numpy path below as one compiled call (``_groupbodies.follower``): the
    same floats bit for bit (``tests/engine/test_group_bodies.py``). The body changes nothing
    and says so when a member's window needs more slots than there are: they double, as
    the numpy path doubles them, and it runs again."""
    out = {"LeftPower": np.empty(n), "RightPower": np.empty(n), "leaderSpeed": np.empty(n)}
    fresh = state.get("fresh")
    if fresh is None or len(fresh) != n:
        fresh = state["fresh"] = np.zeros(n, dtype=bool)
    args = (
        inp["xLeader"],
        inp["yLeader"],
        inp["xFollower"],
        inp["yFollower"],
        inp["headingFollower"],
        inp["distanceLeaderFollower"],
        state["v"],
        p.Kv,
        p.Kw,
        p.distanceRef,
        p.Kff,
        p.maxSpeed,
        p.frictionPower,
        p.speedWindow,
        out["LeftPower"],
        out["RightPower"],
        out["leaderSpeed"],
        fresh,
    )
    while not state["body"](ts, *state["fixes"], *args):
        state["fixes"] = _grow(state["fixes"], n, 2 * state["fixes"][0].shape[1])
    return out


def _in_order(a: np.ndarray) -> np.ndarray:
    """Each row's sum, added left to right as ``_update_speed`` adds its fixes.

    Why not ``a.sum(axis=1)``: numpy sums a row of eight or more with eight interleaved
    accumulators (pairwise summation), which rounds unlike the sequential loop of ``do_step``
    and so gave a batched run a leader speed a few ulps off the run made alone (a different
    trace, and a different command with ``Kff`` > 0). ``cumsum`` accumulates in order; the
    masked slots add 0.0, which leaves a sum unchanged.
    """
    return np.cumsum(a, axis=1)[:, -1]


def _grow(
    fix: tuple[np.ndarray, ...] | None, n: int, slots: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The fix arrays with ``slots`` columns, the newest fixes kept in the last ones."""
    T, X, Y = (np.zeros((n, slots)) for _ in range(3))
    used = np.zeros((n, slots), dtype=bool)
    if fix is not None:
        w = fix[0].shape[1]
        for new, old in zip((T, X, Y, used), fix, strict=True):
            new[:, slots - w :] = old
    return T, X, Y, used
