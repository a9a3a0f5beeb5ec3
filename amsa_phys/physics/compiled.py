"""The compiled physics step (``_step.c``), when it was built: the same step, ~2.5x cheaper.

``FewRovers`` (fewrovers.py) spends a headless run's step in Python: the wheel model, the body
reads and writes and pymunk's step wrapper. ``CompiledFewRovers`` and ``CompiledFleet`` keep
those classes' Python API (state, rims, kinematics, refresh, set_ground, ...) and hand each
step to one C call that does all of it, calling Chipmunk through function pointers taken from
pymunk's own cffi library (no second copy of Chipmunk, nothing to link).

Same trace, bit for bit, as the pure few-rover path: the C code is ``FewRovers.apply``'s
arithmetic in the same order (see ``_step.c``). ``CompiledFleet`` (many rovers) runs that same
per-rover arithmetic too: its runs equal the pure few-rover path's and the pure fleet's
(``forces.rover_step`` is the pure path's one copy).

The extension is optional (``setup.py``): :func:`status` says which path runs and why;
``AMSA_PHYS_PURE=1`` forces the pure-Python path.
"""

from __future__ import annotations

import array
import functools
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from . import bodylayout
from .bodyio import STATE, BodyIO, locked_step, substeps
from .fewrovers import FewRovers
from .fleet import GROUND_ROWS, Fleet
from .forces import Folded, fold, per_kind
from .rover import DiffDriveRover
from .step_path import describe, extension
from .wheel import SLIP_SPEED_MIN, step_constants

_step = extension()
#: Constants ``plan_row`` can give a rover's plan: ``forces.fold``'s and the rim's compliance
#: without back-EMF (the current limit's branch).
KNOWN_FIELDS = (*Folded._fields, "big_bc")


def check_layout(ext: Any) -> tuple[str, ...]:
    """The C step's plan layout (its ``PLAN_FIELDS``), after checking that it matches this
    source: every constant it wants is one :func:`plan_row` can fill, its slip floor and
    ground layout are the Python model's. A build from another version of ``_step.c`` (an
    in-place build not redone after a change) would otherwise run on shifted constants;
    raises ImportError naming the difference instead."""
    fields = tuple(ext.PLAN_FIELDS)
    unknown = [f for f in fields if f not in KNOWN_FIELDS]
    problems = []
    if unknown or len(fields) != ext.PLAN_WIDTH:
        problems.append(f"plan constants {unknown or fields} unknown to forces.fold")
    if ext.SLIP_SPEED_MIN != SLIP_SPEED_MIN:
        problems.append(f"SLIP_SPEED_MIN {ext.SLIP_SPEED_MIN} != wheel.py's {SLIP_SPEED_MIN}")
    if list(ext.GROUND_ROWS) != GROUND_ROWS or len(GROUND_ROWS) != ext.GROUND_TERMS:
        problems.append(f"ground rows {ext.GROUND_ROWS} != fleet.GROUND_ROWS {GROUND_ROWS}")
    if not hasattr(ext, "Columns"):  # older builds: no batch step, Stepper takes 7 functions
        problems.append("no Columns (the batch's step)")
    if not getattr(ext, "SECOND_ORDER", 0):  # older builds: Chipmunk's first-order pose update
        problems.append("no second-order pose update (bodyio.trapezoid)")
    if problems:
        raise ImportError(
            "amsa_phys.physics._step was built from another version of _step.c ("
            + "; ".join(problems)
            + "): rebuild it (pip install -e .)"
        )
    return fields


#: The order of a rover's constants in the C step's plan, as ``_step.c`` declares it.
PLAN_FIELDS: tuple[str, ...] = check_layout(_step) if _step is not None else ()
#: Chipmunk functions the C step calls, in the order ``Stepper`` takes them.
_FUNCTIONS = (
    "cpBodyGetPosition",
    "cpBodyGetAngle",
    "cpBodyGetVelocity",
    "cpBodyGetAngularVelocity",
    "cpBodySetForce",
    "cpBodySetTorque",
    "cpSpaceStep",
    "cpBodySetPosition",
    "cpBodySetAngle",
)
#: Read after each step when Chipmunk's rotation of a body is ``math.cos``/``math.sin`` of
#: its angle (:func:`_rotation_is_libms`): the C step then skips computing them again.
_ROTATION = "cpBodyGetRotation"


def status() -> tuple[bool, str]:
    """(whether the compiled step runs, one phrase saying which path and why)."""
    on, why = describe()
    if on and _functions() is None:
        return False, "pure Python (this pymunk build hides Chipmunk's functions)"
    return on, why


def active() -> bool:
    """Whether new physics worlds take the compiled step."""
    return status()[0]


_cached: tuple[int, ...] | bool | None = False


