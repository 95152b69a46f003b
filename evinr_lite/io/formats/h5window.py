"""What the HDF5 event readers share (HQF, DSEC, MVSEC): a file opened with the compression filters
registered, one message for a damaged file, a window found by bisection on the time column on disk
(only its slice is read), and the window-by-window source.

A format module gives a *layout*: an object built from the open file that has

- ``t`` (the time column on disk: ``t[i]`` one element, ``t.shape[0]`` its length), ``clock`` (a
  :class:`~evinr_lite.io.formats.base.Clock`), ``n``, ``path``, ``origin``, ``sensor_size``;
- ``events(lo, hi)`` (the Events of rows [lo, hi)), ``frames(t_start, t_end, meta)`` (Frames or None)
  and ``meta()`` (the reading's notes start there).

:class:`TimeIndexed` gives a layout its ``span`` and ``window``; :func:`read_window` and
:class:`H5Source` do the rest.
"""
from __future__ import annotations

from ...core.events import EventDataError, Events
from ...core.recording import Recording
from ..source import RecordingSource
from .base import bisect_seconds, check_reader_window, existing, probe_sorted

__all__ = ["H5_ERRORS", "HDF5_MAGIC", "FILTERS", "open_h5", "damaged", "check_filters", "sniff_h5", "column_count",
           "TimeIndexed", "read_window", "H5Source"]

H5_ERRORS = (OSError, KeyError, RuntimeError, TypeError, ValueError, IndexError)
HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
FILTERS = {32001: "Blosc", 32004: "LZ4", 32008: "bitshuffle", 32015: "Zstandard", 32026: "Blosc2"}   # plugin filters


def check_filters(f, path, names) -> None:
    """Refuse, with the fix, a dataset of ``names`` compressed by a filter this h5py cannot decode (h5py
    would only say it cannot read the data)."""
    import h5py

    for name in names:
        plist = f[name].id.get_create_plist()
        for i in range(plist.get_nfilters()):
            fid = plist.get_filter(i)[0]
            if not h5py.h5z.filter_avail(fid):
                raise EventDataError(f"{path}: {name} is compressed with HDF5 filter {fid} "
                                     f"({FILTERS.get(fid, 'a plugin filter')}), which this Python cannot decode; "
                                     "install hdf5plugin (`pip install hdf5plugin`, in environment.txt), which "
                                     "registers it, and run again")


def sniff_h5(path, head, has_layout) -> bool:
    """An HDF5 file (``head``: its first bytes) for which ``has_layout(open file)`` is true."""
    if head is None or not head.startswith(HDF5_MAGIC):
        return False
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return bool(has_layout(f))
    except H5_ERRORS:
        return False


def column_count(f, path, names, kinds: str, what: str) -> int:
    """The common length of the 1-D datasets ``names`` of the open file ``f``, each of a dtype kind in
    ``kinds`` (numpy's letters; ``what`` says which in the message), or an EventDataError naming them."""
    t = f[names[0]]
    n = t.shape[0] if t.ndim == 1 else -1
    if any(f[name].shape != (n,) for name in names):
        raise EventDataError(f"{path}: {list(names)} must be 1-D with the same length, got "
                             f"{[f[name].shape for name in names]}")
    for name in names:
        if f[name].dtype.kind not in kinds:
            raise EventDataError(f"{path}: {name} must be {what}, got dtype {f[name].dtype}")
    return n


def damaged(path, err) -> EventDataError:
    """The error for an HDF5 file that h5py cannot read as it stands."""
    return EventDataError(f"{path}: the HDF5 file is damaged or incomplete ({type(err).__name__}: {err}); copy or "
                          "convert it again")


def open_h5(path):
    """``h5py.File(path, "r")`` with hdf5plugin's filters registered (Blosc, zstd, LZ4, bitshuffle: DSEC
    compresses its events with them); a file h5py cannot open is refused as damaged."""
    import h5py

    try:
        import hdf5plugin  # noqa: F401  (importing it registers the filters)
    except ImportError:   # a dataset that needs one is then named, with the fix, by its reader
        pass
    try:
        return h5py.File(path, "r")
    except OSError as err:
        raise damaged(path, err) from None


class TimeIndexed:
    """``span`` and ``window`` of a layout whose rows are sorted on the time column ``t``."""

    def span(self) -> tuple[float, float]:
        """(first, last) event time, seconds on the returned clock; (0, 0) without events."""
        if not self.n:
            return 0.0, 0.0
        return float(self.clock.seconds(self.t[0])), float(self.clock.seconds(self.t[self.n - 1]))

    def window(self, t_start, t_end) -> tuple[int, int]:
        """The rows [lo, hi) of the events in [t_start, t_end) (None: open), by bisection on disk."""
        lo = 0 if t_start is None else bisect_seconds(self.t, self.clock, t_start, 0, self.n, self.path)
        hi = self.n if t_end is None else bisect_seconds(self.t, self.clock, t_end, lo, self.n, self.path)
        return lo, hi


def read_window(path, make_layout, t_start=None, t_end=None) -> Recording:
    """The Recording of [t_start, t_end) of the HDF5 file ``path`` (seconds on its returned clock; None:
    open), read through ``make_layout(f, path)``: only the window's rows and frames are read."""
    path = existing(path)
    t_start, t_end = check_reader_window(t_start, t_end)   # 0-d, Fraction, Decimal: floats
    f = open_h5(path)
    try:
        with f:
            layout = make_layout(f, path)
            if t_start is not None or t_end is not None:
                probe_sorted(layout.t, path)
            lo, hi = layout.window(t_start, t_end)
            if hi <= lo:
                first, last = layout.span()
                span = f"[{first:.6f}, {last:.6f}] s" if layout.n else "nothing"
                raise EventDataError(f"{path}: no events in the window [{t_start}, {t_end}) s; the events cover "
                                     f"{span} (relative to t_origin = {layout.origin}); choose a window inside that range")
            events = layout.events(lo, hi)
            meta = {**layout.meta(), "event_slice": (lo, hi)}
            frames = layout.frames(t_start, t_end, meta)
    except EventDataError:
        raise
    except H5_ERRORS as err:
        raise damaged(path, err) from None
    return Recording(events, frames, meta)


class H5Source(RecordingSource):
    """Windows of an HDF5 event file: each found by bisection on the time column, only its rows read.
    Holds the file open. ``make_layout(f, path)`` as for :func:`read_window`; ``format``: the format's name."""

    def __init__(self, path, make_layout, format: str):
        path = existing(path)
        self._f = open_h5(path)
        try:
            self._layout = layout = make_layout(self._f, path)
            probe_sorted(layout.t, path)
            self.meta = layout.meta()
            self.frames = layout.frames(meta=self.meta)
            self.t_span = layout.span()
        except EventDataError:
            self.close()
            raise
        except H5_ERRORS as err:
            self.close()
            raise damaged(path, err) from None
        self.path, self.format = path, format
        self.sensor_size, self.t_origin, self.n_events = layout.sensor_size, layout.origin, layout.n

    def _read_window(self, t0: float, t1: float) -> Events:
        try:
            lo, hi = self._layout.window(t0, t1)
            return self._layout.events(lo, hi) if hi > lo else Events.empty(self.sensor_size, self.t_origin)
        except EventDataError:
            raise
        except H5_ERRORS as err:
            raise damaged(self.path, err) from None

    def close(self) -> None:
        f, self._f = getattr(self, "_f", None), None
        if f is not None:
            f.close()
