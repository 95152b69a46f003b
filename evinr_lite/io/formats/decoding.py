"""What the vendor decoders (faery, a maintained Rust decoder of neuromorphic formats) share: their
failures turned into EventDataError, their stderr caught, and decoded packets (t [us], x, y, on)
gathered into Events inside a time window.

Timestamps in these files are integer microseconds; they become float64 seconds relative to a
whole-second ``t_origin`` in integer arithmetic (exact), as everywhere in the package.
"""
from __future__ import annotations

import os
import sys
from contextlib import contextmanager

import numpy as np

from ...core.events import LARGE_T, EventDataError, Events

__all__ = ["US", "decoder_failed", "decoder_stderr", "PacketCollector", "origin_us_of", "percent_header"]

US = 10**6  # microseconds per second


def percent_header(path, limit: int = 1 << 16) -> tuple[list[str], int]:
    """A Prophesee file's ``% ...`` header: its lines (without the '% ') and the byte after it, where the
    binary data starts. The header ends at a ``% end`` line or at the first line not opened by '%'."""
    lines = []
    with open(path, "rb") as f:
        head = f.read(limit)
    pos = 0
    while pos < len(head) and head[pos:pos + 1] == b"%":
        end = head.find(b"\n", pos)
        if end < 0:
            break
        lines.append(head[pos + 1:end].decode("latin-1").strip())
        pos = end + 1
        if lines[-1].lower() == "end":
            break
    return lines, pos


def origin_us_of(first_us: int) -> int:
    """The whole-second origin (in us) of a clock whose first timestamp is ``first_us``: its whole
    seconds on an absolute clock (>= 1e5 s), else 0."""
    return (first_us // US) * US if first_us >= LARGE_T * US else 0


def decoder_failed(err: BaseException) -> bool:
    """True for what faery's decoders raise on damaged or unsupported input: plain exceptions, and Rust
    panics (pyo3's PanicException derives from BaseException); False for Ctrl-C and exits."""
    return not isinstance(err, (KeyboardInterrupt, SystemExit, GeneratorExit))


@contextmanager
def decoder_stderr():
    """Catch what faery's Rust code prints on the process's stderr (a panic message, before pyo3
    turns the panic into an exception): dropped when the block raises (the clean EventDataError
    says what went wrong), passed on otherwise."""
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):
        yield
        return
    import tempfile

    failed = False
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        except BaseException:
            failed = True
            raise
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            if not failed:
                tmp.seek(0)
                text = tmp.read()
                if text:
                    sys.stderr.write(text.decode("utf-8", "replace"))



# ---- microseconds -> Events, a packet at a time -------------------------------------------

class PacketCollector:
    """Gathers decoded packets (structured arrays with t [us], x, y, on) inside a time window.

    The clock's origin (whole seconds of the first event on an absolute clock, else 0) is fixed
    by the first packet; the window [t_start, t_end) is in seconds relative to it.
    """

    def __init__(self, t_start, t_end):
        if t_start is not None and t_end is not None and t_end <= t_start:
            raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
        self.t_start, self.t_end = t_start, t_end
        self.origin_us: int | None = None
        self.parts: list[tuple] = []
        self.n_seen = 0
        self.span_us = [None, None]

    def seconds(self, t_us: np.ndarray) -> np.ndarray:
        return (t_us.astype(np.int64) - self.origin_us) / US

    def add(self, packet: np.ndarray) -> bool:
        """Keep the packet's events inside the window; False once the window is passed."""
        if len(packet) == 0:
            return True
        t_us = packet["t"]
        if self.origin_us is None:
            self.origin_us = origin_us_of(int(t_us[0]))
        self.span_us[0] = int(t_us[0]) if self.span_us[0] is None else self.span_us[0]
        self.span_us[1] = int(t_us[-1])
        self.n_seen += len(packet)
        t = self.seconds(t_us)
        keep = np.ones(len(t), bool)
        if self.t_start is not None:
            keep &= t >= self.t_start
        if self.t_end is not None:
            keep &= t < self.t_end
        if keep.any():
            self.parts.append((t[keep], packet["x"][keep], packet["y"][keep], packet["on"][keep]))
        return self.t_end is None or t.min() < self.t_end

    def events(self, path, sensor_size) -> Events:
        windowed = self.t_start is not None or self.t_end is not None
        if not self.parts and windowed:
            if self.n_seen:
                lo, hi = self.seconds(np.array(self.span_us))
                span = f"[{lo:.6f}, {hi:.6f}] s (relative to t_origin = {self.origin_us // US})"
            else:
                span = "nothing (the file has no events)"
            raise EventDataError(f"{path}: no events in the window [{self.t_start}, {self.t_end}) s; the events "
                                 f"cover {span}; choose a window inside that range")
        if not self.parts:
            return Events.empty(sensor_size)
        t, x, y, on = (np.concatenate(c) for c in zip(*self.parts))
        try:  # packets are sorted in time; a stable sort repairs rare out-of-order packets
            return Events.from_arrays(t, x, y, on, sensor_size, polarity="bool", sort=True,
                                      t_origin=float(self.origin_us // US))
        except EventDataError as err:
            raise EventDataError(f"{path}: {err}") from None
