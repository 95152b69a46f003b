"""The canonical HDF5 file of one converted sequence: its layout, its reader and its writer.

Every dataset that ``data_fetch`` converts (IJRR, HQF, CED, MVSEC, and AED once its converter
exists) ends up in this one layout, so the rest of the kit has a single real-data format::

    /                      attrs: format = "evinr-lite canonical", format_version = 1,
                           sensor_size = (H, W), t_origin (s, absolute time of t = 0),
                           dataset, sequence, source, source_url, raw_file, C (contrast
                           threshold to use), eval_window (s, on this file's clock; NaN, NaN
                           = whole sequence), eval_window_published (as published, seconds
                           after t_zero), t_zero (s, the zero of the published windows:
                           earliest event or frame), n_events, n_frames, t_first, t_last,
                           converter, meta_json (a JSON object: calibration, notes, ...);
                           optional cfa (colour sensors only, see below)
    /events/t              float64 [N], seconds since t_origin, non-decreasing
    /events/x, /events/y   uint16 [N], column and row
    /events/p              int8 [N], polarity -1 / +1
    /events/t_index        float64 [ceil(N / stride)], t[::stride] (attr "stride"): a coarse
                           index so that a time window is found by reading one chunk
    /frames/images         uint8 [F, H, W], ground-truth frames (grey), one chunk per frame
    /frames/rgb            optional, uint8 [F, H, W, 3]: the same frames in colour (R, G, B),
                           present only when the source frames are colour; /frames/images then
                           holds their grey version (ITU-R 709 weights, core.frames.to_grey_uint8)
    /frames/t              float64 [F], seconds since t_origin, non-decreasing

Colour sensors (e.g. the Color DAVIS346 of CED, a 2 x 2 Bayer filter over both the events and the
APS frames) carry the root attribute ``cfa``: the colours of the photosites (row 0, column 0),
(0, 1), (1, 0), (1, 1) of the event sensor, one of "RGGB", "GRBG", "GBRG", "BGGR" (the phase is in
the name: "GRBG" is RGGB shifted by one column). Events stay at the photosites (full resolution);
split them by colour with :func:`evinr_lite.sim.quadbayer.demosaic_events_rgb` (``block=1``,
``phase=cfa_phase(cfa)``). Files without ``cfa`` are mono; files without /frames/rgb have grey
frames only. Both additions are optional, so format_version stays 1: files written before them
read as before, and a reader that ignores them still finds grey frames in /frames/images.
:func:`read_canonical` exposes them as ``meta["cfa"]`` (None for mono), ``meta["frames_rgb"]``
(uint8 [F, H, W, 3], one per frame of ``recording.frames``, or None) and ``meta["frames_rgb_t"]``
(their times, equal to ``recording.frames.t``).

Event datasets are chunked and compressed; readers never load more than the requested
window (or one chunk at a time with :func:`iter_canonical_events`), so a sequence of 10^8
events does not need 10^8 x 4 x 8 bytes of memory.

:class:`CanonicalWriter` (used by ``data_fetch``'s converters) takes events and frames in pieces
(a converter streams a raw file chunk by chunk or message by message), checks them, writes full
compressed chunks, builds the coarse time index on the way, and at the end sets the attributes.
The file is written under a temporary name and renamed into place only when complete, so an
interrupted conversion never leaves a file that looks finished.
"""
from __future__ import annotations

import json
import logging
import math
import os
from pathlib import Path

import numpy as np

from ..core.cfa import CFA_NAMES, cfa_phase, check_cfa  # the colour filter's one home (names kept here)
from ..core.checks import (check_path_type, check_reader_window, decimal_as_float, host_array, is_real_number,
                           real_number, seconds_array, short_repr, true_or_false, whole_number)
from ..core.events import (MAX_SENSOR_SIDE, EventDataError, Events, check_sensor_size, check_t_origin,
                           check_time_range)
from ..core.frames import Frames, to_grey_uint8
from .notes import note
from .output import CloseOrAbort
from .source import RecordingSource

__all__ = [
    "CanonicalWriter",
    "repair_frame_times",
    "CHUNK_EVENTS",
    "COMPRESSION",
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "is_canonical",
    "canonical_info",
    "read_canonical",
    "iter_canonical_events",
    "find_time_index",
    "CFA_NAMES",
    "check_cfa",
    "cfa_phase",
    "CanonicalSource",
    "META_TYPES",
]

FORMAT_NAME = "evinr-lite canonical"
FORMAT_VERSION = 1
CHUNK_EVENTS = 1 << 16          # events per HDF5 chunk, and the stride of events/t_index
COMPRESSION = dict(compression="gzip", compression_opts=4, shuffle=True)
DTYPES = {"t": np.float64, "x": np.uint16, "y": np.uint16, "p": np.int8}
log = logging.getLogger("evinr_lite")
EVENT_FIELDS = ("t", "x", "y", "p")


def _file_path(path) -> Path:
    """``path`` as a Path; None, a number, a list or bytes are refused naming the argument (Python's "expected str,
    bytes or os.PathLike object" named none)."""
    return Path(check_path_type(path, "path", "a file path", "pass the .h5 file that data_fetch.get / convert wrote"))


