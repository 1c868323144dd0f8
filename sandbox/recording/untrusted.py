"""Reading a file that may be crafted: a regular file only, inflated in bounded chunks.

Recordings are files students exchange, so they are read as untrusted: :func:`open_regular`
opens regular files only (never blocks on a FIFO, never reads a device) under
:data:`~sandbox.recording.limits.MAX_FILE_BYTES`, and :class:`GzipLines` inflates them in
bounded chunks under the text and line caps of :mod:`sandbox.recording.limits`, naming the
problem and the fix in one :class:`~sandbox.recording.format.BadRecording` line.
"""

from __future__ import annotations

import os
import stat
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from sandbox.recording import limits
from sandbox.recording.format import FIX, BadRecording

_CHUNK = 1 << 16


def open_regular(path: Path) -> BinaryIO:
    """Open a regular file for reading (never blocks on a FIFO, never reads a device)."""
    if path.is_dir():
        raise BadRecording(f"{str(path)!r} is a directory; give a recording file (.sbx)")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise BadRecording(
            f"cannot read recording {str(path)!r} ({exc.strerror or exc}); check the path"
        ) from None
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise BadRecording(f"{str(path)!r} is a directory; give a recording file (.sbx)")
        if not stat.S_ISREG(info.st_mode):
            raise BadRecording(
                f"{str(path)!r} is not a regular file (a device, pipe or socket); give a "
                "recording file (.sbx) written by 'sandbox run --record' or the web app"
            )
        if info.st_size > limits.MAX_FILE_BYTES:
            raise BadRecording(
                f"recording {str(path)!r} is {info.st_size / 2**20:.0f} MiB, more than the "
                f"{limits.MAX_FILE_BYTES // 2**20} MiB a recording may take; "
                "record shorter sessions"
            )
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


class GzipLines:
    """Complete lines of a gzip stream (numbered from 1), read and inflated in bounded
    chunks. After iterating, :attr:`ended` tells whether the stream ended properly and
    its last line was complete (a partial last line is never yielded)."""

    def __init__(self, path: Path, fh: BinaryIO) -> None:
        self.path = path
        self.fh = fh
        self.ended = False

    def _refuse(self, problem: str, fix: str = FIX) -> BadRecording:
        return BadRecording(f"recording {str(self.path)!r} {problem}; {fix}")

    def __iter__(self) -> Iterator[tuple[int, bytes]]:
        path, fh = self.path, self.fh
        head = fh.read(2)
        if head != b"\x1f\x8b":
            rest = (head + fh.read(38)).decode("utf-8", "replace").strip().splitlines()
            raise BadRecording(
                f"{str(path)!r} is not a sandbox recording (it starts with "
                f"{(rest[0] if rest else '')[:30]!r}, not a gzip stream); give a file written "
                "by 'sandbox run --record' or the web app's record button"
            )
        dec = zlib.decompressobj(wbits=31)
        pending: list[bytes] = []
        size = 0  # bytes in pending
        total = number = 0
        data = head
        while not dec.eof:
            if not data:
                data = fh.read(_CHUNK)
                if not data:
                    return  # the stream stops short: truncated
            try:
                out = dec.decompress(data, _CHUNK)  # at most _CHUNK bytes out at a time
            except zlib.error as exc:
                raise self._refuse(f"is corrupted ({exc})") from None
            data = dec.unconsumed_tail
            total += len(out)
            if total > limits.MAX_TEXT_BYTES:
                raise self._refuse(
                    f"expands to more than {limits.MAX_TEXT_BYTES // 2**20} MiB "
                    "(a compression bomb, or not a recording)",
                    "give a file written by 'sandbox run --record' or the web app",
                )
            parts = out.split(b"\n")
            pending.append(parts.pop())  # the start of a line yet to end
            size += len(pending[-1])
            if parts:  # pieces of a long line are joined once, when it ends
                parts[0] = b"".join([*pending[:-1], parts[0]])
                size = len(pending[-1])
                del pending[:-1]
            for line in parts:
                number += 1
                if len(line) > limits.MAX_LINE_BYTES:
                    raise self._too_long(number)
                yield number, line
            if size > limits.MAX_LINE_BYTES:
                raise self._too_long(number + 1)
        if dec.unused_data or data or fh.read(1):
            raise self._refuse("has data after the end of its gzip stream (trailing garbage)")
        self.ended = size == 0

    def _too_long(self, number: int) -> BadRecording:
        what = "its first line" if number == 1 else f"its line {number}"
        return self._refuse(
            f"is not usable: {what} is longer than {limits.MAX_LINE_BYTES // 2**20} MiB (a "
            "compression bomb, or not a recording)",
            "give a file written by 'sandbox run --record' or the web app",
        )
