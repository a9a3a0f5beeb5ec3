"""The pure path's switch read once inside ``publish.pinned()`` (a reset's build), at every
call outside it, and per thread."""

from __future__ import annotations

import threading

import pytest

from amsa_phys.engine import publish

BUILT = publish._extension("_kernels") is not None


@pytest.mark.skipif(not BUILT, reason="the compiled extensions are not built")
def test_inside_pinned_the_switch_is_the_one_read_on_entry(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv(publish.PURE_ENV, raising=False)
    with publish.pinned():
        monkeypatch.setenv(publish.PURE_ENV, "1")
        assert publish._extension("_kernels") is not None  # read on entry: compiled
        with publish.pinned():  # nested: the outermost reading holds
            assert publish._extension("_kernels") is not None
        assert publish._extension("_kernels") is not None
    assert publish._extension("_kernels") is None  # outside: read again, pure
    with publish.pinned():
        monkeypatch.setenv(publish.PURE_ENV, "0")
        assert publish._extension("_kernels") is None
    assert publish._extension("_kernels") is not None


@pytest.mark.skipif(not BUILT, reason="the compiled extensions are not built")
def test_another_thread_reads_the_switch_itself(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(publish.PURE_ENV, "1")
    seen: list[object] = []
    with publish.pinned():  # this thread's pin: pure
        monkeypatch.setenv(publish.PURE_ENV, "0")
        worker = threading.Thread(target=lambda: seen.append(publish._extension("_kernels")))
        worker.start()
        worker.join()
        assert publish._extension("_kernels") is None
    assert seen[0] is not None
