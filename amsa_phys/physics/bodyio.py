"""The per-step calls into Chipmunk: all bodies' state read, all forces written, one step.

Reading ``body.angle``, ``body.velocity``, ... and setting ``body.force`` one property at a
time costs ~0.3-0.8 µs each through pymunk's Python layer: for two rovers that was more
time than ``space.step`` itself. ``pymunk.batch`` walks every body of the Space in C
instead, but its functions allocate a fresh descriptor and re-wrap the buffers on every
call (~2.8 µs each). ``BodyIO`` builds those descriptors once and calls Chipmunk's batch
iterators directly (~0.9 µs read, ~0.7 µs write for two rovers).

``step`` likewise calls ``cpSpaceStep`` without ``Space.step``'s Python layer when that
layer has nothing to do. That uses names ``pymunk`` has but does not document (``lib``, ``ffi``, the
Space's ``_space`` handle and step queues; pymunk is pinned to 7.x). If they are ever
missing, ``BodyIO`` falls back to the documented ``get_space_bodies`` /
``set_space_bodies`` / ``Space.step``: same results, slower. Both routes are exercised by the tests.

Layout, per body in the Space's own order (``rows`` maps rover index to that order):
state ``x, y, angle, vx, vy, w``; forces ``fx, fy, torque``.
"""

from __future__ import annotations

import array
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pymunk
import pymunk.batch as pb

STATE = 6  #: floats per body in a state read
FORCE = 3  #: floats per body in a force write

_READ = (
    pb.BodyFields.POSITION
    | pb.BodyFields.ANGLE
    | pb.BodyFields.VELOCITY
    | pb.BodyFields.ANGULAR_VELOCITY
)
_WRITE = pb.BodyFields.FORCE | pb.BodyFields.TORQUE

_lib = getattr(pb, "lib", None)
_ffi = getattr(pb, "ffi", None)


def _direct_available(space: pymunk.Space) -> bool:
    try:
        return (
            _lib is not None
            and _ffi is not None
            and all(
                hasattr(space, name)
                for name in (
                    "_space",
                    "_locked",
                    "_add_later",
                    "_remove_later",
                    "_bodies_to_check",
                    "_removed_shapes",
                    "_post_step_callbacks",
                )
            )
            and not space.threaded
            and hasattr(_lib, "cpSpaceStep")
            and hasattr(_lib, "cpSpaceEachBody")
            and hasattr(_lib, "pmSpaceBodyGetIteratorFuncBatched")
            and hasattr(_lib, "pmSpaceBodySetIteratorFuncBatched")
        )
    except Exception:  # an ffi lib raises on unknown names in some builds
        return False


def substeps(top2: float, sub_speed: float) -> int:
    """How many Chipmunk steps a physics step takes so that no rover tunnels.

    ``top2`` is the fastest rover's squared speed at the step's start, ``sub_speed`` the
    speed at which a rover covers its resolvable distance in one step (``space.
    resolvable_speed``). Chipmunk's collisions are discrete: a rover moving more than half
    the thinnest pair of shapes it can meet in one step may end up past the middle of a wall
    and be pushed out the far side (a 1 cm wall was crossed at ~62 m/s). Faster than
    ``sub_speed`` the step is cut into equal parts each within that distance; at usual
    speeds this is 1 and costs one comparison. The C step (``_step.c``'s ``substeps``) does
    the same operations, so both choose the same count.
    """
    sub2 = sub_speed * sub_speed
    if not top2 > sub2:  # (NaN too: the safety check ends such a run)
        return 1
    return math.ceil(math.sqrt(top2) / sub_speed)