def _functions() -> tuple[int, ...] | None:
    """Addresses of :data:`_FUNCTIONS` in pymunk's own Chipmunk, or None if not reachable;
    with :data:`_ROTATION`'s after them when :func:`_rotation_is_libms`."""
    global _cached
    if _cached is False:
        try:
            from pymunk._chipmunk import ffi, lib

            names = _FUNCTIONS + ((_ROTATION,) if _rotation_is_libms() else ())
            _cached = tuple(int(ffi.cast("uintptr_t", ffi.addressof(lib, n))) for n in names)
        except Exception:  # an older/newer pymunk layout: stay pure
            _cached = None
    return _cached  # type: ignore[return-value]


def _rotation_is_libms(samples: int = 200) -> bool:
    """Whether Chipmunk's rotation of a body equals ``math.cos`` and ``math.sin`` of its
    angle (the functions the C step calls) on angles of every size and sign: true where
    pymunk's Chipmunk calls the same libm (checked once a process, ~0.2 ms); elsewhere the C
    step computes them itself."""
    import math

    import pymunk
    from pymunk._chipmunk import lib

    body = pymunk.Body(1.0, 1.0)
    for i in range(samples):
        angle = math.ldexp(math.sin(7.0 * i + 1.0), i % 40 - 20)  # |angle| 1e-6 .. 1e6
        body.angle = angle
        r = lib.cpBodyGetRotation(body._body)
        if r.x != math.cos(angle) or r.y != math.sin(angle):
            return False
    return True


def _address(handle: Any) -> int:
    from pymunk._chipmunk import ffi

    return int(ffi.cast("uintptr_t", handle))


def plan_row(rover: DiffDriveRover, dt: float) -> list[float]:
    """One rover's constants in :data:`PLAN_FIELDS` order (folded as FewRovers folds them)."""
    f = fold(rover, dt)._asdict()
    s = step_constants(rover.wheel, dt, rover.mass, rover.moment, rover.half_track)
    f["big_bc"] = s.big_bc
    return [f[name] for name in PLAN_FIELDS]


def plan_rows(rovers: Sequence[DiffDriveRover], dt: float) -> list[list[float]]:
    """:func:`plan_row` of every rover, folded once per kind of rover (``forces.per_kind``)."""
    return per_kind(rovers, lambda r: plan_row(r, dt))


def _locked_step(space: Any, step: Any) -> int:
    """Run the C step locked as ``Space.step`` locks it (``bodyio.locked_step``)."""
    return int(locked_step(space, step))


def _step_with(io: BodyIO, stepper: Any, dt: float, top2: float, sub_speed: float) -> int:
    """One step through ``stepper``; pymunk's own ``Space.step`` when it has bodies to check
    (in as many sub-steps as the C step would take: ``bodyio.substeps``)."""
    space = io.space
    if space._bodies_to_check:  # new bodies (the first step): let pymunk validate them
        stepper.apply()
        n = substeps(top2, sub_speed)
        h = dt / n
        for _ in range(n):
            stepper.before()
            space.step(h)
            stepper.after(h)  # the trapezoid, as the C step's own steps (bodyio.trapezoid)
        return int(stepper.read_check())
    return _locked_step(space, stepper.advance)


def usable(io: BodyIO) -> bool:
    """Whether the compiled step can drive ``io``'s space (the C step needs BodyIO's route)."""
    return active() and io.direct


def _fill(model: Any, name: str, values: Sequence[float]) -> None:
    """Create ``model.<name>`` as a double array of ``values``, or copy them into it in place
    (the C step holds it; its length never changes)."""
    buf = model.__dict__.get(name)
    if buf is None:
        model.__dict__[name] = array.array("d", values)
        return
    new = array.array("d", values)
    if len(new) != len(buf):
        raise ValueError(f"{name[1:]}: {len(buf)} values expected, got {len(new)}")
    buf[:] = new