def is_canonical(path) -> bool:
    """True when ``path`` is an HDF5 file in the canonical layout (any version)."""
    import h5py

    path = _file_path(path)
    if not path.is_file():
        return False
    try:
        with h5py.File(path, "r") as f:
            return _attr(f.attrs.get("format")) == FORMAT_NAME
    except Exception:   # a damaged file (h5py raises OSError, KeyError, RuntimeError, ...): not canonical
        return False


def _damaged(path, err) -> EventDataError:
    return EventDataError(f"{path}: the canonical file is damaged or incomplete ({type(err).__name__}: {err}); delete "
                          "it and convert again (python -m data_fetch get/convert ...)")


def _open(path):
    import h5py

    path = _file_path(path)
    if not path.exists():
        raise EventDataError(f"no such file: {path}; check the path (data_fetch.get(...) returns it)")
    if not path.is_file():
        raise EventDataError(f"{path} is not a file; pass the converted .h5 file")
    try:
        f = h5py.File(path, "r")
    except OSError as err:
        raise EventDataError(f"{path}: not a readable HDF5 file ({err}); the file is damaged or incomplete: "
                             "delete it and convert again (python -m data_fetch get/convert ...)") from None
    try:
        fmt = _attr(f.attrs.get("format"))
        if fmt != FORMAT_NAME:
            raise EventDataError(f"{path}: not an evinr-lite canonical file (root attribute format is "
                                 f"{fmt!r}); convert the raw recording with "
                                 "`python -m data_fetch convert <raw path>`, or read an HQF-style h5 "
                                 "with evinr_lite.io.readers.read_h5")
        try:
            version = int(np.asarray(f.attrs.get("format_version", 0)).reshape(()))
        except (TypeError, ValueError):
            raise EventDataError(f"{path}: the attribute format_version is not a number; convert the file again") from None
        if version > FORMAT_VERSION:
            raise EventDataError(f"{path}: canonical format version {version} is newer than this evinr-lite "
                                 f"reads ({FORMAT_VERSION}); update evinr-lite")
        missing = [f"events/{k}" for k in EVENT_FIELDS if f"events/{k}" not in f]
        if missing:
            raise EventDataError(f"{path}: missing datasets {missing}; the file is incomplete: convert it again")
        _check_datasets(f, path, [f"events/{k}" for k in EVENT_FIELDS] + ["events/t_index", "frames/t",
                                                                           "frames/images", "frames/rgb"])
        n = f["events/t"].shape
        bad = [k for k in EVENT_FIELDS if f[f"events/{k}"].shape != n or len(n) != 1]
        if bad:
            raise EventDataError(f"{path}: events/{bad[0]} has shape {f[f'events/{bad[0]}'].shape}, expected {n} like "
                                 "events/t; the file is damaged: convert it again")
    except EventDataError:
        f.close()
        raise
    except (OSError, KeyError, RuntimeError, TypeError, ValueError) as err:
        f.close()
        raise _damaged(path, err) from None
    return f


def _check_datasets(f, path, names) -> None:
    """Each of ``names`` present in the file must be a numeric dataset (not a group, not text)."""
    import h5py

    for name in names:
        node = f.get(name)
        if node is None:
            continue
        if not isinstance(node, h5py.Dataset):
            raise EventDataError(f"{path}: {name} is a {type(node).__name__.lower()}, not a dataset; the file is "
                                 "damaged or was not written by data_fetch: convert it again")
        if node.dtype.kind not in "iuf":
            raise EventDataError(f"{path}: {name} holds {node.dtype} values, not numbers; the file is damaged: "
                                 "convert it again")


# Values of meta_json that the kit reads, with their type check and what they must be; other keys are free.
META_TYPES = {
    "C": (lambda v: isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0,
          "a positive number (the contrast threshold)"),
    "eval_window": (lambda v: v is None or (isinstance(v, list) and len(v) == 2 and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v) and v[0] < v[1]),
                    "null or [start, end], two numbers of seconds with start < end"),
    "calib": (lambda v: isinstance(v, (dict, list)), "an object or a list of numbers"),
    "cfa": (lambda v: v is None or (isinstance(v, str) and v.upper() in CFA_NAMES), f"null or one of {list(CFA_NAMES)}"),
    "frame_times_repaired": (lambda v: isinstance(v, list) and all(isinstance(x, int) for x in v),
                             "a list of frame indices"),
    "frames_sorted": (lambda v: isinstance(v, bool), "true or false"),
    "t_origin": (lambda v: isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v),
                 "a finite number of seconds"),
    "time_unit": (lambda v: v in ("s", "ms", "us", "ns"), "one of 's', 'ms', 'us', 'ns'"),
}


def _check_meta(meta: dict, path) -> None:
    """The keys of meta_json that the kit reads must have their type (see :data:`META_TYPES`)."""
    for key, (valid, expected) in META_TYPES.items():
        if key in meta and not valid(meta[key]):
            raise EventDataError(f"{path}: meta_json[{key!r}] is {meta[key]!r}, but it must be {expected}; repair "
                                 f"it (h5py.File(path, 'r+').attrs['meta_json']) or convert the file again")


