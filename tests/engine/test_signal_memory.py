"""The samples an STL requirement reads: the values of every logged instant, in a memory
that grows by the samples' own doubles (a 1-hour run's peak memory used to grow with a
numpy array object per logged instant)."""

from __future__ import annotations

import tracemalloc

import numpy as np

from amsa_phys.engine.signals import SignalSampler
from amsa_phys.engine.store import BufferStore


def store(runs: int) -> BufferStore:
    return BufferStore({"A.x": 0.0, "B.y": 0.0, "C.z": 0.0}, {}, runs=runs)


def test_every_run_and_signal_at_every_instant() -> None:
    st = store(2)
    sampler = SignalSampler(["C.z", "A.x"], 2, st.at)
    sample = sampler.listener(st.col)
    for k in range(5):
        for run in range(2):
            st.data[st.at("A.x", run)] = 10.0 * k + run
            st.data[st.at("C.z", run)] = -(10.0 * k + run) - 0.5
        sample(0.25 * k, None)
    t, cols = sampler.table()
    assert t.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert cols["A.x"].tolist() == [[10.0 * k, 10.0 * k + 1] for k in range(5)]
    assert cols["C.z"].tolist() == [[-10.0 * k - 0.5, -10.0 * k - 1.5] for k in range(5)]
    sample(1.25, None)  # still sampling after a table was taken (no buffer pinned)
    assert sampler.table()[0].tolist()[-1] == 1.25


def test_no_signals_still_counts_the_instants() -> None:
    st = store(1)
    sampler = SignalSampler([], 1, st.at)
    sample = sampler.listener(st.col)
    for k in range(3):
        sample(float(k), None)
    t, cols = sampler.table()
    assert t.tolist() == [0.0, 1.0, 2.0]
    assert cols == {}


def test_memory_grows_by_the_samples_doubles_only() -> None:
    st = store(1)
    sampler = SignalSampler(["A.x", "B.y"], 1, st.at)
    sample = sampler.listener(st.col)
    sample(0.0, None)
    n = 20_000
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for k in range(n):
            sample(k * 0.05, None)
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    # three doubles an instant (t and two signals), with the arrays' over-allocation: an
    # object per instant (a numpy array: ~100 bytes more) would be far above
    assert grown < n * 3 * 8 * 1.5 + 4096, grown
    t, cols = sampler.table()
    assert len(t) == n + 1
    assert np.all(cols["A.x"] == 0.0)