class CompiledFewRovers(FewRovers):
    """``FewRovers`` with the step in C: same API, same numbers."""

    def __init__(
        self,
        io: BodyIO,
        rovers: list[DiffDriveRover],
        dt: float,
        limits: tuple[float, float],
        grounds: list[list[float]],
    ) -> None:
        self._stepper: Any = None
        n = len(rovers)
        self._plan_buf = array.array("d", bytes(8 * len(PLAN_FIELDS) * n))
        self._ground = array.array("d", [t for terms in grounds for t in terms])
        self.drives = np.zeros((2, n))
        super().__init__(io, rovers, dt, limits, grounds)  # sets rims and state (below)
        slots = memoryview(self.drives)  # the same memory; an item write ~45 ns cheaper
        for k, r in enumerate(rovers):
            r.attach_power_slot(slots, k)
        assert _step is not None
        self._stepper = _step.Stepper(
            _address(io.space._space),
            _functions(),
            array.array("Q", [_address(r.body._body) for r in rovers]),
            array.array("q", self.offsets),
            self._plan_buf,
            self.drives,
            self.rims,
            (2, 1),
            self._ground,
            (len(GROUND_ROWS), tuple(range(len(GROUND_ROWS)))),
            self.state,
            dt,
            self._max2,
            self.extent,
            self.sub_speed,
            direct=bodylayout.body_layout_ok(),
        )
        #: ``advance_many(count)``: up to ``count`` steps in one C call, each as
        #: :meth:`advance` takes it: (steps taken, the first bad rover's index after the
        #: last of them, or -1). The C call itself, which ``PhysicsWorld.step_many`` makes
        #: with no layer between; the caller locks the space, and a collision callback finds
        #: its step in :meth:`batch_index` and may end the batch there (:meth:`stop_batch`).
        #: None with an extension built before it.
        self.advance_many = getattr(self._stepper, "advance_many", None)

    # rims and state are buffers the C step holds: assigning either copies into it (as the
    # pure class's users assign lists), so the step never runs on a stale buffer
    @property  # type: ignore[override]
    def rims(self) -> array.array[float]:
        """Left and right rim speed of rover ``k`` at ``2k``, ``2k + 1`` (m/s)."""
        return self._rims

    @rims.setter
    def rims(self, values: Sequence[float]) -> None:
        _fill(self, "_rims", values)

    @property  # type: ignore[override]
    def state(self) -> array.array[float]:
        """Every body's ``x, y, angle, vx, vy, w`` after the last step (rovers' rows kept)."""
        return self._state

    @state.setter
    def state(self, values: Sequence[float]) -> None:
        _fill(self, "_state", values)

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...)."""
        super().refresh()
        width = len(PLAN_FIELDS)
        for k, r in enumerate(self.rovers):
            self._plan_buf[k * width : (k + 1) * width] = array.array("d", plan_row(r, self.dt))

    def set_ground(self, k: int, terms: list[float]) -> None:
        """Rover ``k``'s ground terms (``ground_list``) from the next step on."""
        super().set_ground(k, terms)
        width = len(GROUND_ROWS)
        self._ground[width * k : width * (k + 1)] = array.array("d", terms)

    def kinematics(self, k: int) -> list[float]:
        """Rover ``k``'s six state floats after the last step."""
        return self._stepper.kinematics(k)  # type: ignore[no-any-return]

    def rim_speeds(self, k: int) -> tuple[float, float]:
        """Rover ``k``'s left and right rim speeds (m/s) after the last step."""
        return self._stepper.rim_speeds(k)  # type: ignore[no-any-return]

    def readers(self, k: int) -> tuple[Callable[[], list[float]], Callable[[], Any]]:
        """:meth:`kinematics` and :meth:`rim_speeds` of rover ``k`` as calls straight into
        the C step (``PhysicsWorld`` attaches them to the rover: no Python frame between)."""
        stepper = self._stepper
        return functools.partial(stepper.kinematics, k), functools.partial(stepper.rim_speeds, k)

    def advance(self) -> tuple[int, str] | None:
        """One physics step in C; a safety violation or None.

        ``_step_with`` inlined: at 100 Hz two Python calls a step are ~5 % of scenario1.
        """
        space = self.io.space
        if space._bodies_to_check:
            bad = _step_with(self.io, self._stepper, self.dt, self._top2, self.sub_speed)
        else:
            space._locked = True
            try:
                bad = self._stepper.advance()
            finally:
                space._locked = False
            if space._add_later or space._remove_later or space._post_step_callbacks:
                raise RuntimeError("a collision callback changed the space during a step")
            if space._removed_shapes:
                space._removed_shapes.clear()
        if bad < 0:
            return None
        return self.first_violation(self.state, self.max_speed, self.extent)

    def batch_index(self) -> int:
        """The step :meth:`advance_many` is taking (0: its first)."""
        return self._stepper.batch_i  # type: ignore[no-any-return]

    def stop_batch(self) -> None:
        """End :meth:`advance_many` after the step under way."""
        self._stepper.stop_batch()