def _attr(value):
    """h5py attribute -> plain Python value (str, float, int, tuple)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        return tuple(v.item() for v in value.ravel())
    if isinstance(value, np.generic):
        return value.item()
    return value


def _info_from(f, path) -> dict:
    info = {k: _attr(v) for k, v in f.attrs.items() if k != "meta_json"}
    try:
        info["meta"] = json.loads(_attr(f.attrs["meta_json"])) if "meta_json" in f.attrs else {}
    except (TypeError, ValueError) as err:
        raise EventDataError(f"{path}: the attribute meta_json is not JSON ({err}); convert the file again") from None
    if not isinstance(info["meta"], dict):
        raise EventDataError(f"{path}: the attribute meta_json is not a JSON object; convert the file again")
    _check_meta(info["meta"], path)
    if "sensor_size" not in f.attrs:
        raise EventDataError(f"{path}: no attribute sensor_size (H, W); the file is incomplete: convert it again")
    size = np.asarray(f.attrs["sensor_size"]).ravel()
    if size.size != 2 or size.dtype.kind not in "iuf" or not np.all(np.isfinite(size)) or np.any(size <= 0) \
            or np.any(size != np.round(size)) or np.any(size > MAX_SENSOR_SIDE):
        raise EventDataError(f"{path}: the attribute sensor_size must be (H, W), two positive whole numbers of at most "
                             f"{MAX_SENSOR_SIDE} (no event camera is larger); got {f.attrs['sensor_size']!r}: convert "
                             "the file again")
    info["sensor_size"] = tuple(int(v) for v in size)
    try:
        origin = float(np.asarray(f.attrs.get("t_origin", 0.0)).reshape(()))
    except (TypeError, ValueError):
        origin = math.nan
    if not math.isfinite(origin):
        raise EventDataError(f"{path}: the attribute t_origin is not a finite number of seconds; convert the file again")
    info["t_origin"] = origin
    for key in ("C", "t_first", "t_last", "t_zero"):
        if key in info and not isinstance(info[key], (int, float)):
            raise EventDataError(f"{path}: the attribute {key} is not a number (got {info[key]!r}); convert the file again")
    for key in ("n_events", "n_frames"):
        if key in info and not isinstance(info[key], int):
            raise EventDataError(f"{path}: the attribute {key} is not a whole number (got {info[key]!r}); convert "
                                 "the file again")
    if "C" in info and not (math.isfinite(info["C"]) and info["C"] > 0):
        raise EventDataError(f"{path}: the stored contrast threshold C = {info['C']} is not a positive number; "
                             "convert the file again with a valid --C")
    for key in ("eval_window", "eval_window_published"):   # NaN, NaN on disk = the whole sequence
        window = info.get(key)
        if window is not None:
            if not isinstance(window, tuple) or len(window) != 2 or not all(isinstance(v, (int, float)) for v in window):
                raise EventDataError(f"{path}: the attribute {key} must be two numbers (start, end); got {window!r}")
            if not all(math.isfinite(v) for v in window):
                window = None
        info[key] = window
    info["cfa"] = check_cfa(info.get("cfa"), lambda msg: EventDataError(f"{path}: the attribute {msg}; convert "
                                                                         "the file again"))
    info["path"] = str(path)
    return info


def canonical_info(path) -> dict:
    """The file's attributes as a dict (``meta`` decoded from JSON; ``eval_window`` None = whole)."""
    with _open(path) as f:
        try:
            return _info_from(f, path)
        except EventDataError:
            raise
        except (OSError, KeyError, RuntimeError, TypeError, ValueError) as err:
            raise _damaged(path, err) from None


