"""numpy's ziggurat tables for the normal distribution, read from the installed wheel.

numpy's ``Generator.standard_normal`` is a 256-level ziggurat whose tables (``ki_double``,
``wi_double``, ``fi_double`` of ``random/src/distributions/ziggurat_constants.h``) decide
every draw. The headers are not in the wheel, but the wheel ships the compiled
distributions for Cython users (``numpy/random/lib/libnpyrandom.a``), and there the three
tables are data symbols. This module reads them from that archive (``ar`` members, ELF64
symbols and ``.rodata``: no tool beyond Python) so that

- ``python tests/ziggurat_tables.py > amsa_phys/ros/files/amsa_ziggurat.h`` writes the C++
  nodes' copy (``amsa_rng.h`` draws with it), and
- ``tests/ros/test_cpp_rng.py`` checks that copy against the installed numpy, entry by
  entry, bit for bit.

The tables are numpy's (BSD-3-Clause); the copy says so.
"""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import numpy as np

NAMES = ("ki_double", "wi_double", "fi_double")


def archive() -> Path:
    """``libnpyrandom.a`` of the numpy that is imported."""
    return Path(np.__file__).parent / "random" / "lib" / "libnpyrandom.a"


def _members(data: bytes) -> dict[str, bytes]:
    """The members of a System V ``ar`` archive (GNU long names resolved)."""
    if not data.startswith(b"!<arch>\n"):
        raise ValueError("not an ar archive")
    pos, out, longnames = 8, {}, b""
    while pos + 60 <= len(data):
        head = data[pos : pos + 60]
        name = head[:16].decode().rstrip()
        size = int(head[48:58].decode().strip())
        body = data[pos + 60 : pos + 60 + size]
        if name == "//":
            longnames = body
        elif name.startswith("/") and name[1:].isdigit():
            start = int(name[1:])
            out[longnames[start:].split(b"/\n", 1)[0].decode()] = body
        elif name not in ("/", "/SYM64/"):
            out[name.rstrip("/")] = body
        pos += 60 + size + (size & 1)
    return out


def _symbols(obj: bytes) -> dict[str, bytes]:
    """Each named data symbol of an ELF64 little-endian object: its bytes."""
    if obj[:4] != b"\x7fELF" or obj[4] != 2 or obj[5] != 1:
        raise ValueError("not an ELF64 little-endian object")
    (shoff,) = struct.unpack_from("<Q", obj, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", obj, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", obj, shoff + i * shentsize) for i in range(shnum)]
    out = {}
    for sh in sections:
        if sh[1] != 2:  # SHT_SYMTAB
            continue
        strtab = sections[sh[6]]
        for k in range(sh[5] // sh[9]):
            name_off, _info, _other, shndx, value, size = struct.unpack_from(
                "<IBBHQQ", obj, sh[4] + k * sh[9]
            )
            if size == 0 or shndx == 0 or shndx >= shnum:
                continue
            end = obj.index(b"\0", strtab[4] + name_off)
            name = obj[strtab[4] + name_off : end].decode()
            home = sections[shndx]
            if home[1] == 8:  # SHT_NOBITS
                continue
            out[name] = obj[home[4] + value : home[4] + value + size]
    return out


def tables(path: Path | None = None) -> dict[str, tuple[int | float, ...]]:
    """``ki_double`` (integers), ``wi_double`` and ``fi_double`` (floats), 256 entries each."""
    members = _members((path or archive()).read_bytes())
    for body in members.values():
        syms = _symbols(body)
        if all(n in syms for n in NAMES):
            return {
                "ki_double": struct.unpack("<256Q", syms["ki_double"]),
                "wi_double": struct.unpack("<256d", syms["wi_double"]),
                "fi_double": struct.unpack("<256d", syms["fi_double"]),
            }
    raise LookupError("no ziggurat tables in the archive")


def header(t: dict[str, tuple[int | float, ...]]) -> str:
    """``amsa_ziggurat.h``: the tables as C++ literals that read back exactly."""
    lines = [
        "// numpy's ziggurat tables for Generator.standard_normal (numpy's",
        "// random/src/distributions/ziggurat_constants.h, BSD-3-Clause, Copyright (c) 2005-2025",
        f"// NumPy Developers), read from the installed numpy {np.__version__}'s libnpyrandom.a",
        "// by tests/ziggurat_tables.py. Do not edit: tests/ros/test_cpp_rng.py checks every",
        "// entry against the installed numpy.",
        "#pragma once",
        "#include <cstdint>",
        "",
        "namespace amsa {",
        "namespace zig {",
        "",
    ]
    for name, kind in (
        ("ki_double", "std::uint64_t"),
        ("wi_double", "double"),
        ("fi_double", "double"),
    ):
        values = t[name]
        text = [f"0x{v:016X}ULL" if isinstance(v, int) else repr(float(v)) for v in values]
        lines.append(f"static const {kind} {name}[256] = {{")
        for i in range(0, 256, 4):
            lines.append("    " + ", ".join(text[i : i + 4]) + ",")
        lines.append("};")
        lines.append("")
    lines += ["}  // namespace zig", "}  // namespace amsa", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.stdout.write(header(tables()))
