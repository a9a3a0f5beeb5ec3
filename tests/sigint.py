"""Children that a test interrupts start with SIGINT at its default action.

A job started in the background (``cmd &`` in a script, ``nohup``, some CI runners) runs
with SIGINT ignored, and its children inherit that: a test's Ctrl-C then reaches a child
that ignores it, and the test waits out its timeout. Every test that sends SIGINT to a
child it starts passes ``preexec_fn=sigint.at_default`` (in the child, before its program
runs), so the suite behaves the same from a terminal and from a background job. A test
that interrupts its own process uses the ``python_sigint`` fixture (registered by
``tests/conftest.py``).
"""

from __future__ import annotations

import signal
from collections.abc import Iterator

import pytest


def at_default() -> None:
    """``preexec_fn``: SIGINT at its default action in the child, whatever the parent's."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture
def python_sigint() -> Iterator[None]:
    """Python's own SIGINT handler for the test (a KeyboardInterrupt on Ctrl-C), as in a
    terminal, whatever the suite was started with; the session's put back afterwards. For
    tests that interrupt their own process."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
