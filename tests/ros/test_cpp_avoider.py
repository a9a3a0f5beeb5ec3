"""The C++ ReactiveAvoider (``ros/files/cpp/ReactiveAvoider.inc``) against its template, bitwise.

Lockstep with the C++ node is byte-identical to ``amsa-phys run`` only if the body repeats
the template's numpy and ``math`` arithmetic exactly: ``np.linspace``'s order of operations,
numpy's ``cos``/``sin`` (libm's on the machines tested), ``math.hypot`` (CPython's own,
``amsa_pymath.h``), Python's ``%``, ``min``/``max`` and numpy's ``argmin``/``argmax`` ties. A small
program built from the body (behind a stand-in of ``amsa_leaf_node.h``'s interface: no ROS
needed) steps 2,000 random avoiders, four steps each (the remembered direction carries
over), on scans of 1 to 64 beams with missing returns, equal angles, walls at every
distance, poses near and far from the goal and parameters over their whole ranges, and
compares both wheel powers with the template's. Skipped where there is no C++ compiler.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.control.avoider import ReactiveAvoider

#: compiles C++ with g++: the build tier, not the quick one
pytestmark = pytest.mark.build

FILES = Path(__file__).resolve().parents[2] / "amsa_phys" / "ros" / "files"
PARAMS = [p.name for p in ReactiveAvoider.params]
STEPS = 4
HARNESS = """#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>
#include "amsa_pymath.h"
namespace amsa {  // the part of amsa_leaf_node.h's LeafNode a body sees
class LeafNode {
 public:
  virtual ~LeafNode() = default;
  virtual void doStep(double, const std::vector<double>&, std::vector<double>&,
                      std::vector<bool>&) = 0;
  double p(const std::string& name) const { return values_.at(name); }
  const std::vector<double>& array(std::size_t port) const { return arrays_in_.at(port); }
  std::map<std::string, double> values_;
  std::vector<std::vector<double>> arrays_in_;
};
}  // namespace amsa
class Node : public amsa::LeafNode {
 public:
#include "ReactiveAvoider.inc"
};
static const char* kParams[] = {NAMES};
int main() {
  double head[2];
  while (std::fread(head, sizeof(double), 2, stdin) == 2) {
    Node node;  // a new avoider per case: theta_prev starts at 0
    for (const char* name : kParams) {
      double v;
      if (std::fread(&v, sizeof v, 1, stdin) != 1) return 1;
      node.values_[name] = v;
    }
    const std::size_t n = static_cast<std::size_t>(head[0]);
    for (int s = 0; s < static_cast<int>(head[1]); ++s) {
      std::vector<double> in(4, 0.0), out(2, 0.0);
      std::vector<bool> published(2, false);
      if (std::fread(&in[1], sizeof(double), 3, stdin) != 3) return 1;
      std::vector<double> ranges(n);
      if (std::fread(ranges.data(), sizeof(double), n, stdin) != n) return 1;
      node.arrays_in_.assign(1, ranges);
      node.doStep(0.1 * s, in, out, published);
      std::fwrite(out.data(), sizeof(double), 2, stdout);
    }
  }
}
"""


def _case(rng: np.random.Generator) -> tuple[dict[str, float], int, list[np.ndarray]]:
    """Random parameters within the template's ranges, a beam count and STEPS inputs."""
    params: dict[str, float] = {}
    for p in ReactiveAvoider.params:
        lo, hi = max(p.min, -60.0), min(p.max, 60.0)
        params[p.name] = float(p.default) if rng.random() < 0.3 else float(rng.uniform(lo, hi))
    if rng.random() < 0.3:
        params["angle_min"], params["angle_max"] = -1.5708, 1.5708  # the course's lidar
    if rng.random() < 0.05:
        params["angle_max"] = params["angle_min"]  # a zero step in linspace
    if rng.random() < 0.2:
        params["hold"] = 0.0
    if rng.random() < 0.3:
        params["minPower"] = 0.0
    n = int(rng.choice([1, 2, 3, 5, 31, 31, 31, 64]))
    steps = []
    for _ in range(STEPS):
        far = rng.random() < 0.8
        x, y = rng.uniform(-60, 60, 2) if far else params["goalX"] + rng.normal(0, 1.0, 2)
        heading = rng.uniform(-7, 7)
        ranges = rng.uniform(0.15, 12.0, n)
        ranges[rng.random(n) < 0.1] = 12.0  # no echo: range_max
        ranges[rng.random(n) < 0.05] = 0.0  # no scan yet
        if rng.random() < 0.3:
            ranges[:] = np.round(ranges, 2)  # the course's 1 cm resolution: ties
        if rng.random() < 0.1:
            ranges[:] = 0.0  # before the first scan
        steps.append(np.concatenate([[x, y, heading], ranges]))
    return params, n, steps


def _python(params: dict[str, float], steps: list[np.ndarray]) -> list[float]:
    comp = ReactiveAvoider("Pilot", dict(params))
    comp.initialize(None)
    out: list[float] = []
    for k, s in enumerate(steps):
        inp = {"posX": float(s[0]), "posY": float(s[1]), "heading": float(s[2])}
        inp["ranges"] = np.array(s[3:])
        got = comp.do_step(k, inp)
        out += [float(got["LeftPower"]), float(got["RightPower"])]
    return out


@pytest.mark.skipif(shutil.which("g++") is None, reason="no C++ compiler (g++)")
@pytest.mark.skipif(sys.version_info[:2] != (3, 11), reason="the port is of CPython 3.11's hypot")
def test_cpp_avoider_gives_the_templates_bits(tmp_path: Path) -> None:
    names = ", ".join(f'"{n}"' for n in PARAMS)
    (tmp_path / "harness.cpp").write_text(HARNESS.replace("NAMES", names))
    exe = tmp_path / "harness"
    flags = ["-O2", "-ffp-contract=off", "-fno-fast-math"]  # the package's CMake flags
    includes = [f"-I{FILES}", f"-I{FILES / 'cpp'}"]
    cmd = ["g++", *flags, *includes, str(tmp_path / "harness.cpp"), "-o", str(exe)]
    subprocess.run(cmd, check=True)
    rng = np.random.default_rng(26)
    stream: list[float] = []
    want: list[float] = []
    for _ in range(2000):
        params, n, steps = _case(rng)
        stream += [n, STEPS, *(params[p] for p in PARAMS)]
        for s in steps:
            stream += s.tolist()
        want += _python(params, steps)
    done = subprocess.run(
        [str(exe)], input=np.array(stream).tobytes(), capture_output=True, check=True
    )
    got = np.frombuffer(done.stdout)
    expected = np.array(want)
    assert got.shape == expected.shape
    differ = np.flatnonzero(got.view(np.int64) != expected.view(np.int64))
    assert differ.size == 0, (differ.size, got[differ[:4]], expected[differ[:4]])
    # the cases exercised what they claim: stops at the goal, deadband, turns in place
    assert (expected == 0.0).sum() > 100
    assert math.isfinite(float(np.abs(expected).max()))
