"""The canonical HDF5 file of one converted sequence (written by ``data_fetch``), and its reader.

Every dataset that ``data_fetch`` converts (IJRR, HQF, CED, MVSEC, and AED once its converter
exists) ends up in this one layout, so the rest of the kit has a single real-data format::

    /                      attrs: format = "evinr-lite canonical", format_version = 1,
                           sensor_size = (H, W), t_origin (s, absolute time of t = 0),
                           dataset, sequence, source, source_url, raw_file, C (contrast
                           threshold to use), eval_window (s, on this file's clock; NaN, NaN
                           = whole sequence), eval_window_published (as published, seconds
                           after t_zero), t_zero (s, the zero of the published windows:
                           earliest event or frame), n_events, n_frames, t_first, t_last,
                           converter, meta_json (a JSON object: calibration, notes, ...)
    /events/t              float64 [N], seconds since t_origin, non-decreasing
    /events/x, /events/y   uint16 [N], column and row
    /events/p              int8 [N], polarity -1 / +1
    /events/t_index        float64 [ceil(N / stride)], t[::stride] (attr "stride"): a coarse
                           index so that a time window is found by reading one chunk
    /frames/images         uint8 [F, H, W], ground-truth frames (grey), one chunk per frame
    /frames/t              float64 [F], seconds since t_origin, non-decreasing

Event datasets are chunked and compressed; readers never load more than the requested
window (or one chunk at a time with :func:`iter_canonical_events`), so a sequence of 10^8
events does not need 10^8 x 4 x 8 bytes of memory.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .events import EventDataError, Events
from .frames import Frames

__all__ = [
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "is_canonical",
    "canonical_info",
    "read_canonical",
    "iter_canonical_events",
    "find_time_index",
]

FORMAT_NAME = "evinr-lite canonical"
FORMAT_VERSION = 1
EVENT_FIELDS = ("t", "x", "y", "p")


def is_canonical(path) -> bool:
    """True when ``path`` is an HDF5 file in the canonical layout (any version)."""
    import h5py

    path = Path(path)
    if not path.is_file():
        return False
    try:
        with h5py.File(path, "r") as f:
            return f.attrs.get("format") == FORMAT_NAME
    except OSError:
        return False


def _open(path):
    import h5py

    path = Path(path)
    if not path.exists():
        raise EventDataError(f"no such file: {path}; check the path (data_fetch.get(...) returns it)")
    try:
        f = h5py.File(path, "r")
    except OSError as err:
        raise EventDataError(f"{path}: not a readable HDF5 file ({err}); the file is damaged or incomplete: "
                             "delete it and convert again (python -m data_fetch get/convert ...)") from None
    if f.attrs.get("format") != FORMAT_NAME:
        f.close()
        raise EventDataError(f"{path}: not an evinr-lite canonical file (root attribute format is "
                             f"{f.attrs.get('format')!r}); convert the raw recording with "
                             "`python -m data_fetch convert <raw path>`, or read an HQF-style h5 "
                             "with evinr_lite.readers.read_h5")
    version = int(f.attrs.get("format_version", 0))
    if version > FORMAT_VERSION:
        f.close()
        raise EventDataError(f"{path}: canonical format version {version} is newer than this evinr-lite "
                             f"reads ({FORMAT_VERSION}); update evinr-lite")
    missing = [f"events/{k}" for k in EVENT_FIELDS if f"events/{k}" not in f]
    if missing:
        f.close()
        raise EventDataError(f"{path}: missing datasets {missing}; the file is incomplete: convert it again")
    return f


def _attr(value):
    """h5py attribute -> plain Python value (str, float, int, tuple)."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray):
        return tuple(v.item() for v in value.ravel())
    if isinstance(value, np.generic):
        return value.item()
    return value


def _info_from(f, path) -> dict:
    info = {k: _attr(v) for k, v in f.attrs.items() if k != "meta_json"}
    info["meta"] = json.loads(f.attrs["meta_json"]) if "meta_json" in f.attrs else {}
    info["sensor_size"] = tuple(int(v) for v in f.attrs["sensor_size"])
    for key in ("eval_window", "eval_window_published"):   # NaN, NaN on disk = the whole sequence
        window = info.get(key)
        if window is not None and not all(math.isfinite(v) for v in window):
            window = None
        info[key] = window
    info["path"] = str(path)
    return info


def canonical_info(path) -> dict:
    """The file's attributes as a dict (``meta`` decoded from JSON; ``eval_window`` None = whole)."""
    with _open(path) as f:
        return _info_from(f, path)


