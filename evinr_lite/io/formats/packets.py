"""A :class:`~evinr_lite.io.source.RecordingSource` over a packet format (AEDAT4, Prophesee .raw / .dat).

These files have no time index a reader could seek with, so a window is found by decoding packets
in order: packets before the window are skipped (decoded, not converted), packets inside it are
kept, and decoding stops at the first packet that starts after it. The decoder stays open between
calls, so windows asked for in time order (streaming) decode the file once in all; the packets
that reach into the last window asked for are kept, so overlapping windows need no second pass.
A window that starts before that reopens the file. Memory holds the packets of about one window.

Opening scans the file once (decoding, keeping only each packet's first and last time and count)
for ``t_span``, ``n_events`` and the frames.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...core.events import EventDataError, Events
from ...core.frames import Frames
from ...core.recording import Recording
from ..source import RecordingSource
from .decoding import US, PacketCollector, decoder_stderr, origin_us_of

__all__ = ["PacketSource", "read_packets", "frames_from"]


def frames_from(path, frame_t: list, images: list, origin_us: int | None, size) -> Frames | None:
    """The APS frames decoded (microsecond stamps) on the events' clock, sorted; None without frames."""
    if not images:
        return None
    if origin_us is None:   # frames but no events: the frames set the clock
        origin_us = origin_us_of(frame_t[0])
    shapes = {im.shape for im in images}
    if shapes != {size}:
        raise EventDataError(f"{path}: frames are {sorted(shapes)} but the events' sensor is {size} (H, W); "
                             "frames with a region of interest are not supported")
    t = (np.array(frame_t, np.int64) - origin_us) / US
    return Frames(np.stack(images), t, float(origin_us // US)).sorted()


def read_packets(path: Path, decoded, *, sensor_size=None, t_start=None, t_end=None, frames_from=None) -> Recording:
    """The Recording of a packet-format file read whole or in the window [t_start, t_end) (seconds relative to
    ``t_origin``): ``decoded`` and ``frames_from`` as for :class:`PacketSource`. Events are kept only inside the
    window and decoding stops after it, so memory holds the window; frames are gathered on the way."""
    collect = PacketCollector(t_start, t_end)
    frame_t, images = [], []
    with decoded(path, sensor_size) as (size, meta, packets):
        for kind, *item in packets:
            if kind == "events":
                if not collect.add(item[0]):
                    break
            else:
                frame_t.append(item[0])
                images.append(item[1])
    events = collect.events(path, size)
    frames = frames_from(path, frame_t, images, collect.origin_us, size) if frames_from else None
    if frames is not None:
        frames = frames.slice_time(t_start, t_end)
        frames = frames if len(frames) else None
    return Recording(events, frames, meta)


class PacketSource(RecordingSource):
    """Windows of a packet-format file, decoded in order.

    Args:
        path: the file.
        decoded: ``decoded(path, sensor_size, **options)``, a context manager that yields
            (sensor size (H, W), meta, packets): packets yields ("events", structured array with
            t [us], x, y, on) and, for formats with frames, ("frame", t_us, grey uint8 image).
        sensor_size: passed to ``decoded`` (supplied or checked there).
        format: the format's name.
        frames_from: ``frames_from(path, frame_t, images, origin_us, size) -> Frames | None``
            (formats with frames).
        options: the decoder's other options (e.g. Prophesee's ``version``).
    """

    def __init__(self, path: Path, decoded, *, sensor_size=None, format: str, frames_from=None, **options):
        self.path = Path(path)
        self.format = format
        self._open = lambda: decoded(self.path, sensor_size, **options)
        self._context = self._packets = None
        first = last = None
        n = 0
        frame_t, images = [], []
        with decoder_stderr():
            with self._open() as (size, meta, packets):
                for kind, *item in packets:
                    if kind == "events":
                        t = item[0]["t"]
                        if len(t):
                            lo, hi = int(t.min()), int(t.max())
                            first = lo if first is None else min(first, lo)
                            last = hi if last is None else max(last, hi)
                            n += len(t)
                    else:
                        frame_t.append(item[0])
                        images.append(item[1])
        self.sensor_size = size
        self.meta = meta
        self.n_events = n
        if first is not None:
            self._origin_us = origin_us_of(first)
        else:
            self._origin_us = origin_us_of(frame_t[0]) if frame_t else 0
        self.t_origin = float(self._origin_us // US)
        self.t_span = ((first - self._origin_us) / US, (last - self._origin_us) / US) if n else (0.0, 0.0)
        self.frames = frames_from(self.path, frame_t, images, self._origin_us, size) if frames_from else None
        self._low = math.inf   # every event at t >= _low is in the buffer or still to be decoded
        self._buffer: list[tuple[np.ndarray, np.ndarray]] = []   # (t seconds, packet), in file order

    def _reopen(self) -> None:
        self.close()
        self._context = self._open()
        _, _, self._packets = self._context.__enter__()
        self._buffer = []
        self._low = -math.inf

    def _next_packet(self):
        """The next events packet with its times in seconds, or None at the end of the file."""
        if self._packets is None:
            return None
        for kind, *item in self._packets:
            if kind == "events" and len(item[0]):
                packet = item[0]
                return (packet["t"].astype(np.int64) - self._origin_us) / US, packet
        self._finish()   # end of file: the buffer stays valid
        return None

    def _read_window(self, t0: float, t1: float) -> Events:
        with decoder_stderr():
            if t0 < self._low:
                self._reopen()
            self._buffer = [(t, p) for t, p in self._buffer if t.max() >= t0]   # packets before the window
            self._low = t0
            while not any(t.min() >= t1 for t, _ in self._buffer):
                item = self._next_packet()
                if item is None:
                    break
                if item[0].max() >= t0:
                    self._buffer.append(item)
        parts = []
        for t, packet in self._buffer:
            keep = (t >= t0) & (t < t1)
            if keep.any():
                parts.append((t[keep], packet["x"][keep], packet["y"][keep], packet["on"][keep]))
        if not parts:
            return Events.empty(self.sensor_size, self.t_origin)
        t, x, y, on = (np.concatenate(c) for c in zip(*parts))
        try:   # packets are sorted in time; a stable sort repairs rare out-of-order packets
            return Events.from_arrays(t, x, y, on, self.sensor_size, polarity="bool", sort=True,
                                      t_origin=self.t_origin)
        except EventDataError as err:
            raise EventDataError(f"{self.path}: {err}") from None

    def close(self) -> None:
        self._finish()
        self._low, self._buffer = math.inf, []

    def _finish(self) -> None:
        context, self._context, self._packets = self._context, None, None
        if context is not None:
            with decoder_stderr():
                context.__exit__(None, None, None)
