"""The optional compiled physics step (``amsa_phys/physics/_step.c``) and the engine's compiled
write of published outputs (``amsa_phys/engine/_publish.c``) and its other C helpers; the rest
is pyproject.toml.

``optional=True``: where there is no C compiler (or no Python headers) the build of the
extension fails quietly and the install goes on; ``amsa_phys.physics.compiled`` then finds no
``_step`` module and the pure-Python step runs (``amsa-phys --version`` says which).
``-ffp-contract=off`` and no ``-ffast-math``: the C step must round every operation as
CPython does, or the traces would differ from the pure path's.
"""

import os

from setuptools import Extension, setup


def _numpy_random() -> list[Extension]:
    """The draws extension (``amsa_phys/engine/_draws.c``), linked with the static library of
    numpy's distributions that numpy ships for extensions; none where numpy (a build
    requirement) cannot be imported or ships no such library."""
    try:
        import numpy
    except ImportError:
        return []
    lib = os.path.join(os.path.dirname(numpy.__file__), "random", "lib")
    if not os.path.exists(os.path.join(lib, "libnpyrandom.a")):
        return []
    return [
        Extension(
            "amsa_phys.engine._draws",
            ["amsa_phys/engine/_draws.c"],
            include_dirs=[numpy.get_include()],
            library_dirs=[lib],
            libraries=["npyrandom", "m"],
            optional=True,
        )
    ]


#: Python's float ``%`` in C, included by three of the extensions (their angle wrapping)
PYMOD = "amsa_phys/pymod.h"

setup(
    ext_modules=[
        Extension(
            "amsa_phys.physics._step",
            ["amsa_phys/physics/_step.c"],
            # workers.h: the helper threads of a batch's column step
            depends=[PYMOD, "amsa_phys/physics/workers.h"],
            extra_compile_args=["-O2", "-ffp-contract=off", "-fno-fast-math", "-pthread"],
            extra_link_args=["-pthread"],
            libraries=["m"],
            optional=True,
        ),
        # the engine's write of a component's outputs into the store (engine/publish.py)
        Extension("amsa_phys.engine._publish", ["amsa_phys/engine/_publish.c"], optional=True),
        Extension(
            "amsa_phys.engine._kernels",
            ["amsa_phys/engine/_kernels.c"],
            depends=[PYMOD],
            # the components' bodies (``engine/kernels.py``) round as Python's arithmetic does
            extra_compile_args=["-O2", "-ffp-contract=off", "-fno-fast-math"],
            libraries=["m"],
            optional=True,
        ),
        Extension(
            "amsa_phys.engine._groupbodies",
            ["amsa_phys/engine/_groupbodies.c"],
            depends=[PYMOD],
            # component groups' numpy arithmetic as one loop (``engine/batch_bodies.py``)
            extra_compile_args=["-O2", "-ffp-contract=off", "-fno-fast-math"],
            libraries=["m"],
            optional=True,
        ),
        # numpy's SeedSequence state for the runs' random streams (``engine/rng.py``)
        Extension("amsa_phys.engine._seeds", ["amsa_phys/engine/_seeds.c"], optional=True),
        # a group's random streams refilled in one call (``engine/rng.py``)
        *_numpy_random(),
    ]
)
