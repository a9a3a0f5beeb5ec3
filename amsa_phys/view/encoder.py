"""Streams raw frames into the ffmpeg that ships with imageio-ffmpeg: MP4 (H.264) or GIF.

Why this way (measured, see ../shared/measurements.md):

* **imageio-ffmpeg** for the binary: a maintained wheel that bundles a static ffmpeg with
  libx264, so no system ffmpeg is needed. We start the process ourselves rather than through
  ``imageio_ffmpeg.write_frames`` to control the pipe (1 MiB buffer: faster than the 64 KiB
  default), the pixel format (the surface's own ``bgr0`` bytes, no conversion in Python) and
  the process group.
* **Zero-copy frames**: a frame is the Surface's pixel buffer (``get_view("0")``), written
  straight to the pipe; ffmpeg converts to yuv420p (what browsers play) on the other core.
* **Concurrency**: a writer thread pushes frame *n* into the pipe while the main thread draws
  frame *n + 1* into the other of two surfaces (double buffering), so drawing, the pipe and
  the encoder overlap. ``os.write`` releases the GIL.
* **Interrupts**: ffmpeg runs in its own session, so a terminal's Ctrl-C reaches only
  Python; on any exit we close ffmpeg's input and it finishes a playable file. It writes to
  ``NAME.tmp`` and the file is renamed when ffmpeg exits cleanly, so the final name never
  holds a half-written video. If Python is SIGKILLed, ffmpeg still sees end-of-input and
  leaves a playable ``.tmp``.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import queue
import subprocess
import tempfile
import threading
from pathlib import Path
from typing import Any

from ..atomic import open_exclusive, reason, temp_path
from ..errors import OutputError

FORMATS = (".mp4", ".gif")
PIPE_BYTES = 1 << 20
F_SETPIPE_SZ = getattr(fcntl, "F_SETPIPE_SZ", 1031)


class EncoderError(RuntimeError):
    """ffmpeg refused the input or failed while writing (message holds its last words)."""


def ffmpeg_exe() -> str:
    """The bundled ffmpeg (imported lazily: only recording needs it)."""
    import imageio_ffmpeg

    return imageio_ffmpeg.get_ffmpeg_exe()


def ffmpeg_args(
    path: Path, size: tuple[int, int], fps: int, pix_fmt: str = "bgr0", fmt: str = ".mp4"
) -> list[str]:
    """The ffmpeg command line for raw ``pix_fmt`` frames on stdin to ``path`` as ``fmt``."""
    w, h = size
    args = [
        ffmpeg_exe(),
        "-hide_banner",
        "-loglevel",
        "error",
        "-y",
        "-f",
        "rawvideo",
        "-pix_fmt",
        pix_fmt,
        "-s",
        f"{w}x{h}",
        "-r",
        str(fps),
        "-i",
        "-",
        "-an",
    ]
    if fmt.lower() == ".gif":
        # One palette per frame: streams (a whole-video palette would hold every frame).
        args += [
            "-filter_complex",
            "split[a][b];[a]palettegen=stats_mode=single:reserve_transparent=0[p];"
            "[b][p]paletteuse=new=1:dither=bayer",
            "-loop",
            "0",
            "-f",
            "gif",
        ]
    else:
        args += [
            "-c:v",
            "libx264",
            "-preset",
            "ultrafast",
            "-crf",
            "23",
            "-pix_fmt",
            "yuv420p",
            "-movflags",
            "+faststart",
            "-f",
            "mp4",
        ]
    return [*args, str(path)]


class VideoEncoder:
    """One video being written. ``submit`` frames, then ``close``."""

    def __init__(self, path: Path, size: tuple[int, int], fps: int, pix_fmt: str = "bgr0") -> None:
        if size[0] % 2 or size[1] % 2:
            raise ValueError(f"video size {size[0]}x{size[1]} must be even (yuv420p)")
        self.path = Path(path)
        self.size = size
        #: frames written whole to ffmpeg, counted by the writer thread: Ctrl-C interrupts only
        #: the main thread, possibly between handing a frame over and counting it, so this is
        #: the count that matches the finished file
        self.written = 0
        self.tmp = temp_path(self.path)
        try:  # created here, exclusively: ffmpeg then writes our file, not a planted link
            os.close(open_exclusive(self.tmp))
        except OSError as exc:
            raise OutputError(self.path, reason(exc)) from None
        self._log = tempfile.TemporaryFile()  # noqa: SIM115 (lives as long as ffmpeg)
        self._proc = subprocess.Popen(
            ffmpeg_args(self.tmp, size, fps, pix_fmt, self.path.suffix),
            stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            stderr=self._log,
            start_new_session=True,  # not in the terminal's process group: Ctrl-C is ours
        )
        assert self._proc.stdin is not None
        self._fd = self._proc.stdin.fileno()
        with contextlib.suppress(OSError):  # not Linux, or over the per-user pipe budget
            fcntl.fcntl(self._fd, F_SETPIPE_SZ, PIPE_BYTES)
        self._queue: queue.Queue[Any] = queue.Queue(maxsize=1)
        self._done = threading.Semaphore(0)
        self._error: BaseException | None = None
        self._closing = False
        self._thread = threading.Thread(target=self._writer, name="video-writer", daemon=True)
        self._thread.start()

    def _writer(self) -> None:
        # get() with a timeout, not a plain blocking get: Ctrl-C raises KeyboardInterrupt in
        # the main thread between any two bytecodes, also inside Queue.put and the pure-Python
        # Condition it wakes us with, so a wake-up can be lost. A writer that only waited was
        # seen to sleep through close()'s sentinel (2 hangs in 25 interrupted recordings);
        # polling the queue and the closing flag cannot miss either.
        while True:
            try:
                buf = self._queue.get(timeout=0.1)
            except queue.Empty:
                if self._closing:
                    return
                continue
            if buf is None:
                return
            try:
                if self._error is None:
                    self._write_all(buf)
                    self.written += 1
            except OSError as exc:  # ffmpeg died (disk full, bad argument)
                self._error = exc
            finally:
                # drop every reference first: a Surface stays locked while its buffer is
                # exported, and the main thread draws into it again once we say "written"
                del buf
                self._done.release()

    def _write_all(self, buf: Any) -> None:
        with memoryview(buf) as whole, whole.cast("B") as flat:
            done = 0
            total = len(flat)
            while done < total:
                with flat[done:] as rest:
                    done += os.write(self._fd, rest)

    def submit(self, pixels: Any) -> None:
        """Queue one frame's bytes; they must stay untouched until :meth:`wait_idle` says so.

        Returns as soon as the writer has taken the frame, so the caller can draw the next
        one into another buffer while this one is written.
        """
        if self._error is not None:
            raise EncoderError(self._failure())
        self._queue.put(pixels)

    def wait_written(self) -> None:
        """Block until the oldest submitted frame has been written to the pipe."""
        self._done.acquire()

    def close(self) -> Path:
        """Finish the file (also after Ctrl-C) and move it to its final name."""
        self._closing = True  # the writer finishes what is queued, then stops
        with contextlib.suppress(queue.Full):
            self._queue.put(None, timeout=1.0)
        self._thread.join()
        with contextlib.suppress(OSError):
            self._proc.stdin.close()  # type: ignore[union-attr]
        rc = self._proc.wait()
        if rc != 0 or self._error is not None:
            self.tmp.unlink(missing_ok=True)  # unplayable; on a full disk, space for the rest
            raise EncoderError(self._failure())
        try:
            os.replace(self.tmp, self.path)
        except OSError as exc:
            self.tmp.unlink(missing_ok=True)
            raise OutputError(self.path, reason(exc)) from None
        self._log.close()
        return self.path

    def _failure(self) -> str:
        self._log.seek(0)
        words = self._log.read().decode(errors="replace").strip().splitlines()
        last = words[-1] if words else "no message"
        return f"ffmpeg failed writing {self.path}: {last}"