def _time_index(f, n: int):
    """(t_index, stride) when ``events/t_index`` is usable: a float dataset of ceil(n / stride) finite,
    non-decreasing values with a positive whole ``stride``; else None (the caller bisects events/t)."""
    import h5py

    ds = f.get("events/t_index")
    if not isinstance(ds, h5py.Dataset) or ds.ndim != 1 or ds.dtype.kind != "f":
        return None
    try:
        stride = int(np.asarray(ds.attrs.get("stride")).reshape(()))
    except (TypeError, ValueError):
        return None
    if stride <= 0 or ds.shape[0] != -(-n // stride):
        return None
    index = ds[()]
    if not np.all(np.isfinite(index)) or np.any(np.diff(index) < 0):
        return None
    return index, stride


def _check_index_query(f, value, side) -> None:
    """find_time_index's arguments: an open canonical file (a group with events/t), a time that is no NaN
    (-inf and +inf are before and after every event: 0 and n), 'left' or 'right' (None or text were Python's or
    numpy's errors; NaN, True or text answered n, as for a time after every event)."""
    import h5py

    if not isinstance(f, h5py.Group) or not isinstance(f.get("events/t"), h5py.Dataset):
        raise EventDataError(f"find_time_index: f= must be an open canonical file with events/t "
                             f"(h5py.File(path, 'r')), got {short_repr(f)}")
    number = decimal_as_float(value)   # a Decimal window is read as its float, as the readers' windows are
    if not is_real_number(number) or math.isnan(float(number)):
        raise EventDataError(f"find_time_index: value= must be a time in seconds (relative to t_origin; -inf or inf "
                             f"for before or after every event), not NaN; got {short_repr(value)}")
    if not isinstance(side, str) or side not in ("left", "right"):
        raise EventDataError(f"find_time_index: side= must be 'left' (t[i] >= value) or 'right' (t[i] > value), got "
                             f"{short_repr(side)}")


def find_time_index(f, value: float, side: str = "left") -> int:
    """First event index i with t[i] >= value (side 'left') or t[i] > value ('right').

    Uses ``events/t_index`` (one float per chunk: t_index[k] = t[k * stride]) and then reads a single
    chunk of ``events/t``. The index is not trusted blindly: it must be well-formed, and the entries
    that bracket the answer must equal the timestamps they index (checked on the chunk read, plus one
    element); a damaged or missing index falls back to a binary search on ``events/t`` reading one
    element at a time (the same answer, slower), with a logged warning.
    """
    _check_index_query(f, value, side)
    ts = f["events/t"]
    n = ts.shape[0]
    found = _time_index(f, n) if n else None
    if found is not None:
        index, stride = found
        k = int(np.searchsorted(index, value, side=side))
        lo, hi = max(k - 1, 0) * stride, min(max(k, 1) * stride, n)
        chunk = ts[lo:hi]
        ok = chunk[0] == index[max(k - 1, 0)] and (hi >= n or float(ts[hi]) == index[hi // stride])
        if ok:   # t[lo] < value <= t[hi] (left side): the answer lies in this chunk
            return 0 if k == 0 else lo + int(np.searchsorted(chunk, value, side=side))
    if n and "events/t_index" in f:
        log.warning("%s: events/t_index does not match events/t (the index is damaged); finding the window by "
                    "binary search on events/t instead (convert the file again to repair the index)", f.filename)
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
        if "polarity" in str(err):   # the layout fixes -1/+1: the reader takes no other encoding
            values = sorted(set(np.unique(np.asarray(p)).tolist()) - {-1, 1})[:6]
            raise EventDataError(f"{source}: events/p must hold -1/+1 (the canonical layout) but holds {values}; the "
                                 "file is damaged: convert it again with python -m data_fetch convert RAW") from None
        raise EventDataError(f"{source}: {err}") from None


def _read_open(f, path, t_start, t_end, frames):
    info = _info_from(f, path)
    sensor_size, origin = info["sensor_size"], float(info["t_origin"])
    lo, hi = _window(f, path, t_start, t_end)
    if hi <= lo and (t_start is not None or t_end is not None):
        first, last = info.get("t_first"), info.get("t_last")
        span = f"[{first:.6f}, {last:.6f}] s" if info.get("n_events") and first is not None else "nothing (no events)"
        raise EventDataError(f"{path}: no events in the window [{t_start}, {t_end}) s; the events cover "
                             f"{span} (relative to t_origin = {origin}); choose a window inside that range")
    events = _events(f, lo, hi, sensor_size, origin, path)
    gt = _frames(f, path, origin, t_start, t_end, info) if frames and "frames/t" in f else None
    return info, lo, hi, events, gt


def _frames(f, path, origin: float, t_start, t_end, info: dict):
    """The frames with t_start <= t < t_end (None when there are none), in time order: frames/t out of
    order is sorted with a note (meta["read_notes"]); frames/rgb, when present, goes to info["frames_rgb"]."""
    ft = f["frames/t"][()]
    if ft.ndim != 1 or not np.all(np.isfinite(ft)):
        raise EventDataError(f"{path}: frames/t must be finite seconds, one per frame (got shape {ft.shape}); the "
                             "file is damaged: convert it again")
    if not len(ft):
        return None
    if "frames/images" not in f or f["frames/images"].shape[0] != len(ft):
        raise EventDataError(f"{path}: frames/t and frames/images do not match; the file is damaged: convert "
                             "it again")
    order = None
    if np.any(np.diff(ft) < 0):
        order = np.argsort(ft, kind="stable")
        ft = ft[order]
        note(info, f"{path}: frames/t is not in time order; the frames are read sorted by their timestamps")
    a = 0 if t_start is None else int(np.searchsorted(ft, t_start, side="left"))
    b = len(ft) if t_end is None else int(np.searchsorted(ft, t_end, side="left"))
    if b <= a:
        return None

    def take(ds):   # rows a:b of the time order (h5py reads increasing indices only)
        if order is None:
            return ds[a:b]
        wanted = order[a:b]
        rows = np.unique(wanted)
        return ds[rows][np.searchsorted(rows, wanted)]

    try:
        gt = Frames(take(f["frames/images"]), ft[a:b], origin)
    except EventDataError as err:
        raise EventDataError(f"{path}: {err}") from None
    if "frames/rgb" in f:
        rgb = f["frames/rgb"]
        if rgb.shape != (len(ft), *f["frames/images"].shape[1:], 3) or rgb.dtype != np.uint8:
            raise EventDataError(f"{path}: frames/rgb is {rgb.dtype} {rgb.shape}, expected uint8 "
                                 f"{(len(ft), *f['frames/images'].shape[1:], 3)} like frames/images; the "
                                 "file is damaged: convert it again")
        info["frames_rgb"], info["frames_rgb_t"] = take(rgb), gt.t.copy()
    return gt


def read_canonical(path, t_start: float | None = None, t_end: float | None = None, *,
                   frames: bool = True):
    """A canonical sequence file as a :class:`~evinr_lite.core.recording.Recording`.

    Args:
        path: the ``.h5`` file that ``data_fetch.get`` / ``convert`` wrote.
        t_start, t_end: seconds on the file's clock (``t`` relative to ``t_origin``); only the
            events with ``t_start <= t < t_end`` are read from disk (found through the stored
            time index), and only the frames in that window. None: from the start / to the end.
            ``recording.meta["eval_window"]`` is the sequence's evaluation window on this clock.
        frames: False skips the ground-truth frames.

    Returns:
        Recording(events, frames or None, meta) with meta holding dataset, sequence, source, C,
        eval_window (None = whole sequence), t_zero, event_slice (lo, hi), cfa (the colour filter
        name, None for a mono sensor), frames_rgb / frames_rgb_t (colour frames uint8 [F, H, W, 3]
        and their times, one per grey frame, or None) and the stored meta.
    """
    from ..core.recording import Recording

    check_reader_window(t_start, t_end)   # the bounds are searched with as given, as before the check
    t_start, t_end = host_array(t_start), host_array(t_end)   # a tensor as numpy: the same value, no torch warning
    frames = true_or_false(frames, "frames")
    with _open(path) as f:
        try:
            info, lo, hi, events, gt = _read_open(f, path, t_start, t_end, frames)
        except EventDataError:
            raise
        except (OSError, KeyError, RuntimeError, TypeError, ValueError, IndexError) as err:
            raise _damaged(path, err) from None
    return Recording(events, gt, _recording_meta(info, path, (lo, hi)))


def _recording_meta(info: dict, path, event_slice) -> dict:
    """Recording.meta of a canonical file: its attributes, then meta_json, then what the reader adds."""
    meta = {"format": "canonical", "frames_rgb": None, "frames_rgb_t": None,
            **{k: v for k, v in info.items() if k not in ("format", "meta")}, **info["meta"]}
    meta.update(path=str(path), event_slice=event_slice)
    if info.get("read_notes"):
        meta["read_notes"] = list(info["read_notes"])
    return meta


class CanonicalSource(RecordingSource):
    """Windows of a canonical file: each found through the (checked) time index, only its events read.

    Holds the file open (use as a context manager or call :meth:`close`). ``t_span`` and ``n_events``
    come from the stored events (first and last timestamp, dataset length), the frames are read once.
    """

    def __init__(self, path, *, frames: bool = True):
        path = _file_path(path)
        frames = true_or_false(frames, "frames")
        self._f = _open(path)
        try:
            info = _info_from(self._f, path)
            ts = self._f["events/t"]
            n = ts.shape[0]
            self.t_span = (float(ts[0]), float(ts[n - 1])) if n else (0.0, 0.0)
            gt = _frames(self._f, path, float(info["t_origin"]), None, None, info) if frames and "frames/t" in self._f \
                else None
        except BaseException as err:
            self.close()
            if not isinstance(err, EventDataError) and isinstance(err, (OSError, KeyError, RuntimeError, TypeError,
                                                                         ValueError, IndexError)):
                raise _damaged(path, err) from None   # an EventDataError already names the problem and the fix
            raise
        self.path, self.format, self.frames, self.n_events = path, "canonical", gt, int(n)
        self.sensor_size, self.t_origin = info["sensor_size"], float(info["t_origin"])
        self.meta = _recording_meta(info, path, (0, int(n)))

    def _read_window(self, t0: float, t1: float) -> Events:
        try:
            lo, hi = _window(self._f, self.path, t0, t1)
            return _events(self._f, lo, hi, self.sensor_size, self.t_origin, self.path)
        except EventDataError:
            raise
        except (OSError, KeyError, RuntimeError, TypeError, ValueError, IndexError) as err:
            raise _damaged(self.path, err) from None

    def load(self, t_start=None, t_end=None):
        """As :func:`read_canonical` (the frames' colour version included)."""
        return read_canonical(self.path, t_start, t_end)

    def close(self) -> None:
        f, self._f = getattr(self, "_f", None), None
        if f is not None:
            f.close()


def iter_canonical_events(path, t_start: float | None = None, t_end: float | None = None, *,
                          chunk_events: int = 1 << 20):
    """Yield the events of a canonical file as consecutive :class:`Events` of at most ``chunk_events``.

    Memory stays at one chunk whatever the sequence length (e.g. for event rates or binning of a
    10^8-event recording). The window is ``t_start <= t < t_end`` as in :func:`read_canonical`.
    """
    chunk_events = whole_number(chunk_events, "chunk_events", lo=1)   # 2.5 was range()'s TypeError, True one event
    check_reader_window(t_start, t_end)   # "0" was read as seconds, NaN gave no chunk without a word
    t_start, t_end = host_array(t_start), host_array(t_end)   # searched with as given (a tensor as numpy)
    with _open(path) as f:
        try:
            info = _info_from(f, path)
            lo, hi = _window(f, path, t_start, t_end)
        except EventDataError:
            raise
        except (OSError, KeyError, RuntimeError, TypeError, ValueError, IndexError) as err:
            raise _damaged(path, err) from None
        for start in range(lo, hi, chunk_events):
            try:
                chunk = _events(f, start, min(start + chunk_events, hi), info["sensor_size"],
                                float(info["t_origin"]), path)
            except EventDataError:
                raise
            except (OSError, KeyError, RuntimeError, TypeError, ValueError) as err:
                raise _damaged(path, err) from None
            yield chunk


# ---- writing ----------------------------------------------------------------------------

def repair_frame_times(t: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """Repair isolated wrong frame timestamps (a stamp out of order between two good ones).

    A decreasing step t[i] > t[i+1] is blamed on the one stamp whose neighbours are in order
    (t[i-1] <= t[i+1]: t[i] is too late; else t[i] <= t[i+2]: t[i+1] is too early); that stamp is
    replaced by the midpoint of its neighbours. Returns (repaired copy, indices repaired). Steps
    that cannot be blamed on one interior stamp are left (the caller then sorts the frames).
    """
    t = seconds_array(t, "t", allow_empty=True).astype(np.float64)   # None, text, NaN, 2-D: refused by name
    fixed = []
    for i in np.flatnonzero(np.diff(t) < 0):
        if t[i] <= t[i + 1]:
            continue  # already repaired through its neighbour
        if 0 < i and t[i - 1] <= t[i + 1]:
            t[i] = 0.5 * (t[i - 1] + t[i + 1])
            fixed.append(int(i))
        elif i + 2 < len(t) and t[i] <= t[i + 2]:
            t[i + 1] = 0.5 * (t[i] + t[i + 2])
            fixed.append(int(i + 1))
    return t, fixed


class CanonicalWriter(CloseOrAbort):
    """Stream events and frames into a canonical ``.h5`` file.

    Args:
        out: final path of the file (written as ``.<name>.partial`` and renamed when done).
        sensor_size: (H, W) of the events.
        t_origin: seconds; absolute time of t = 0 (the times given to :meth:`add_events` and
            :meth:`add_frame` are relative to it).
        dataset, sequence, source, source_url, raw_file, converter: provenance attributes.
        C: contrast threshold to use with this sequence.
        eval_window: (start, end) seconds after the sequence's zero (earliest event or frame), as
            published; None = the whole sequence.
        meta: JSON-serialisable extras (calibration, notes).
        cfa: the colour filter of a colour sensor ("RGGB", "GRBG", "GBRG", "BGGR"; see the module
            docstring), None for a mono sensor.

    Frames are grey [H, W] or colour [H, W, 3] uint8 (one kind per file): colour frames are stored
    in /frames/rgb and their grey version in /frames/images.

    Use as a context manager; leaving the block with an exception deletes the partial file.
    Problems raise :attr:`error` (``EventDataError``; ``data_fetch`` sets its ``ConversionError``).
    """

    error = EventDataError

    def __init__(self, out, *, sensor_size, t_origin: float = 0.0, dataset: str = "", sequence: str = "",
                 source: str = "", source_url: str = "", raw_file: str = "", C: float = 1.0,
                 eval_window=None, converter: str = "", meta: dict | None = None, cfa: str | None = None):
        import h5py

        self.out = Path(out)
        self._check_settings(sensor_size, t_origin, C, eval_window, meta,
                             dict(dataset=dataset, sequence=sequence, source=source, source_url=source_url,
                                  raw_file=raw_file, converter=converter))   # before any folder or file is made
        self.out.parent.mkdir(parents=True, exist_ok=True)
        self.tmp = self.out.with_name(f".{self.out.name}.partial")
        self.H, self.W = (int(v) for v in sensor_size)
        self.t_origin = float(t_origin)
        self.attrs = dict(dataset=dataset, sequence=sequence, source=source, source_url=source_url,
                          raw_file=raw_file, C=float(C), converter=converter)
        self.eval_window = None if eval_window is None else tuple(float(v) for v in eval_window)
        self.meta = dict(meta or {})
        self.cfa = check_cfa(cfa, self.error)
        self.f = h5py.File(self.tmp, "w")
        ev = self.f.create_group("events")
        self.ds = {k: ev.create_dataset(k, shape=(0,), maxshape=(None,), dtype=dt, chunks=(CHUNK_EVENTS,),
                                        **COMPRESSION) for k, dt in DTYPES.items()}
        self.buf = {k: [] for k in DTYPES}
        self.buffered = 0
        self.n = 0
        self.t_last = -math.inf
        self.t_first = None
        self.index: list[np.ndarray] = []
        self.frame_t: list[float] = []
        self.frames = None
        self.rgb = None              # /frames/rgb once a colour frame arrived
        self.closed = False

    def _check_settings(self, sensor_size, t_origin, C, eval_window, meta, texts: dict) -> None:
        """Refuse (:attr:`error`) what the file's attributes cannot hold: a sensor size that is no two whole numbers
        (2.5 rows were written as 2), a C or t_origin that is no finite number (NaN was written), a reversed or
        non-finite eval_window, meta that JSON cannot hold (found at close, after every event) and attributes that
        are no text (5 was written as a number, None was h5py's TypeError at close)."""
        try:
            check_sensor_size(sensor_size)
            check_t_origin(t_origin)
            real_number(decimal_as_float(C), "C", lo=0, lo_open=True,   # Fraction, Decimal: float(C) as before
                        hint="the contrast threshold to use with this sequence")
        except EventDataError as err:
            raise self.error(str(err)) from None
        if eval_window is not None:
            check_time_range(eval_window, "eval_window", self.error)
        try:
            json.dumps(dict(meta or {}))
        except (TypeError, ValueError) as err:
            raise self.error(f"meta= must be a dict of JSON values (numbers, text, lists, dicts; convert numpy "
                             f"values with .item() or .tolist()), got {type(meta).__name__}: {err}") from None
        for name, value in texts.items():
            if not isinstance(value, str):
                raise self.error(f"{name}= must be text (a str), got {value!r}")

    # ---- events -----------------------------------------------------------------------------
    def add_events(self, t, x, y, p, *, where: str = "") -> None:
        """Append events (t float64 s since t_origin, non-decreasing; p in -1/+1).

        ``where`` names the position in the raw file for error messages (e.g. "line 1200").
        """
        t = np.asarray(t)
        if t.size == 0:
            return
        x, y, p = np.asarray(x), np.asarray(y), np.asarray(p)
        at = f" ({where})" if where else ""
        if not (t.shape == x.shape == y.shape == p.shape) or t.ndim != 1:
            raise self.error(f"t, x, y, p of a block differ in shape{at}: {t.shape}, {x.shape}, {y.shape}, {p.shape}")
        if t.dtype.kind not in "iuf":
            raise self.error(f"t must be numbers (seconds since t_origin){at}; got {t.dtype} values such as "
                             f"{t[:3].tolist()}")
        t = t.astype(np.float64, copy=False)
        for name, v in (("x", x), ("y", y)):   # numpy's cast made 1.5 into 1 and NaN into 0
            if v.dtype.kind not in "iu" and not (v.dtype.kind == "f" and np.all(np.isfinite(v)) and
                                                 np.all(v == np.round(v))):
                raise self.error(f"{name} must be whole pixel indices{at}; got {v.dtype} values such as "
                                 f"{v[:3].tolist()}")
        if not np.all(np.isfinite(t)):
            raise self.error(f"non-finite timestamp{at}; the raw file is damaged")
        steps = np.diff(t, prepend=self.t_last)
        if np.any(steps < 0):
            i = int(np.flatnonzero(steps < 0)[0])
            prev = self.t_last if i == 0 else t[i - 1]
            raise self.error(f"timestamps go back in time{at}: {t[i]!r} s after {prev!r} s (event "
                                  f"{self.n + self.buffered + i}); the raw events are not sorted by time")
        for name, v, size in (("x", x, self.W), ("y", y, self.H)):
            if v.min() < 0 or v.max() >= size:
                raise self.error(
                    f"{name} coordinates span [{v.min()}, {v.max()}] but the sensor is (H, W) = "
                    f"{(self.H, self.W)}{at}; the sensor size is wrong for this recording (pass the camera's "
                    "real size) or the raw file is damaged")
        if not np.all((p == 1) | (p == -1)):
            raise self.error(f"polarities must be -1/+1 when written{at}; got {np.unique(p)[:6]}")
        if self.t_first is None:
            self.t_first = float(t[0])
        self.t_last = float(t[-1])
        for k, v in zip("txyp", (t, x, y, p)):
            self.buf[k].append(v.astype(DTYPES[k], copy=False))
        self.buffered += t.size
        if self.buffered >= 16 * CHUNK_EVENTS:
            self._flush(full_chunks_only=True)

    def _flush(self, full_chunks_only: bool) -> None:
        if not self.buffered:
            return
        cols = {k: np.concatenate(v) if len(v) > 1 else v[0] for k, v in self.buf.items()}
        count = self.buffered
        if full_chunks_only:
            count = (count // CHUNK_EVENTS) * CHUNK_EVENTS
            if count == 0:
                return
        start, end = self.n, self.n + count
        for k, ds in self.ds.items():
            ds.resize((end,))
            ds[start:end] = cols[k][:count]
        first = (-start) % CHUNK_EVENTS
        self.index.append(cols["t"][first:count:CHUNK_EVENTS].copy())
        self.buf = {k: [v[count:]] if count < self.buffered else [] for k, v in cols.items()}
        self.buffered -= count
        self.n = end

    # ---- frames -----------------------------------------------------------------------------
    def add_frame(self, image, t: float) -> None:
        """Append one uint8 frame taken at ``t`` (s since t_origin): grey [H, W] or colour (R, G, B)
        [H, W, 3]; all frames of a file are of one kind (a colour frame is also stored as grey)."""
        if not is_real_number(decimal_as_float(t)):   # text, None, a list: "must be real number"; True was 1 s
            raise self.error(f"frame time must be a finite number of seconds since t_origin, got {t!r} "
                             f"(frame {len(self.frame_t)})")
        image = np.asarray(image)
        colour = image.ndim == 3 and image.shape[-1] == 3
        if image.dtype != np.uint8 or not (image.ndim == 2 or colour):
            raise self.error(f"frames must be grey uint8 [H, W] or colour uint8 [H, W, 3]; got {image.dtype} "
                             f"{image.shape}")
        if not math.isfinite(t):
            raise self.error(f"frame {len(self.frame_t)} has a non-finite timestamp")
        k = len(self.frame_t)
        if k and colour != (self.rgb is not None):
            raise self.error(f"frame {k} is {'colour' if colour else 'grey'} but the first frame is "
                             f"{'grey' if colour else 'colour'}; all frames of a sequence must be of one kind")
        grey = to_grey_uint8(image, f"frame {k}") if colour else image
        if self.frames is None:
            h, w = grey.shape
            self.frames = self.f.create_dataset("frames/images", shape=(0, h, w), maxshape=(None, h, w),
                                                dtype=np.uint8, chunks=(1, h, w), **COMPRESSION)
            if colour:
                self.rgb = self.f.create_dataset("frames/rgb", shape=(0, h, w, 3), maxshape=(None, h, w, 3),
                                                 dtype=np.uint8, chunks=(1, h, w, 3), **COMPRESSION)
        if grey.shape != self.frames.shape[1:]:
            raise self.error(f"frame {k} is {grey.shape} but the first frame is "
                                  f"{self.frames.shape[1:]}; all frames of a sequence must share one size")
        self.frames.resize((k + 1, *self.frames.shape[1:]))
        self.frames[k] = grey
        if colour:
            self.rgb.resize((k + 1, *self.rgb.shape[1:]))
            self.rgb[k] = image
        self.frame_t.append(float(t))

    # ---- finishing --------------------------------------------------------------------------
    def _finish_frames(self) -> list[int]:
        ft = np.array(self.frame_t, dtype=np.float64)
        repaired: list[int] = []
        if ft.size > 1 and np.any(np.diff(ft) < 0):
            ft, repaired = repair_frame_times(ft)
            if repaired:
                log.warning("frame timestamps out of order at %s; repaired as the midpoint of their "
                            "neighbours", repaired)
                self.meta["frame_times_repaired"] = repaired
            if np.any(np.diff(ft) < 0):
                order = np.argsort(ft, kind="stable")
                log.warning("frames are not in time order; sorting them")
                for ds in (self.frames, self.rgb):
                    if ds is not None:
                        ds[...] = ds[()][order]
                ft = ft[order]
                self.meta["frames_sorted"] = True
        self.f.create_dataset("frames/t", data=ft, dtype=np.float64)
        if self.frames is None:
            self.f.create_dataset("frames/images", shape=(0, self.H, self.W), dtype=np.uint8)
        return repaired

    def close(self) -> Path:
        """Write the remaining events, the index and the attributes; rename into place."""
        if self.closed:
            return self.out
        self._flush(full_chunks_only=False)
        if self.n == 0:
            self.abort()
            raise self.error(f"no events were found for {self.out.name}; the raw file holds no events "
                                  "(wrong topic or an empty/damaged file)")
        idx = np.concatenate(self.index) if self.index else np.zeros(0)
        dset = self.f.create_dataset("events/t_index", data=idx, dtype=np.float64)
        dset.attrs["stride"] = CHUNK_EVENTS
        self._finish_frames()
        ft = self.f["frames/t"][()]
        t_zero = min(self.t_first, float(ft[0])) if ft.size else self.t_first
        window = (math.nan, math.nan) if self.eval_window is None else (t_zero + self.eval_window[0],
                                                                        t_zero + self.eval_window[1])
        a = self.f.attrs
        a["format"] = FORMAT_NAME
        a["format_version"] = FORMAT_VERSION
        a["sensor_size"] = np.array([self.H, self.W], dtype=np.int64)
        a["t_origin"] = self.t_origin
        for k, v in self.attrs.items():
            a[k] = v
        a["eval_window"] = np.array(window, dtype=np.float64)
        a["eval_window_published"] = np.array(self.eval_window or (math.nan, math.nan), dtype=np.float64)
        a["t_zero"] = float(t_zero)
        a["n_events"] = int(self.n)
        a["n_frames"] = int(ft.size)
        a["t_first"] = float(self.t_first)
        a["t_last"] = float(self.t_last)
        a["meta_json"] = json.dumps(self.meta, sort_keys=True)
        if self.cfa is not None:
            a["cfa"] = self.cfa
        self.f.close()
        os.replace(self.tmp, self.out)
        self.closed = True
        return self.out

    def abort(self) -> None:
        """Drop the partial file."""
        if not self.closed:
            try:
                self.f.close()
            finally:
                self.tmp.unlink(missing_ok=True)
                self.closed = True
