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
from ..source import RecordingSource
from .base import (Clock, FileFormat, bisect_seconds, build_events, check_reader_window, check_time_spread,
                   existing, plain_attr, probe_sorted, size_value)

__all__ = ["read_dsec", "DsecSource", "FORMAT"]

EVENT_NAMES = ("events/x", "events/y", "events/t", "events/p")
H5_ERRORS = (OSError, KeyError, RuntimeError, TypeError, ValueError, IndexError)
FILTERS = {32001: "Blosc", 32004: "LZ4", 32008: "bitshuffle", 32015: "Zstandard", 32026: "Blosc2"}
SIZE_FIX = "pass sensor_size=(H, W) (rows, columns; DSEC's event cameras: (480, 640))"


def _open_file(path):
    import h5py

    try:
        import hdf5plugin  # noqa: F401  (registers the Blosc / zstd / LZ4 filters DSEC's files are written with)
    except ImportError:   # a missing filter is then named, with the fix, by _check_filters
        pass
    try:
        return h5py.File(path, "r")
    except OSError as err:
        raise _damaged(path, err) from None


def _damaged(path, err) -> EventDataError:
    return EventDataError(f"{path}: the HDF5 file is damaged or incomplete ({type(err).__name__}: {err}); copy or "
                          "download it again")


def _check_filters(f, path) -> None:
    """Refuse, with the fix, a dataset compressed by a filter this h5py cannot decode."""
    import h5py

    for name in EVENT_NAMES:
        plist = f[name].id.get_create_plist()
        for i in range(plist.get_nfilters()):
            fid = plist.get_filter(i)[0]
            if not h5py.h5z.filter_avail(fid):
                raise EventDataError(f"{path}: {name} is compressed with HDF5 filter {fid} "
                                     f"({FILTERS.get(fid, 'a plugin filter')}), which this Python cannot decode; "
                                     "install hdf5plugin (`pip install hdf5plugin`, in environment.txt), which "
                                     "registers it, and run again")


def is_dsec_file(f) -> bool:
    """The open HDF5 file has DSEC's events/x, events/y, events/t and events/p datasets."""
    import h5py

    return all(name in f and isinstance(f[name], h5py.Dataset) for name in EVENT_NAMES)


class _Layout:
    """The checked layout of an open DSEC file: event count, clock, sensor size."""

    def __init__(self, f, path, sensor_size):
        self.f, self.path = f, path
        if not is_dsec_file(f):
            raise EventDataError(f"{path}: expected DSEC's datasets {list(EVENT_NAMES)}")
        t = self.t = f["events/t"]
        n = self.n = t.shape[0] if t.ndim == 1 else -1
        if any(f[name].shape != (n,) for name in EVENT_NAMES):
            raise EventDataError(f"{path}: {list(EVENT_NAMES)} must be 1-D with the same length, got "
                                 f"{[f[name].shape for name in EVENT_NAMES]}")
        for name in EVENT_NAMES:
            if f[name].dtype.kind not in "iub":
                raise EventDataError(f"{path}: {name} must hold integers (t in microseconds), got dtype {f[name].dtype}")
        _check_filters(f, path)
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

    def span(self) -> tuple[float, float]:
        if not self.n:
            return 0.0, 0.0
        return float(self.clock.seconds(self.t[0])), float(self.clock.seconds(self.t[self.n - 1]))

    def window(self, t_start, t_end) -> tuple[int, int]:
        lo = 0 if t_start is None else bisect_seconds(self.t, self.clock, t_start, 0, self.n, self.path)
        hi = self.n if t_end is None else bisect_seconds(self.t, self.clock, t_end, lo, self.n, self.path)
        return lo, hi

    def events(self, lo: int, hi: int, polarity: str = "auto") -> Events:
        t = self.clock.seconds(self.t[lo:hi])
        check_time_span(t, f"{self.path}: events/t", "us")
        x, y, p = (self.f[name][lo:hi] for name in ("events/x", "events/y", "events/p"))
        return build_events(self.path, t, x, y, p, self.sensor_size, polarity=polarity, t_origin=self.origin)

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
    path = existing(path)
    check_reader_window(t_start, t_end)
    f = _open_file(path)
    try:
        with f:
            layout = _Layout(f, path, sensor_size)
            if t_start is not None or t_end is not None:
                probe_sorted(layout.t, path)
            lo, hi = layout.window(t_start, t_end)
            if hi <= lo:
                first, last = layout.span()
                span = f"[{first:.6f}, {last:.6f}] s" if layout.n else "nothing"
                raise EventDataError(f"{path}: no events in the window [{t_start}, {t_end}) s; the events cover "
                                     f"{span} (relative to t_origin = {layout.origin}); choose a window inside that range")
            events = layout.events(lo, hi, polarity)
            meta = {**layout.meta(), "event_slice": (lo, hi)}
    except EventDataError:
        raise
    except H5_ERRORS as err:
        raise _damaged(path, err) from None
    return Recording(events, None, meta)


class DsecSource(RecordingSource):
    """Windows of a DSEC file: each found by bisection on events/t, only its slice read. Holds the file open."""

    def __init__(self, path, *, sensor_size=None, polarity="auto"):
        path = existing(path)
        self._f = _open_file(path)
        try:
            self._layout = layout = _Layout(self._f, path, sensor_size)
            probe_sorted(layout.t, path)
            self.meta = layout.meta()
            self.t_span = layout.span()
        except EventDataError:
            self.close()
            raise
        except H5_ERRORS as err:
            self.close()
            raise _damaged(path, err) from None
        self.path, self.format, self.frames, self._polarity = path, "dsec", None, polarity
        self.sensor_size, self.t_origin, self.n_events = layout.sensor_size, layout.origin, layout.n

    def _read_window(self, t0: float, t1: float) -> Events:
        try:
            lo, hi = self._layout.window(t0, t1)
            return (self._layout.events(lo, hi, self._polarity) if hi > lo
                    else Events.empty(self.sensor_size, self.t_origin))
        except EventDataError:
            raise
        except H5_ERRORS as err:
            raise _damaged(self.path, err) from None

    def close(self) -> None:
        f, self._f = getattr(self, "_f", None), None
        if f is not None:
            f.close()


def _sniff(path, head) -> bool:
    """An HDF5 file with DSEC's events/x, events/y, events/t and events/p datasets."""
    if head is None or not head.startswith(b"\x89HDF\r\n\x1a\n"):
        return False
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return is_dsec_file(f)
    except H5_ERRORS:
        return False


FORMAT = FileFormat(
    name="dsec", description="a DSEC-style .h5 (events/x, y, t in microseconds since t_offset, p)", reader=read_dsec,
    suffixes=(".h5", ".hdf5"), sniff=_sniff, needs_sensor_size=True, takes_sensor_size=True, time_unit="us",
    windowed=True, open_source=DsecSource, options=("polarity",), priority=15)
