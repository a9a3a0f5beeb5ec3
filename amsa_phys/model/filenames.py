"""How long a name may be where it becomes a file name.

An export names files after the model: a Leaf's path names its node's script
(``Team__Leader.py``), a world's name its package directory and its AMSA files
(``NAME.amsacore``), a scenario's name its launch file. A file name is at most 255 bytes on
the common file systems (ext4, XFS, APFS, NTFS; 143 under an encrypted home), and the
export adds its own prefixes and suffixes (``_params.yaml``, ``.launch.py``): a name is
refused, in one line, past :data:`MAX_FILE_NAME` characters, well inside all of them,
instead of failing half-way with the file system's "File name too long".
"""

from __future__ import annotations

#: Longest name (in characters; the names checked are ASCII) that may name a file.
MAX_FILE_NAME = 100


def shown(name: str, width: int = 24) -> str:
    """``name`` cut for a message: a 300-character name would drown the line."""
    return name if len(name) <= width else name[:width] + "…"


def file_name_problem(name: str, what: str) -> str | None:
    """Why ``name`` (``what`` it is, for the message) cannot name a file, or None."""
    size = len(name.encode("utf-8"))
    if size <= MAX_FILE_NAME:
        return None
    return (
        f"{what} {shown(name)!r} is {size} characters long: it names a file of the export, "
        f"at most {MAX_FILE_NAME} characters"
    )
