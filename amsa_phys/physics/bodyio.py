"""All bodies' state read, and all forces written, in one C call each.

Reading ``body.angle``, ``body.velocity``, ... and setting ``body.force`` one property at a
time costs ~0.3-0.8 µs each through pymunk's Python layer: for two rovers that was more
time than ``space.step`` itself. ``pymunk.batch`` walks every body of the Space in C
instead, but its functions allocate a fresh descriptor and re-wrap the buffers on every
call (~2.8 µs each). ``BodyIO`` builds those descriptors once and calls Chipmunk's batch
iterators directly (~0.9 µs read, ~0.7 µs write for two rovers).

That uses names ``pymunk.batch`` imports but does not document (``lib``, ``ffi``, the
Space's ``_space`` handle; pymunk is pinned to 7.x). If they are ever missing, ``BodyIO``
falls back to the documented ``get_space_bodies`` / ``set_space_bodies``: same data,
slower. Both routes are exercised by the tests.

Layout, per body in the Space's own order (``rows`` maps rover index to that order):
state ``x, y, angle, vx, vy, w``; forces ``fx, fy, torque``.
"""

from __future__ import annotations

import array
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
            and hasattr(space, "_space")
            and hasattr(_lib, "cpSpaceEachBody")
            and hasattr(_lib, "pmSpaceBodyGetIteratorFuncBatched")
            and hasattr(_lib, "pmSpaceBodySetIteratorFuncBatched")
        )
    except Exception:  # an ffi lib raises on unknown names in some builds
        return False


class BodyIO:
    """Batch state reads and force writes for every body of one Space.

    Build it after all bodies are added; the body order is fixed then. ``direct=False``
    forces the documented (slower) ``pymunk.batch`` route.
    """

    def __init__(self, space: pymunk.Space, bodies: list[pymunk.Body], direct: bool = True) -> None:
        self.space = space
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
            self._handle = space._space
            self._get_fn = _ffi.addressof(_lib, "pmSpaceBodyGetIteratorFuncBatched")
            self._set_fn = _ffi.addressof(_lib, "pmSpaceBodySetIteratorFuncBatched")
            self._get = self._descriptor(_READ, self._in)
            self._set = self._descriptor(_WRITE, self._out)
            self._in_arr = self._in._float_arr
            self._out_arr = self._out._float_arr

    @staticmethod
    def _descriptor(fields: pb.BodyFields, buf: pb.Buffer) -> Any:
        assert _ffi is not None
        data = _ffi.new("pmBatchedData *")
        data.fields = fields.value
        data.floatArray = buf._float_arr
        data.intArray = buf._int_arr
        return data

    def read(self) -> list[float]:
        """Every body's ``x, y, angle, vx, vy, w`` as one flat list of floats."""
        if self.direct:
            arr = self._in_arr
            arr.num = 0
            self._each(self._handle, self._get_fn, self._get)
            return _ffi.unpack(arr.arr, arr.num)  # type: ignore[union-attr]
        self._in.clear()
        pb.get_space_bodies(self.space, _READ, self._in)
        return memoryview(self._in.float_buf()).cast("d").tolist()

    def read_array(self) -> np.ndarray:
        """The same state as a (bodies, 6) numpy array viewing the read buffer.

        The view is valid until the next read (the many-rover path indexes it at once).
        """
        if self.direct:
            arr = self._in_arr
            arr.num = 0
            self._each(self._handle, self._get_fn, self._get)
            raw = _ffi.buffer(arr.arr, 8 * arr.num)  # type: ignore[union-attr]
        else:
            self._in.clear()
            pb.get_space_bodies(self.space, _READ, self._in)
            raw = self._in.float_buf()
        return np.frombuffer(raw, dtype=np.float64).reshape(-1, STATE)

    def write(self) -> None:
        """Send :attr:`forces` to every body (forces of non-rover bodies stay zero)."""
        if self.direct:
            self._out_arr.num = 0
            self._each(self._handle, self._set_fn, self._set)
            return
        pb.set_space_bodies(self.space, _WRITE, self._out)
