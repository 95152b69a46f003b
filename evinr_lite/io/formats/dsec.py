"""A DSEC-style HDF5 event file (DSEC's events.h5, and the files its tools write).

Layout: events/x, events/y (integers), events/t (integer microseconds since ``t_offset``, sorted),
events/p (0/1); optional scalar ``t_offset`` (microseconds, added to every t: the recording's clock)
and ``ms_to_idx`` (not needed: a window is found by bisection on events/t on disk, and only its
slice is read). DSEC compresses the events with Blosc / zstd, which h5py decodes once
``hdf5plugin`` (a dependency) has registered those filters. The file does not record the sensor
size: pass it (DSEC's event cameras are 480 x 640, (H, W) = (480, 640)).
"""
from __future__ import annotations

import numpy as np

from ...core.events import EventDataError, Events, check_time_span
from ...core.recording import Recording
from .base import Clock, FileFormat, build_events, check_time_spread, plain_attr, size_value
from .h5window import FILTERS, H5Source, TimeIndexed, check_filters, column_count, read_window, sniff_h5  # noqa: F401
# (FILTERS names DSEC's compressions, Blosc and zstd, beside the reader that meets them)

__all__ = ["read_dsec", "DsecSource", "FORMAT"]

EVENT_NAMES = ("events/x", "events/y", "events/t", "events/p")
SIZE_FIX = "pass sensor_size=(H, W) (rows, columns; DSEC's event cameras: (480, 640))"


def is_dsec_file(f) -> bool:
    """The open HDF5 file has DSEC's events/x, events/y, events/t and events/p datasets."""
    import h5py

    return all(name in f and isinstance(f[name], h5py.Dataset) for name in EVENT_NAMES)


class _Layout(TimeIndexed):
    """The checked layout of an open DSEC file: event count, clock, sensor size."""

    def __init__(self, f, path, sensor_size, polarity="auto"):
        self.f, self.path, self.polarity = f, path, polarity
        if not is_dsec_file(f):
            raise EventDataError(f"{path}: expected DSEC's datasets {list(EVENT_NAMES)}")
        t = self.t = f["events/t"]
        n = self.n = column_count(f, path, ("events/t", "events/x", "events/y", "events/p"), "iub",
                                  "integers (t in microseconds)")
        check_filters(f, path, EVENT_NAMES)
        self.offset = 0
        if "t_offset" in f:
            value = np.asarray(f["t_offset"][()])
            if value.shape != () or value.dtype.kind not in "iu":
                raise EventDataError(f"{path}: t_offset must be one integer (microseconds), got {value.dtype} "
                                     f"of shape {value.shape}")
            self.offset = int(value)
        if sensor_size is None:
            hint = ""
            if n > 0:
                hint = (f"; the first events span x 0..{int(np.max(f['events/x'][:min(n, 100_000)]))} and y "
                        f"0..{int(np.max(f['events/y'][:min(n, 100_000)]))}")
            raise EventDataError(f"{path}: a DSEC file does not record the sensor size; {SIZE_FIX}{hint}")
        self.sensor_size = size_value(path, sensor_size, "sensor_size")
        # file values are microseconds since t_offset: the clock's origin is taken on offset + t
        self.clock = Clock(int(t[0]) + self.offset if n else 0, "us", True)
        self.clock.origin_units -= self.offset
        self.origin = self.clock.origin
        if n >= 2:
            check_time_spread(*self.span(), n, f"{path}: events/t")

    def events(self, lo: int, hi: int) -> Events:
        t = self.clock.seconds(self.t[lo:hi])
        check_time_span(t, f"{self.path}: events/t", "us")
        x, y, p = (self.f[name][lo:hi] for name in ("events/x", "events/y", "events/p"))
        return build_events(self.path, t, x, y, p, self.sensor_size, polarity=self.polarity, t_origin=self.origin)

    def frames(self, t_start=None, t_end=None, meta=None) -> None:
        return None   # DSEC keeps its frame camera's images in other files

    def meta(self) -> dict:
        return {"format": "dsec", "path": str(self.path), "t_offset_us": self.offset,
                "attrs": {k: plain_attr(v) for k, v in self.f.attrs.items()}}


def read_dsec(path, sensor_size=None, *, t_start=None, t_end=None, polarity="auto") -> Recording:
    """A DSEC-style events.h5, optionally only the time window [t_start, t_end).

    Args:
        sensor_size: (H, W), required (the file does not record it; DSEC: (480, 640)).
        t_start, t_end: seconds on the returned clock (t_offset + t, minus ``t_origin``). The window is
            found by bisection on events/t on disk and only that slice is read.
        polarity: encoding of events/p ('auto', '01', 'pm1').
    Raises:
        EventDataError for a missing, damaged or compressed-but-undecodable file, missing datasets,
        a missing sensor size, an empty window.
    """
    return read_window(path, lambda f, p: _Layout(f, p, sensor_size, polarity), t_start, t_end)


class DsecSource(H5Source):
    """Windows of a DSEC file: each found by bisection on events/t, only its slice read. Holds the file open."""

    def __init__(self, path, *, sensor_size=None, polarity="auto"):
        super().__init__(path, lambda f, p: _Layout(f, p, sensor_size, polarity), "dsec")


def _sniff(path, head) -> bool:
    """An HDF5 file with DSEC's events/x, events/y, events/t and events/p datasets."""
    return sniff_h5(path, head, is_dsec_file)


FORMAT = FileFormat(
    name="dsec", description="a DSEC-style .h5 (events/x, y, t in microseconds since t_offset, p)", reader=read_dsec,
    suffixes=(".h5", ".hdf5"), sniff=_sniff, needs_sensor_size=True, takes_sensor_size=True, time_unit="us",
    windowed=True, open_source=DsecSource, options=("polarity",), priority=15)
