"""Saving a figure atomically (rendered in memory, then written under its final name)."""

from __future__ import annotations

import io
import os
import stat
import struct
import sys
import warnings
import zlib
from pathlib import Path
from typing import BinaryIO

from matplotlib.figure import Figure
from matplotlib.text import Text

from ..atomic import write_atomic

#: zlib level of the PNGs: 1 encodes a run's two plots in ~2/3 of the time of the default 6
#: (~25 ms less CPU in the plot child) for files 10-18 % larger (~45 KB); same pixels.
PNG_LEVEL = 1


def save_png(
    fig: Figure,
    out: Path,
    margins: tuple[float, float, float, float] | None = None,
    metadata: dict[str, str] | None = None,
) -> Path:
    """Render ``fig`` to PNG, write it atomically to ``out`` and close the figure.

    ``margins`` (left, bottom, right, top, in figure fractions) places a single-axes figure
    directly; without it ``tight_layout`` measures every label first, which costs a full
    extra layout pass (~60 ms a figure, a tenth of a headless run's process time). A figure
    made with a layout engine of its own (``layout="constrained"``) keeps it.
    ``metadata``: PNG text chunks (``Title``...), read back by :func:`png_text`.
    A figure made without pyplot (the run's plots: the plot child never imports it) needs no
    closing; one made with it is closed here.
    """
    for text in fig.findobj(Text):  # see _plain
        _plain(text)
    if margins is None:
        if fig.get_layout_engine() is None:
            # a label too wide to fit: matplotlib keeps its default layout and says "Tight
            # layout not applied"; the picture is still written, and the terminal is for
            # amsa-phys's own messages (no library warning reaches it)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fig.tight_layout()
    else:
        left, bottom, right, top = margins
        fig.subplots_adjust(left=left, bottom=bottom, right=right, top=top)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata=metadata, pil_kwargs={"compress_level": PNG_LEVEL})
    if "matplotlib.pyplot" in sys.modules:  # a pyplot figure is kept by pyplot until closed
        sys.modules["matplotlib.pyplot"].close(fig)
    write_atomic(out, buf.getvalue())
    return out


def _plain(text: Text) -> None:
    """Draw ``text`` as written, never as mathtext: titles, legends and labels hold names
    from the user's files (a scenario's or a context's name), and two ``$`` in one were
    parsed as TeX (``$\\frac{x$`` a traceback, the run's plots lost). No amsa-phys figure
    writes mathtext of its own."""
    text.set_parse_math(False)


#: The PNG signature, and the most a reader of a PNG's text takes: chunks before the image
#: data, each text chunk at most 1 MiB (inflated too), 4 MiB of text in all
_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_MAX_CHUNKS = 1000
_MAX_TEXT = 1 << 20
_MAX_TEXT_TOTAL = 4 << 20


def png_text(path: Path) -> dict[str, str]:
    """The text chunks of a PNG before its image data (``{}`` if it is unreadable, not a
    regular file, or has none).

    A summary.png comes with the sweep directory someone hands over, so it is data: read
    without decoding the image (a 20000x20000 "decompression bomb" costs nothing here), opened
    without blocking (a FIFO is not waited on), and never more than a few MiB of it read.
    """
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return {}
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return {}
        with os.fdopen(os.dup(fd), "rb") as fh:
            return _text_chunks(fh)
    except (OSError, ValueError, zlib.error):
        return {}
    finally:
        os.close(fd)


def _text_chunks(fh: BinaryIO) -> dict[str, str]:
    """``tEXt``, ``zTXt`` and ``iTXt`` chunks up to the first ``IDAT`` (where Pillow, which
    writes the plots, puts them); others are skipped over unread."""
    if fh.read(8) != _SIGNATURE:
        return {}
    found: dict[str, str] = {}
    total = 0
    for _ in range(_MAX_CHUNKS):
        head = fh.read(8)
        if len(head) < 8:
            break
        length, kind = struct.unpack(">I4s", head)
        if kind in (b"IDAT", b"IEND"):
            break
        if kind not in (b"tEXt", b"zTXt", b"iTXt") or length > _MAX_TEXT:
            fh.seek(length + 4, os.SEEK_CUR)  # the data and its CRC, unread
            continue
        total += length
        if total > _MAX_TEXT_TOTAL:
            break
        data = fh.read(length)
        fh.seek(4, os.SEEK_CUR)
        if len(data) < length:
            break
        item = _text_item(kind, data)
        if item is not None:
            found[item[0]] = item[1]
    return found


def _text_item(kind: bytes, data: bytes) -> tuple[str, str] | None:
    """One text chunk's (keyword, text); None if it is malformed."""
    key, sep, rest = data.partition(b"\0")
    if not sep:
        return None
    if kind == b"tEXt":
        return key.decode("latin-1"), rest.decode("latin-1")
    if kind == b"zTXt":
        return key.decode("latin-1"), _inflate(rest[1:]).decode("latin-1")
    compressed, method, rest = rest[0:1], rest[1:2], rest[2:]
    if not method:
        return None
    _language, _, rest = rest.partition(b"\0")
    _translated, _, text = rest.partition(b"\0")
    raw = _inflate(text) if compressed == b"\1" else text
    return key.decode("latin-1"), raw.decode("utf-8", "replace")


def _inflate(data: bytes) -> bytes:
    """zlib data inflated to at most :data:`_MAX_TEXT` bytes (a bomb of text is cut there)."""
    return zlib.decompressobj().decompress(data, _MAX_TEXT)
