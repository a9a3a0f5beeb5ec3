"""The C++ nodes' Python arithmetic (``ros/files/amsa_pymath.h``) against Python, bit for bit.

``math.hypot`` is CPython's own algorithm (not libm's ``hypot``) and ``x % y`` on floats takes
the divisor's sign (not C's ``fmod``); the C++ FollowerController uses both, and lockstep is
byte-identical only if they give Python's very bits. A small C++ program built from the
header computes both on 1,000,000 pairs (random magnitudes over 2**±60, metre-sized values,
and every pair of the edge cases: zeros, subnormals, the largest double, infinities, NaN).
Skipped where there is no C++ compiler.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

#: compiles C++ with g++: the build tier, not the quick one
pytestmark = pytest.mark.build

HEADER = Path(__file__).resolve().parents[2] / "amsa_phys" / "ros" / "files" / "amsa_pymath.h"
HARNESS = """#include <cstdio>
#include "amsa_pymath.h"
int main() {
  double p[2];
  while (std::fread(p, sizeof(double), 2, stdin) == 2) {
    double r[2] = {amsa::py_hypot(p[0], p[1]), amsa::py_mod(p[0], p[1])};
    std::fwrite(r, sizeof(double), 2, stdout);
  }
}
"""
EDGES = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1e-310, 1.7976931348623157e308]
EDGES += [-1.7976931348623157e308, math.inf, -math.inf, math.nan, 1.0, 3.0, 4.0, 1e300, 1e-300]


def _pairs() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(26)
    n = 1_000_000
    a = rng.standard_normal(n) * np.exp2(rng.integers(-60, 60, n))
    b = rng.standard_normal(n) * np.exp2(rng.integers(-60, 60, n))
    a[: n // 4] = rng.uniform(-200, 200, n // 4)  # positions and differences in metres
    b[: n // 4] = rng.uniform(-200, 200, n // 4)
    ea = [x for x in EDGES for _ in EDGES]
    eb = [y for _ in EDGES for y in EDGES]
    return np.concatenate([a, ea]), np.concatenate([b, eb])


def _same(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return (u.view(np.int64) == v.view(np.int64)) | (np.isnan(u) & np.isnan(v))


@pytest.mark.skipif(shutil.which("g++") is None, reason="no C++ compiler (g++)")
@pytest.mark.skipif(sys.version_info[:2] != (3, 11), reason="the port is of CPython 3.11's hypot")
def test_cpp_hypot_and_mod_give_pythons_bits(tmp_path: Path) -> None:
    src = tmp_path / "harness.cpp"
    src.write_text(HARNESS)
    exe = tmp_path / "harness"
    flags = ["-O2", "-ffp-contract=off", "-fno-fast-math"]  # the package's CMake flags
    subprocess.run(["g++", *flags, f"-I{HEADER.parent}", str(src), "-o", str(exe)], check=True)
    a, b = _pairs()
    pairs = np.empty(2 * len(a))
    pairs[0::2], pairs[1::2] = a, b
    done = subprocess.run([str(exe)], input=pairs.tobytes(), capture_output=True, check=True)
    got = np.frombuffer(done.stdout).reshape(-1, 2)
    hyp = np.array([math.hypot(x, y) for x, y in zip(a.tolist(), b.tolist(), strict=True)])
    assert int((~_same(got[:, 0], hyp)).sum()) == 0
    mod = np.array([x % y if y else math.nan for x, y in zip(a.tolist(), b.tolist(), strict=True)])
    defined = ~np.isnan(mod)  # Python raises on x % 0; the C++ body never divides by 0
    assert int((~_same(got[defined, 1], mod[defined])).sum()) == 0


ROUND_HARNESS = """#include <cstdio>
#include "amsa_pymath.h"
int main() {
  double x;
  while (std::fread(&x, sizeof(double), 1, stdin) == 1) {
    double r = amsa::py_round6(x);
    std::fwrite(&r, sizeof(double), 1, stdout);
  }
}
"""


@pytest.mark.skipif(shutil.which("g++") is None, reason="no C++ compiler (g++)")
def test_cpp_round6_gives_pythons_bits(tmp_path: Path) -> None:
    """``round(x, 6)``, which the C++ LeaderMonitor keys its track by, on 1,000,000 values:
    time differences on rational grids (the steps' instants), exact decimal ties such as
    2**-7 (ties to even), tiny negatives (-0.0), huge values and the edge cases."""
    src = tmp_path / "round.cpp"
    src.write_text(ROUND_HARNESS)
    exe = tmp_path / "round"
    flags = ["-O2", "-ffp-contract=off", "-fno-fast-math"]
    subprocess.run(["g++", *flags, f"-I{HEADER.parent}", str(src), "-o", str(exe)], check=True)
    rng = np.random.default_rng(6)
    n = 250_000
    steps = rng.integers(0, 4000, n) / rng.choice([3, 4, 7, 10, 20, 100], n)
    grid = steps - rng.integers(0, 4000, n) / rng.choice([3, 4, 7, 10, 20, 100], n)
    ties = (2 * rng.integers(-(10**6), 10**6, n) + 1) * 2.0 ** -rng.integers(7, 21, n)
    wide = rng.standard_normal(n) * np.exp2(rng.integers(-40, 60, n))
    x = np.concatenate([grid, ties, wide, steps, EDGES, [-1e-9, -4e-7, 5e-7, -5e-7]])
    done = subprocess.run([str(exe)], input=x.tobytes(), capture_output=True, check=True)
    got = np.frombuffer(done.stdout)
    want = np.array([round(v, 6) for v in x.tolist()])
    assert int((~_same(got, want)).sum()) == 0