def locked_step(space: pymunk.Space, step: Callable[[], Any]) -> Any:
    """Run ``step`` (a C call that steps ``space``) locked as ``Space.step`` locks it.

    Then what pymunk would do after a step: refused loudly if a collision callback queued
    work (nothing in this project does; lost silently otherwise), removed shapes forgotten.
    Shared by the plain C step (:meth:`BodyIO.step`) and the compiled step
    (``physics/compiled.py``). Returns what ``step`` returned.
    """
    space._locked = True
    try:
        result = step()
    finally:
        space._locked = False
    if space._add_later or space._remove_later or space._post_step_callbacks:
        raise RuntimeError("a collision callback changed the space during a step")
    if space._removed_shapes:
        space._removed_shapes.clear()
    return result


def velocities(bodies: list[pymunk.Body]) -> list[tuple[float, float, float]]:
    """Each body's ``vx, vy, w`` before a Chipmunk step (:func:`trapezoid`'s other end)."""
    if _lib is not None:  # Chipmunk's own getters: ~4x cheaper than the properties
        out = []
        for b in bodies:
            h = b._body
            v = _lib.cpBodyGetVelocity(h)
            out.append((v.x, v.y, _lib.cpBodyGetAngularVelocity(h)))
        return out
    return [(b.velocity.x, b.velocity.y, b.angular_velocity) for b in bodies]


def trapezoid(
    bodies: list[pymunk.Body], before: list[tuple[float, float, float]], half: float
) -> None:
    """Make the Chipmunk step just taken second order in the pose: ``p += (v1 - v0) h / 2``.

    Chipmunk moves a body by the velocity it had at the start of the step
    (``cpBodyUpdatePosition`` runs before ``cpBodyUpdateVelocity``), so under an acceleration
    ``a`` the pose lags by ``a t dt / 2``, a first-order error (a 3 s spin-up from rest on
    μ 0.1: 0.032 rad of heading at 100 Hz). Moving each body on by half the step's change of
    velocity (``half`` is ``h / 2``) makes the step the trapezoid ``p += (v0 + v1) h / 2``.
    Velocities are untouched, so no energy is added; a contact impulse's change of velocity
    moves the body by half of it times ``h``, as the trapezoid would. ``_step.c``'s
    ``second_order`` is the compiled step's copy: the same operations in the same order
    (and the same Chipmunk setters, which the properties call too).
    """
    lib = _lib
    if lib is not None:
        for b, (vx0, vy0, w0) in zip(bodies, before, strict=True):
            h = b._body
            p = lib.cpBodyGetPosition(h)
            v = lib.cpBodyGetVelocity(h)
            a = lib.cpBodyGetAngle(h)
            w = lib.cpBodyGetAngularVelocity(h)
            lib.cpBodySetPosition(h, (p.x + (v.x - vx0) * half, p.y + (v.y - vy0) * half))
            lib.cpBodySetAngle(h, a + (w - w0) * half)
        return
    for b, (vx0, vy0, w0) in zip(bodies, before, strict=True):
        p = b.position
        v = b.velocity
        a = b.angle
        w = b.angular_velocity
        b.position = (p.x + (v.x - vx0) * half, p.y + (v.y - vy0) * half)
        b.angle = a + (w - w0) * half