def find_time_index(f, value: float, side: str = "left") -> int:
    """First event index i with t[i] >= value (side 'left') or t[i] > value ('right').

    Uses ``events/t_index`` (one float per chunk) and then reads a single chunk of ``events/t``;
    files without the index fall back to a binary search reading one element at a time.
    """
    ts = f["events/t"]
    n = ts.shape[0]
    if "events/t_index" in f:
        index = f["events/t_index"][()]
        stride = int(f["events/t_index"].attrs["stride"])
        k = int(np.searchsorted(index, value, side=side))
        if k == 0:
            return 0
        lo, hi = (k - 1) * stride, min(k * stride, n)
        return lo + int(np.searchsorted(ts[lo:hi], value, side=side))
    lo, hi = 0, n
    while lo < hi:
        mid = (lo + hi) // 2
        t_mid = float(ts[mid])
        if t_mid < value or (side == "right" and t_mid == value):
            lo = mid + 1
        else:
            hi = mid
    return lo


def _window(f, path, t_start, t_end) -> tuple[int, int]:
    n = f["events/t"].shape[0]
    if t_start is not None and t_end is not None and t_end <= t_start:
        raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
    lo = 0 if t_start is None else find_time_index(f, t_start)
    hi = n if t_end is None else find_time_index(f, t_end)
    return lo, max(lo, hi)


def _events(f, lo: int, hi: int, sensor_size, origin: float, source) -> Events:
    t = f["events/t"][lo:hi].astype(np.float64, copy=False)
    x, y, p = (f[f"events/{k}"][lo:hi] for k in "xyp")
    try:
        return Events(t, x, y, p, sensor_size, t_origin=origin, polarity_encoding="pm1")
    except EventDataError as err:
        raise EventDataError(f"{source}: {err}") from None


def read_canonical(path, t_start: float | None = None, t_end: float | None = None, *,
                   frames: bool = True):
    """A canonical sequence file as a :class:`~evinr_lite.readers.Recording`.

    Args:
        path: the ``.h5`` file that ``data_fetch.get`` / ``convert`` wrote.
        t_start, t_end: seconds on the file's clock (``t`` relative to ``t_origin``); only the
            events with ``t_start <= t < t_end`` are read from disk (found through the stored
            time index), and only the frames in that window. None: from the start / to the end.
            ``recording.meta["eval_window"]`` is the sequence's evaluation window on this clock.
        frames: False skips the ground-truth frames.

    Returns:
        Recording(events, frames or None, meta) with meta holding dataset, sequence, source, C,
        eval_window (None = whole sequence), t_zero, event_slice (lo, hi) and the stored meta.
    """
    from .readers import Recording

    with _open(path) as f:
        info = _info_from(f, path)
        sensor_size, origin = info["sensor_size"], float(info["t_origin"])
        lo, hi = _window(f, path, t_start, t_end)
        if hi <= lo and (t_start is not None or t_end is not None):
            first, last = info.get("t_first"), info.get("t_last")
            span = f"[{first:.6f}, {last:.6f}] s" if info.get("n_events") else "nothing (no events)"
            raise EventDataError(f"{path}: no events in the window [{t_start}, {t_end}) s; the events cover "
                                 f"{span} (relative to t_origin = {origin}); choose a window inside that range")
        events = _events(f, lo, hi, sensor_size, origin, path)
        gt = None
        if frames and "frames/t" in f and f["frames/t"].shape[0]:
            ft = f["frames/t"][()]
            a = 0 if t_start is None else int(np.searchsorted(ft, t_start, side="left"))
            b = len(ft) if t_end is None else int(np.searchsorted(ft, t_end, side="left"))
            if b > a:
                gt = Frames(f["frames/images"][a:b], ft[a:b], origin)
    meta = {"format": "canonical", **{k: v for k, v in info.items() if k not in ("format", "meta")},
            **info["meta"], "event_slice": (lo, hi)}
    meta["path"] = str(path)
    return Recording(events, gt, meta)


def iter_canonical_events(path, t_start: float | None = None, t_end: float | None = None, *,
                          chunk_events: int = 1 << 20):
    """Yield the events of a canonical file as consecutive :class:`Events` of at most ``chunk_events``.

    Memory stays at one chunk whatever the sequence length (e.g. for event rates or binning of a
    10^8-event recording). The window is ``t_start <= t < t_end`` as in :func:`read_canonical`.
    """
    if chunk_events < 1:
        raise EventDataError(f"chunk_events must be a positive number of events, got {chunk_events}")
    with _open(path) as f:
        info = _info_from(f, path)
        lo, hi = _window(f, path, t_start, t_end)
        for start in range(lo, hi, chunk_events):
            yield _events(f, start, min(start + chunk_events, hi), info["sensor_size"],
                          float(info["t_origin"]), path)