class CompiledFleet(Fleet):
    """``Fleet`` (many rovers, arrays) with the step in C, per rover as FewRovers."""

    def __init__(
        self,
        io: BodyIO,
        rovers: list[DiffDriveRover],
        dt: float,
        limits: tuple[float, float],
        grounds: list[list[float]],
    ) -> None:
        self._stepper: Any = None
        self._plan_buf = np.zeros((len(rovers), len(PLAN_FIELDS)))
        super().__init__(io, rovers, dt, limits, grounds)  # sets rims and state (below)
        n = len(rovers)
        self._stepper = _step.Stepper(  # type: ignore[union-attr]
            _address(io.space._space),
            _functions(),
            array.array("Q", [_address(r.body._body) for r in rovers]),
            array.array("q", range(0, STATE * n, STATE)),
            self._plan_buf,
            self.drives,
            self.rims,
            (1, n),
            self.ground,
            (1, tuple(row * n for row in GROUND_ROWS)),
            self.state,
            dt,
            self.max_speed * self.max_speed * (1 - 1e-12),
            self.extent,
            self.sub_speed,
            direct=bodylayout.body_layout_ok(),
        )

    # as CompiledFewRovers: assigning rims or state copies into the C step's arrays
    @property  # type: ignore[override]
    def rims(self) -> np.ndarray:
        """(2, n) rim speeds, left row then right row (m/s)."""
        return self._rims

    @rims.setter
    def rims(self, values: Any) -> None:
        _fill_array(self, "_rims", values)

    @property  # type: ignore[override]
    def state(self) -> np.ndarray:
        """(n, 6) ``x, y, angle, vx, vy, w`` of every rover after the last step."""
        return self._state

    @state.setter
    def state(self, values: Any) -> None:
        _fill_array(self, "_state", values)

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...)."""
        super().refresh()
        if self.rovers:
            self._plan_buf[...] = plan_rows(self.rovers, self.dt)

    def advance(self) -> tuple[int, str] | None:
        """One physics step in C; a safety violation or None."""
        bad = _step_with(self.io, self._stepper, self.dt, self._top2, self.sub_speed)
        if bad < 0:
            return None
        return self.first_violation(self.state, self.max_speed, self.extent)


def _fill_array(model: Any, name: str, values: Any) -> None:
    """``_fill`` for numpy arrays: a C-contiguous float64 copy first, in place afterwards."""
    buf = model.__dict__.get(name)
    if buf is None:
        model.__dict__[name] = np.array(values, dtype=np.float64, order="C")
        return
    buf[...] = values  # numpy refuses a shape that does not broadcast to it


def columns_compiled() -> bool:
    """Whether a batch's column forces take the C force model (:class:`ColumnForces`).

    Only ``_step.c``'s force code is needed (no Chipmunk functions: a batch integrates its
    rovers itself), so only the extension and ``AMSA_PHYS_PURE`` decide.
    """
    return describe()[0] and hasattr(_step, "column_forces")


class ColumnForces(Fleet):
    """``Fleet`` whose force pass is ``_step.column_forces``: the C per-rover force model.

    Why: in a batched sweep the numpy pass evaluated the masks of the wheel model's rare
    branches over whole arrays at most steps (half of a batch's time); the C code takes
    each rover's branch alone. And it is the code a run made alone takes (the compiled
    step), so a batched row equals its single run's when the integration does
    (``columns.py``). Everything else (drives, rims, ground, state, the safety check) is
    the Fleet's, in the same arrays.
    """

    def refresh(self) -> None:
        """Re-read every rover's constants into the C plan (folded as FewRovers folds them)."""
        super().refresh()
        plan = np.array(plan_rows(self.rovers, self.dt), dtype=np.float64).reshape(
            len(self.rovers), len(PLAN_FIELDS)
        )
        if getattr(self, "_plan", None) is None:
            self._plan = plan
        else:  # in place: a :meth:`columns` step holds this array
            self._plan[...] = plan

    def apply(self, state: np.ndarray) -> None:
        """Every rover's force and torque for this step (into the io's forces), rims advanced."""
        out = self._out[self._span] if self._span is not None else self._gather
        state = np.ascontiguousarray(state, dtype=np.float64)
        _step.column_forces(  # type: ignore[union-attr]
            self._plan, self.drives, self.rims, self.ground, state, out, self.dt
        )
        if self._span is None:
            self._out[self.rows] = out

    def columns(
        self,
        state: np.ndarray,
        forces: np.ndarray,
        inverse: tuple,
        screen: dict,
        threads: int = 1,
    ) -> Any:
        """The whole column step in C (``_step.Columns``) over these arrays: contact screening
        on the state before the step, this model's forces, Chipmunk's integration of a body
        without contacts and the safety check, as ``columns.ColumnPhysics`` does them in
        numpy, in one call. ``inverse`` is (1/m, 1/I) per rover; ``screen`` the screening's
        arrays (``ColumnPhysics._start``); ``state`` and ``forces`` the io's, which the step
        updates in place (this model's ``state`` becomes ``state``). ``threads`` above 1
        splits each step's forces and integration between that many threads
        (``workers.h``): the same floats, in a little over half the wall time on two cores."""
        self.state = state
        return _step.Columns(  # type: ignore[union-attr]
            self._plan,
            self.drives,
            self.rims,
            self.ground,
            state,
            forces,
            *inverse,
            self.dt,
            self.max_speed**2,
            self.extent,
            **screen,
            threads=threads,
        )