class BodyIO:
    """Batch state reads and force writes for every body of one Space.

    Build it after all bodies are added; the body order is fixed then. ``direct=False``
    forces the documented (slower) ``pymunk.batch`` route.
    """

    def __init__(self, space: pymunk.Space, bodies: list[pymunk.Body], direct: bool = True) -> None:
        self.space = space
        #: the bodies whose pose :func:`trapezoid` corrects after each Chipmunk step
        self.bodies = list(bodies)
        ids_buf = pb.Buffer()
        pb.get_space_bodies(space, pb.BodyFields.BODY_ID, ids_buf)
        ids = np.frombuffer(memoryview(ids_buf.int_buf()).cast("P"), dtype=np.uintp)
        self.n_bodies = len(ids)
        order = {int(body_id): i for i, body_id in enumerate(ids)}
        self.rows = [order[b.id] for b in bodies]
        #: this step's forces, written by the force model then sent by :meth:`write`
        self.forces = array.array("d", bytes(8 * FORCE * self.n_bodies))
        self._in = pb.Buffer()
        self._out = pb.Buffer()
        self._out.set_float_buf(self.forces)
        self.direct = direct and _direct_available(space)
        if self.direct:
            assert _ffi is not None
            assert _lib is not None
            self._each = _lib.cpSpaceEachBody
            self._space_step = _lib.cpSpaceStep
            self._handle = space._space
            self._get_fn = _ffi.addressof(_lib, "pmSpaceBodyGetIteratorFuncBatched")
            self._set_fn = _ffi.addressof(_lib, "pmSpaceBodySetIteratorFuncBatched")
            self._get = self._descriptor(_READ, self._in)
            self._set = self._descriptor(_WRITE, self._out)
            self._in_arr = self._in._float_arr
            self._out_arr = self._out._float_arr
            # one read sizes the C array; later reads refill it in place (the count is reset
            # to 0 first, so it never grows and never moves), so one view serves every read
            self._read_c()
            self._n_floats = self._in_arr.num
            self._view = memoryview(_ffi.buffer(self._in_arr.arr, 8 * self._n_floats)).cast("d")

    @staticmethod
    def _descriptor(fields: pb.BodyFields, buf: pb.Buffer) -> Any:
        assert _ffi is not None
        data = _ffi.new("pmBatchedData *")
        data.fields = fields.value
        data.floatArray = buf._float_arr
        data.intArray = buf._int_arr
        return data

    def _read_c(self) -> None:
        arr = self._in_arr
        arr.num = 0
        self._each(self._handle, self._get_fn, self._get)

    def _read_view(self) -> memoryview:
        """The read buffer after a fresh read, as doubles (valid until the next read)."""
        if self.direct:
            arr = self._in_arr
            arr.num = 0
            self._each(self._handle, self._get_fn, self._get)
            if arr.num != self._n_floats:
                raise RuntimeError("a body was added to the space after its BodyIO was built")
            return self._view
        self._in.clear()
        pb.get_space_bodies(self.space, _READ, self._in)
        return memoryview(self._in.float_buf()).cast("d")

    def read(self) -> list[float]:
        """Every body's ``x, y, angle, vx, vy, w`` as one flat list of floats."""
        return self._read_view().tolist()

    def read_array(self) -> np.ndarray:
        """The same state as a (bodies, 6) numpy array viewing the read buffer.

        The view is valid until the next read (the many-rover path indexes it at once).
        """
        return np.frombuffer(self._read_view(), dtype=np.float64).reshape(-1, STATE)

    def step(self, dt: float, substeps: int = 1) -> None:
        """``space.step(dt)`` without pymunk's Python bookkeeping when there is none to do;
        in ``substeps`` equal steps (:func:`substeps`: a rover fast enough to cross a wall
        within one step) with the same forces.

        ``Space.step`` wraps ``cpSpaceStep`` with work for bodies, shapes and callbacks queued
        while the space was locked (~1 µs of Python per step, half of the step for two
        rovers). Nothing in this project queues any (the collision callback only counts), so
        when those queues are empty the C step is called directly, locked as pymunk locks it.
        If a callback ever queued work during the step, it is refused loudly rather than lost.
        """
        space = self.space
        bodies = self.bodies
        h = dt / substeps
        half = 0.5 * h
        for _ in range(substeps):
            before = velocities(bodies)
            if not self.direct or space._bodies_to_check:  # new bodies: pymunk validates them
                space.step(h)
            else:
                locked_step(space, lambda: self._space_step(self._handle, h))
            trapezoid(bodies, before, half)

    def write(self) -> None:
        """Send :attr:`forces` to every body (forces of non-rover bodies stay zero)."""
        if self.direct:
            self._out_arr.num = 0
            self._each(self._handle, self._set_fn, self._set)
            return
        pb.set_space_bodies(self.space, _WRITE, self._out)
