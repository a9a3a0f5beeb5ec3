"""An MCAP file with ROS 2 encodings (profile ``ros2``, schemas ``ros2msg``, messages CDR).

Streaming: the ``mcap`` writer holds one chunk (1 MiB, zstd) and the summary's indexes
(a few dozen bytes per chunk and channel), so a 1-hour run never holds its bag in memory.
The file is written under ``NAME.tmp`` (``amsa_phys.atomic``) and renamed by
:meth:`BagWriter.close` once MCAP's summary and footer are written: a bag under its final
name is always complete and indexed, whatever ended the run.

Messages are CDR-encoded by :mod:`.cdr` from each type's definition text
(:mod:`amsa_phys.stdmsgs.defs`), which the file also carries as its schema; the stamped
scalars, one per traced Data buffer per trace row (the bulk of a bag), are packed directly
(:func:`scalar_cdr`, ~1 µs a message). Tests check both against ``mcap-ros2-support``'s
encoder byte for byte.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter

from ..atomic import AtomicFile
from ..stdmsgs.defs import msgdef, schema_name
from .cdr import CDR_LE, encoder

_STAMP = struct.Struct("<iII")
DOUBLE = struct.Struct("<d")
_NS = 1_000_000_000


class _Stream:
    """The file-like object the MCAP writer needs over an :class:`AtomicFile` (it asks
    ``tell`` for its indexes)."""

    def __init__(self, out: AtomicFile) -> None:
        self._out = out
        self._pos = 0

    def write(self, data: bytes) -> int:
        self._out.write(bytes(data))
        self._pos += len(data)
        return len(data)

    def tell(self) -> int:
        return self._pos

    def flush(self) -> None:
        """Nothing: :meth:`AtomicFile.commit` flushes and fsyncs."""


def split_ns(ns: int) -> tuple[int, int]:
    """A ``builtin_interfaces/Time`` (sec, nanosec) from nanoseconds."""
    return ns // _NS, ns % _NS


def scalar_prefix(ns: int) -> bytes:
    """The CDR of an ``amsa_msgs/msg/Scalar`` up to its ``data``: header stamped ``ns``, an
    empty ``frame_id`` (length 1: its NUL), padding to the double's 8-byte alignment."""
    sec, nsec = split_ns(ns)
    return CDR_LE + _STAMP.pack(sec, nsec, 1) + b"\x00\x00\x00\x00"


def scalar_cdr(ns: int, value: float) -> bytes:
    """The CDR of an ``amsa_msgs/msg/Scalar`` stamped ``ns`` holding ``value``."""
    return scalar_prefix(ns) + DOUBLE.pack(value)


class BagWriter:
    """Channels of ROS 2 messages into one MCAP file, finished and renamed by :meth:`close`."""

    def __init__(self, path: str | Path, metadata: dict[str, str] | None = None) -> None:
        self.path = Path(path)
        self._file = AtomicFile(self.path)
        self._mcap = McapWriter(
            _Stream(self._file), chunk_size=1024 * 1024, compression=CompressionType.ZSTD
        )
        self._mcap.start(profile="ros2", library="amsa-phys")
        self._schemas: dict[str, int] = {}
        self._encoders: dict[str, Callable[[Any], bytes]] = {}
        self._channels: dict[str, tuple[int, str]] = {}  # topic -> (channel id, type)
        self._closed = False
        self.messages = 0
        if metadata:
            self._mcap.add_metadata("amsa-phys", metadata)

    def channel(self, topic: str, msg_type: str) -> int:
        """The channel of ``topic`` carrying ``msg_type`` (``pkg/Type``), created once."""
        known = self._channels.get(topic)
        if known is not None:
            return known[0]
        sid = self._schemas.get(msg_type)
        if sid is None:
            text = msgdef(msg_type)
            sid = self._mcap.register_schema(schema_name(msg_type), "ros2msg", text.encode())
            self._schemas[msg_type] = sid
            self._encoders[msg_type] = encoder(msg_type)
        cid = self._mcap.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)
        self._channels[topic] = (cid, msg_type)
        return cid

    def write(self, topic: str, msg_type: str, message: dict[str, Any], ns: int) -> None:
        """Encode and append ``message`` on ``topic``, logged (and published) at ``ns``."""
        cid = self.channel(topic, msg_type)
        self.write_raw(cid, self._encoders[msg_type](message), ns)

    def write_raw(self, channel_id: int, data: bytes, ns: int) -> None:
        """Append an already encoded message."""
        self._mcap.add_message(channel_id=channel_id, log_time=ns, publish_time=ns, data=data)
        self.messages += 1

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` (or :meth:`discard`) was called."""
        return self._closed

    def close(self) -> Path | None:
        """Write MCAP's summary and footer, then give the file its final name (safe twice).

        None if a write failed (the partial file is removed, never left under its name).
        """
        if not self._closed:
            self._closed = True
            if not self._file.failed:
                self._mcap.finish()
                self._file.commit()
        return None if self._file.failed else self.path

    def discard(self) -> None:
        """Drop the bag (its temporary file)."""
        self._closed = True
        self._file.discard()
