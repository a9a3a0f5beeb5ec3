"""``ros/files/amsa_exit.h``: a failed C++ Leaf's exit code reaches its process, without ROS.

The Leaves live in a plugin library that the process loads with ``dlopen`` (pluginlib), so
the code a failing Leaf sets must cross from the library to the executable's ``main``. A
small host program stands for the two kinds of process: ``container`` reads the code as
``amsa_leaves``' main does (``hostReadsExitCode`` first, ``exitCode()`` at the end),
``standalone`` returns 0 as nodelet's main does; the Leaf is a function of a shared library
the host ``dlopen``s locally (``RTLD_LOCAL``, as a plugin). Checked: a failure gives 2 in
both, also when the library is unloaded before ``main`` returns; no failure gives 0; a
variable inherited from a parent process is not taken for this one's. The launches
themselves are ``tests/ros/test_ros_leaf_failure.py``. Skipped where there is no C++
compiler.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

#: compiles C++ with g++: the build tier, not the quick one
pytestmark = pytest.mark.build

HEADER = Path(__file__).resolve().parents[2] / "amsa_phys" / "ros" / "files" / "amsa_exit.h"

PLUGIN = """#include "amsa_exit.h"
extern "C" void leaf_fails() { amsa::setExitCode(2); }
"""

HOST = """#include <dlfcn.h>
#include <cstdio>
#include <cstring>
#include "amsa_exit.h"
// host MODE PLUGIN fail|ok [unload]: MODE container reads the code, standalone returns 0
int main(int argc, char** argv) {
  const bool container = std::strcmp(argv[1], "container") == 0;
  if (container) amsa::hostReadsExitCode();
  void* plugin = dlopen(argv[2], RTLD_NOW | RTLD_LOCAL);
  if (plugin == nullptr) { std::fprintf(stderr, "%s\\n", dlerror()); return 99; }
  if (std::strcmp(argv[3], "fail") == 0)
    reinterpret_cast<void (*)()>(dlsym(plugin, "leaf_fails"))();
  if (argc > 4) dlclose(plugin);
  return container ? amsa::exitCode() : 0;
}
"""


@pytest.fixture(scope="module")
def host(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The host program and the plugin library, compiled from the header."""
    if shutil.which("g++") is None:
        pytest.skip("no C++ compiler (g++)")
    tmp = tmp_path_factory.mktemp("exit")
    (tmp / "plugin.cpp").write_text(PLUGIN)
    (tmp / "host.cpp").write_text(HOST)
    inc = f"-I{HEADER.parent}"
    plugin, exe = tmp / "libleaf.so", tmp / "host"
    flags = ["-std=c++14", "-Wall", "-Wextra", "-Werror"]  # the package's standard
    cc = ["g++", *flags, inc, "-fPIC", "-shared", str(tmp / "plugin.cpp"), "-o", str(plugin)]
    subprocess.run(cc, check=True)
    subprocess.run(["g++", *flags, inc, str(tmp / "host.cpp"), "-o", str(exe), "-ldl"], check=True)
    return exe, plugin


def _exit(host: tuple[Path, Path], *args: str, inherited: str | None = None) -> int:
    exe, plugin = host
    env = {k: v for k, v in os.environ.items() if k != "AMSA_LEAVES_EXIT"}
    if inherited is not None:
        env["AMSA_LEAVES_EXIT"] = inherited
    return subprocess.run([str(exe), args[0], str(plugin), *args[1:]], env=env).returncode


@pytest.mark.parametrize("mode", ["container", "standalone"])
def test_a_failed_leaf_makes_its_process_exit_2(host: tuple[Path, Path], mode: str) -> None:
    assert _exit(host, mode, "fail") == 2
    assert _exit(host, mode, "fail", "unload") == 2  # the plugin unloaded before main ends
    assert _exit(host, mode, "ok") == 0
    assert _exit(host, mode, "ok", "unload") == 0


def test_a_code_inherited_from_a_parent_process_is_not_this_ones(
    host: tuple[Path, Path],
) -> None:
    """A parent's ``AMSA_LEAVES_EXIT`` (another process id) neither fails a process that did
    not fail nor keeps a standalone one from exiting 2."""
    parent = f"{os.getpid()}:2"
    assert _exit(host, "container", "ok", inherited=parent) == 0
    assert _exit(host, "standalone", "ok", inherited=parent) == 0
    assert _exit(host, "standalone", "fail", inherited=f"{os.getpid()}:0") == 2
