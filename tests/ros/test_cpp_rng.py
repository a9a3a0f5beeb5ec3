"""The C++ sensor nodes' random streams (``ros/files/amsa_rng.h``) against numpy, bit for bit.

A C++ GPS or compass is byte-identical to its Python template in lockstep only if it draws
numpy's very numbers: ``component_rng`` (SeedSequence keyed by the path's crc32 -> PCG64),
``spawn``, ``random`` and ``standard_normal`` (numpy's ziggurat with numpy's tables and
libm's ``exp``/``log1p``). A small C++ program built from the header draws, for several
seeds and paths, 2,000,000 normals in all (about 500 of them through the ziggurat's tail,
about 14,000 through its wedges), uniforms, and the streams of spawned children (twice, to
check the spawn counter); the test compares every bit with numpy. Mutation-checked: the
tail's value (``log`` for ``log1p``, a dropped sign) and the spawn counter fail it; a change
that only moves an accept/reject comparison by an ulp (the wedge's ``exp``) flips a draw too
rarely to be seen, which is why the tables are also compared entry by entry with the ones
compiled into the installed numpy. Skipped where there is no C++ compiler.
"""

from __future__ import annotations

import shutil
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest
import ziggurat_tables

from amsa_phys.engine.rng import component_rng

#: compiles C++ with g++: the build tier, not the quick one
pytestmark = pytest.mark.build

FILES = Path(__file__).resolve().parents[2] / "amsa_phys" / "ros" / "files"
HARNESS = r"""#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
#include "amsa_rng.h"
// seed path n: n normals, n/10 uniforms, then spawn(3) and spawn(2): each child n/100 of each
static void out(double v) { std::fwrite(&v, sizeof v, 1, stdout); }
int main(int argc, char** argv) {
  amsa::Generator g = amsa::component_rng(argv[1], argv[2]);
  const long n = std::atol(argv[3]);
  for (long i = 0; i < n; ++i) out(g.standard_normal());
  for (long i = 0; i < n / 10; ++i) out(g.random());
  for (int round : {3, 2}) {
    for (amsa::Generator& c : g.spawn(round)) {
      for (long i = 0; i < n / 100; ++i) out(c.standard_normal());
      for (long i = 0; i < n / 100; ++i) out(c.random());
    }
  }
}
"""
#: (seed, path, normals): a big seed (three 32-bit words), seed 0, non-ASCII path
CASES = [
    (1, "Car3.Gps", 1_000_000),
    (0, "LeaderGPS", 400_000),
    (123456789012345678901, "Team.Compass", 400_000),
    (7, "Capteur_é", 200_000),
]


def _numpy(seed: int, path: str, n: int) -> np.ndarray:
    g = component_rng(seed, path)
    parts = [g.standard_normal(n), g.random(n // 10)]
    for count in (3, 2):
        for child in g.spawn(count):
            parts += [child.standard_normal(n // 100), child.random(n // 100)]
    return np.concatenate(parts)


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if shutil.which("g++") is None:
        pytest.skip("no C++ compiler (g++)")
    tmp = tmp_path_factory.mktemp("rng")
    (tmp / "harness.cpp").write_text(HARNESS)
    flags = ["-O2", "-ffp-contract=off", "-fno-fast-math"]  # the package's CMake flags
    exe = tmp / "harness"
    subprocess.run(
        ["g++", *flags, f"-I{FILES}", str(tmp / "harness.cpp"), "-o", str(exe)], check=True
    )
    return exe


@pytest.mark.parametrize(("seed", "path", "n"), CASES)
def test_cpp_streams_give_numpys_bits(harness: Path, seed: int, path: str, n: int) -> None:
    done = subprocess.run([str(harness), str(seed), path, str(n)], capture_output=True, check=True)
    got = np.frombuffer(done.stdout)
    want = _numpy(seed, path, n)
    assert got.shape == want.shape
    differ = np.flatnonzero(got.view(np.int64) != want.view(np.int64))
    assert differ.size == 0, f"first difference at draw {differ[:1]} of {want.size}"


def test_the_draws_reach_the_ziggurats_tail_and_wedges() -> None:
    """The cases above exercise the rare paths (else they would prove little about them)."""
    t = ziggurat_tables.tables() if ziggurat_tables.archive().exists() else None
    if t is None:
        pytest.skip("the installed numpy ships no libnpyrandom.a")
    raw = component_rng(1, "Car3.Gps").bit_generator.random_raw(1_000_000)
    idx = raw & 0xFF
    rabs = (raw >> 9) & 0x000FFFFFFFFFFFFF
    slow = rabs >= np.array(t["ki_double"], dtype=np.uint64)[idx]
    assert int((slow & (idx == 0)).sum()) > 100  # the tail
    assert int((slow & (idx != 0)).sum()) > 3000  # the wedges


def test_the_header_holds_the_installed_numpys_tables() -> None:
    if not ziggurat_tables.archive().exists():
        pytest.skip("the installed numpy ships no libnpyrandom.a")
    header = (FILES / "amsa_ziggurat.h").read_text()
    # the comment names the numpy version it was read from; the tables must match any numpy
    body = header[header.index("namespace amsa") :]
    want = ziggurat_tables.header(ziggurat_tables.tables())
    assert body == want[want.index("namespace amsa") :]


def test_crc32_key_matches_zlib(harness: Path) -> None:
    """The stream key: a path's crc32 as zlib computes it (checked through the draws above,
    here directly on the numpy side so a wrong key is named as such)."""
    ss = component_rng(5, "A.b").bit_generator.seed_seq
    assert ss.spawn_key == (zlib.crc32(b"A.b"),)
