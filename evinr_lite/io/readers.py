"""Readers for event recordings: IJRR text folders, rpg_e2vid text, EVREAL npy folders, HQF h5, npy
(AEDAT4 and Prophesee files: :mod:`evinr_lite.io.formats`).

Every reader returns :class:`~evinr_lite.core.events.Events` (or a :class:`Recording`: events plus
ground-truth frames plus metadata) in the package conventions: t float64 seconds relative to
``t_origin``, x column, y row, p in {-1, +1}, sensor_size (H, W).

Absolute clocks (IJRR: about 1.47e9 s written with 9 decimals) do not fit float64 at nanosecond
resolution (the spacing of float64 near 1.5e9 is 2.4e-7 s). The text readers therefore split each
timestamp into whole seconds and nanoseconds as integers and subtract a whole-second ``t_origin``
exactly, before any float is formed. Frames of the same recording are read on the same origin.

Use :func:`read_recording` (format detected from content and name) or the per-format readers.
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from ..core.events import (TIME_UNITS, EventDataError, Events, auto_origin, check_time_span, relative_seconds,
                           resolve_time_unit)
from ..core.frames import Frames, to_grey_uint8
from ..core.recording import Recording
from .text import NS, origin_to_ns, parse_event_text, parse_frame_list, read_text_bytes

__all__ = [
    "read_events_npy",
    "read_events_txt",
    "read_frames_ijrr",
    "read_ijrr_folder",
    "read_evreal_folder",
    "read_h5",
    "read_recording",
    "read_events",
    "detect_format",
    "SUPPORTED_FORMATS",
]

SUPPORTED_FORMATS = (
    "an IJRR folder (events.txt, images.txt, images/, calib.txt); "
    "an EVREAL folder (events_ts.npy, events_xy.npy, events_p.npy, images.npy, images_ts.npy, metadata.json); "
    "a data_fetch canonical .h5 file; an HQF-style .h5/.hdf5 file; "
    "a `t x y p` .txt file (optional `W H` header line); "
    "an [N, 4] .npy array; "
    "an AEDAT4 file (.aedat4, DV / DAVIS, with its frames); "
    "a Prophesee EVT2/EVT3 .raw or DAT .dat file"
)


# ---- small helpers ------------------------------------------------------------------------

def _existing(path, kind: str = "file") -> Path:
    import stat

    path = Path(path)
    if not path.exists():
        raise EventDataError(f"no such {kind}: {path}; check the path")
    mode = path.stat().st_mode
    if kind == "folder" and not stat.S_ISDIR(mode):
        raise EventDataError(f"{path} is not a folder; pass the recording's folder")
    if kind == "file" and stat.S_ISDIR(mode):
        raise EventDataError(f"{path} is a folder, not a file; pass the file")
    if kind == "file" and not stat.S_ISREG(mode):
        raise EventDataError(f"{path} is not a regular file (a FIFO, pipe or device); save the data to a file first")
    if kind == "file" and path.stat().st_size == 0:
        raise EventDataError(f"{path} is empty")
    return path


def _load_npy(path: Path):
    """np.load of one plain array, every failure an EventDataError naming the file."""
    try:   # memory-mapped first: a damaged header that claims more data than the file holds fails, not allocates
        array = np.load(path, allow_pickle=False, mmap_mode="r")
        return np.array(array) if isinstance(array, np.memmap) else array
    except Exception as err:   # numpy raises ValueError, SyntaxError, TokenError, OSError, ... on a damaged header
        raise EventDataError(f"{path}: not a readable numeric .npy array ({type(err).__name__}: {err}); the file is "
                             "damaged or incomplete, or not saved with np.save(path, array)") from None


def _seconds(source, t, time_unit):
    """Timestamps in their unit (detected when time_unit is 'auto'/None) -> (seconds relative to origin,
    origin, unit), the span checked for plausibility."""
    unit = resolve_time_unit(t, time_unit, source)
    t, origin = relative_seconds(t, unit)
    check_time_span(t, source, unit)
    return t, origin, unit


def _build_events(source, t, x, y, p, sensor_size, *, polarity, t_origin=0.0, sort=False) -> Events:
    """Events.from_arrays with the file named in any error message."""
    try:
        return Events.from_arrays(t, x, y, p, sensor_size, polarity=polarity, sort=sort, t_origin=t_origin)
    except EventDataError as err:
        raise EventDataError(f"{source}: {err}") from None


def _size_hint(x, y) -> str:
    if len(x) == 0:
        return ""
    return (f"; the events span x (column) 0..{int(np.max(x))} and y (row) 0..{int(np.max(y))}, "
            f"so the smallest sensor that fits is ({int(np.max(y)) + 1}, {int(np.max(x)) + 1}), "
            "but use the camera's real size, e.g. (180, 240) for a DAVIS240C")


def _sensor_from_header(path, header, sensor_size):
    """Reconcile a `W H` header (given as (H, W)) with a sensor_size argument."""
    if header is None or sensor_size is None:
        return sensor_size if header is None else header
    if tuple(int(v) for v in sensor_size) != header:
        H, W = header
        raise EventDataError(
            f"{path}: the header line `{W} {H}` (width first) means sensor_size (H, W) = {header}, "
            f"but sensor_size={tuple(sensor_size)} was passed; pass sensor_size={header} or leave it out"
        )
    return header


# ---- readers ------------------------------------------------------------------------------

def read_events_npy(path, sensor_size=None, *, columns="txyp", polarity="auto", time_unit="auto",
                    sort=False) -> Events:
    """Events from an .npy array [N, 4].

    Args:
        path: .npy file holding an [N, 4] numeric array.
        sensor_size: (H, W); required (an .npy array does not record it).
        columns: order of the columns, a permutation of 'txyp' (e.g. 'xytp' for MVSEC).
        polarity: encoding of p, see :func:`~evinr_lite.core.events.normalize_polarity`.
        time_unit: unit of t: 's', 'ms', 'us' or 'ns'; 'auto': an integer array is microseconds
            (with a TimeUnitWarning), a floating-point one seconds. Implausible spans are refused.
        sort: sort the events by time instead of raising on unsorted input.
    """
    path = _existing(path)
    a = _load_npy(path)
    if sorted(columns) != sorted("txyp"):
        raise EventDataError(f"columns must be a permutation of 'txyp' (e.g. 'txyp' or 'xytp'), got {columns!r}")
    if a.ndim != 2 or a.shape[1] != 4 or a.dtype.kind not in "iuf":
        raise EventDataError(
            f"{path}: expected a numeric array of shape [N, 4] with columns {' '.join(columns)} "
            f"(set columns= for another order), got shape {a.shape} and dtype {a.dtype}; for an EVREAL "
            "folder (events_ts.npy, events_xy.npy, ...) use read_evreal_folder"
        )
    col = {c: a[:, i] for i, c in enumerate(columns)}
    if sensor_size is None:
        raise EventDataError(
            f"{path}: an .npy array does not record the sensor size; pass sensor_size=(H, W) (rows, columns)"
            + _size_hint(col["x"], col["y"])
        )
    t, origin, _ = _seconds(path, col["t"], time_unit)
    return _build_events(path, t, col["x"], col["y"], col["p"], sensor_size,
                         polarity=polarity, t_origin=origin, sort=sort)


def read_events_txt(path, sensor_size=None, *, polarity="auto", t_origin=None, time_unit="auto") -> Events:
    """Events from a text file of `t x y p` lines (IJRR events.txt, rpg_e2vid .txt).

    Args:
        path: text file; t in seconds, x column, y row, p polarity. An optional first line `W H`
            (two integers, width first: the rpg_e2vid header) gives the sensor size.
        sensor_size: (H, W); required unless the file has the header (then they must agree).
        polarity: encoding of p ('auto', '01', 'pm1').
        t_origin: seconds subtracted from every timestamp (exactly). None: the whole seconds of the
            first timestamp when it is >= 1e5 s (an absolute clock), else 0.
        time_unit: unit of t, 's', 'ms', 'us', 'ns'; 'auto': integer timestamps are microseconds
            (with a TimeUnitWarning), decimals seconds. Implausible spans are refused.
    """
    path = Path(path)
    raw = parse_event_text(path, None if t_origin is None else origin_to_ns(t_origin), time_unit=time_unit)
    check_time_span(raw.t, path, raw.time_unit)
    sensor_size = _sensor_from_header(path, raw.header, sensor_size)
    if sensor_size is None:
        raise EventDataError(
            f"{path}: the sensor size is unknown (no `W H` header line); pass sensor_size=(H, W) "
            f"(rows, columns){_size_hint(raw.x, raw.y)}"
        )
    return _build_events(path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                         polarity=polarity, t_origin=raw.origin_ns / NS)


def read_frames_ijrr(folder, t_origin=0.0, *, time_unit: str = "s") -> Frames:
    """Frames listed in ``folder/images.txt`` (`t images/frame_%08d.png` per line), in time order.

    Args:
        folder: the IJRR sequence folder.
        t_origin: seconds subtracted exactly from the timestamps (pass the events' ``t_origin``);
            None: automatic, as for the events.
        time_unit: unit of the timestamps (the events' unit), 's' by default.
    Returns:
        Frames with grey uint8 images [F, H, W] (RGB is converted to grey).
    """
    from skimage.io import imread

    folder = _existing(folder, "folder")
    listing = folder / "images.txt"
    if not listing.exists():
        raise EventDataError(f"{folder}: no images.txt, so no frames; expected lines `t images/frame_%08d.png`")
    try:
        data = read_text_bytes(listing, "frame list")
    except EventDataError as err:
        if "is empty" not in str(err):
            raise
        data = b""
    t, names, origin_ns = parse_frame_list(data, None if t_origin is None else origin_to_ns(t_origin),
                                           source=listing, time_unit=time_unit)
    if not names:
        raise EventDataError(f"{listing} lists no frames; expected lines `t images/frame_%08d.png` "
                             "(or remove images.txt and give the sensor size)")
    images = []
    for name in names:
        image_path = folder / name
        if not image_path.is_file():
            raise EventDataError(f"{listing} lists {image_path.name}, but {image_path} does not exist (or is not a file)")
        try:
            image = imread(image_path)
        except Exception as err:   # Pillow / imageio raise many types on a damaged image
            raise EventDataError(f"{image_path}: not a readable image ({type(err).__name__}: {err}); the file is "
                                 "damaged: replace it or remove its line from images.txt") from None
        images.append(to_grey_uint8(image, image_path))
    shapes = {im.shape for im in images}
    if len(shapes) > 1:
        raise EventDataError(f"{listing}: the frames have different sizes {sorted(shapes)}; all must share one (H, W)")
    try:
        return Frames(np.stack(images), t, origin_ns / NS).sorted()
    except EventDataError as err:
        raise EventDataError(f"{listing}: {err}") from None


def _read_calib(path: Path) -> dict | list:
    values = np.loadtxt(path, ndmin=1).ravel().tolist()
    names = ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")
    return dict(zip(names, values)) if len(values) == len(names) else values


def read_ijrr_folder(folder, *, t_origin=None, sensor_size=None, time_unit="auto") -> Recording:
    """An IJRR / Event Camera Dataset sequence folder (the unzipped text release).

    Reads events.txt (p in {0, 1}), the frames of images.txt on the events' clock, and calib.txt
    (``meta["calib"] = {fx, fy, cx, cy, k1, k2, p1, p2, k3}``) when present. The sensor size is the
    frames' (H, W) (or a `W H` header of events.txt when there are no frames).

    Args:
        t_origin: seconds subtracted from all timestamps; None: whole seconds of the first event
            when the clock is absolute (>= 1e5 s), else 0.
        sensor_size: (H, W); needed only when there are no frames and no `W H` header (then the
            events' size is unknown); checked against the frames / header otherwise.
        time_unit: unit of the timestamps of events.txt and images.txt ('auto': see
            :func:`read_events_txt`).
    """
    folder = _existing(folder, "folder")
    events_path = folder / "events.txt"
    if not events_path.exists():
        raise EventDataError(f"{folder}: no events.txt; an IJRR folder holds events.txt, "
                             "images.txt, images/, calib.txt")
    raw = parse_event_text(events_path, None if t_origin is None else origin_to_ns(t_origin), time_unit=time_unit)
    check_time_span(raw.t, events_path, raw.time_unit)
    frames = (read_frames_ijrr(folder, t_origin=raw.origin_ns / NS, time_unit=raw.time_unit)
              if (folder / "images.txt").exists() else None)
    known = _sensor_from_header(events_path, raw.header, frames.size if frames is not None else None)
    if known is not None and sensor_size is not None and tuple(int(v) for v in sensor_size) != tuple(known):
        H, W = known
        raise EventDataError(f"{folder}: the frames (or header) say the sensor is (H, W) = {tuple(known)} ({H}x{W}) "
                             f"but sensor_size={tuple(int(v) for v in sensor_size)} was given; leave it out or pass "
                             f"sensor_size=({H}, {W})")
    sensor_size = known if known is not None else sensor_size
    if sensor_size is None:
        raise EventDataError(
            f"{folder}: no images.txt and no `W H` header in events.txt, so the sensor size is unknown; "
            f"pass sensor_size=(H, W){_size_hint(raw.x, raw.y)}"
        )
    events = _build_events(events_path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                           polarity="auto", t_origin=raw.origin_ns / NS)
    meta = {"format": "ijrr", "path": str(folder), "time_unit": raw.time_unit}
    if (folder / "calib.txt").is_file():
        try:
            meta["calib"] = _read_calib(folder / "calib.txt")
        except (ValueError, OSError) as err:
            raise EventDataError(f"{folder / 'calib.txt'}: not a list of numbers ({err}); repair or remove it") from None
    return Recording(events, frames, meta)


def _json_file(path: Path) -> dict:
    try:
        data = json.loads(read_text_bytes(path, "JSON file").decode("utf-8"))
    except UnicodeDecodeError as err:
        raise EventDataError(f"{path}: not UTF-8 text ({err}); save it as UTF-8 JSON") from None
    except json.JSONDecodeError as err:
        raise EventDataError(f"{path}: not valid JSON ({err}); expected e.g. {{\"sensor_resolution\": [H, W]}}") from None
    if not isinstance(data, dict):
        raise EventDataError(f"{path}: expected a JSON object such as {{\"sensor_resolution\": [H, W]}}, "
                             f"got {type(data).__name__}")
    return data


def _size_value(source, value, name) -> tuple[int, int]:
    """A stored (H, W) -> two positive ints, or an EventDataError naming where it came from."""
    try:
        a = np.asarray(value).ravel()
        if a.size != 2 or a.dtype.kind not in "iuf" or not np.all(np.isfinite(a)) or np.any(a != np.round(a)) \
                or np.any(a <= 0) or np.any(a > 1 << 20):
            raise ValueError
        return int(a[0]), int(a[1])
    except (ValueError, TypeError):
        raise EventDataError(f"{source}: {name} must be (H, W), two positive whole numbers; got {value!r}") from None


def read_evreal_folder(folder, *, time_unit="auto") -> Recording:
    """An EVREAL per-sequence folder of .npy files.

    Files: events_ts.npy [N] float64 s, events_xy.npy [N, 2] (x first), events_p.npy [N] in {0, 1}
    (or -1/+1), images.npy [F, H, W, 1] uint8, images_ts.npy [F], metadata.json
    {"sensor_resolution": [H, W]}, image_event_indices.npy (optional, kept in ``meta``).

    Args:
        time_unit: unit of events_ts.npy and images_ts.npy; 'auto': integers are microseconds (with a
            TimeUnitWarning), floats seconds.
    """
    folder = _existing(folder, "folder")
    needed = ("events_ts.npy", "events_xy.npy", "events_p.npy", "metadata.json")
    missing = [name for name in needed if not (folder / name).exists()]
    if missing:
        raise EventDataError(f"{folder}: missing {', '.join(missing)}; an EVREAL folder holds {', '.join(needed)} "
                             "(and images.npy, images_ts.npy for frames)")
    metadata = _json_file(folder / "metadata.json")
    if "sensor_resolution" not in metadata:
        raise EventDataError(f"{folder / 'metadata.json'}: no 'sensor_resolution'; add \"sensor_resolution\": [H, W]")
    sensor_size = _size_value(folder / "metadata.json", metadata["sensor_resolution"], "sensor_resolution")
    load = lambda name: _load_npy(_existing(folder / name))  # noqa: E731
    ts, xy, p = load("events_ts.npy"), load("events_xy.npy"), load("events_p.npy")
    if ts.ndim != 1 or ts.dtype.kind not in "iuf":
        raise EventDataError(f"{folder / 'events_ts.npy'}: expected a 1-D numeric array of timestamps, got shape "
                             f"{ts.shape} dtype {ts.dtype}")
    if xy.ndim != 2 or xy.shape[1] != 2 or xy.dtype.kind not in "iuf":
        raise EventDataError(f"{folder / 'events_xy.npy'}: expected a numeric array of shape [N, 2] (x, y), got "
                             f"{xy.shape} dtype {xy.dtype}")
    if p.dtype.kind not in "iufb":
        raise EventDataError(f"{folder / 'events_p.npy'}: expected numeric polarities, got dtype {p.dtype}")
    t, origin, unit = _seconds(folder / "events_ts.npy", ts, time_unit)
    events = _build_events(folder, t, xy[:, 0], xy[:, 1], p, sensor_size, polarity="auto", t_origin=origin)
    frames = None
    if (folder / "images.npy").exists():
        if not (folder / "images_ts.npy").exists():
            raise EventDataError(f"{folder}: images.npy without images_ts.npy; add the frame timestamps or remove "
                                 "images.npy")
        images, images_ts = load("images.npy"), load("images_ts.npy")
        if images_ts.ndim != 1 or images_ts.dtype.kind not in "iuf":
            raise EventDataError(f"{folder / 'images_ts.npy'}: expected a 1-D numeric array, got shape "
                                 f"{images_ts.shape} dtype {images_ts.dtype}")
        frame_t = np.asarray(images_ts, np.float64) * TIME_UNITS[unit] - origin
        try:
            frames = Frames(images, frame_t, origin).sorted()
        except EventDataError as err:
            raise EventDataError(f"{folder / 'images.npy'}: {err}") from None
        if frames.size != sensor_size:
            raise EventDataError(f"{folder}: frames are {frames.size} but sensor_resolution is "
                                 f"{sensor_size} (both (H, W))")
    meta = {"format": "evreal", "path": str(folder), "metadata": metadata, "time_unit": unit}
    if (folder / "image_event_indices.npy").exists():
        meta["image_event_indices"] = load("image_event_indices.npy")
    return Recording(events, frames, meta)


def _bisect_h5(ts, value_units: float, lo: int, hi: int) -> int:
    """First index in [lo, hi) with ts[i] >= value_units (file units), reading single elements from disk."""
    while lo < hi:
        mid = (lo + hi) // 2
        if float(ts[mid]) < value_units:
            lo = mid + 1
        else:
            hi = mid
    return lo


def _h5_damaged(path, err) -> EventDataError:
    return EventDataError(f"{path}: the HDF5 file is damaged or incomplete ({type(err).__name__}: {err}); copy or "
                          "convert it again")


def read_h5(path, *, t_start=None, t_end=None, time_unit="auto") -> Recording:
    """An HQF-style h5 file, optionally only the time window [t_start, t_end).

    Layout: events/xs, events/ys (int), events/ts (float64 s, sorted), events/ps (bool, 0/1 or
    -1/+1); images/image%09d (uint8) with attrs 'timestamp' (and 'event_idx'); root attr
    'sensor_resolution' (H, W).

    Args:
        t_start, t_end: seconds on the returned clock (file time minus ``t_origin``). The window
            is found by binary search on the ts dataset on disk and only that slice is read; frames
            are restricted to the same window. Frames come sorted by timestamp.
        time_unit: unit of events/ts and the frames' timestamps; 'auto': an integer dataset is
            microseconds (with a TimeUnitWarning), floats seconds.
    Raises:
        EventDataError for a missing, damaged or incomplete file, missing datasets or attributes.
    """
    import h5py

    path = _existing(path)
    try:
        f = h5py.File(path, "r")
    except OSError as err:
        raise _h5_damaged(path, err) from None
    try:
        with f:
            return _read_h5_open(f, path, t_start, t_end, time_unit)
    except EventDataError:
        raise
    except (OSError, KeyError, RuntimeError, TypeError, ValueError, IndexError) as err:
        raise _h5_damaged(path, err) from None


def _read_h5_open(f, path, t_start, t_end, time_unit) -> Recording:
    import h5py

    names = ("events/xs", "events/ys", "events/ts", "events/ps")
    missing = [n for n in names if n not in f or not isinstance(f[n], h5py.Dataset)]
    if missing:
        raise EventDataError(f"{path}: missing datasets {missing}; expected the HQF layout {list(names)}")
    if "sensor_resolution" not in f.attrs:
        raise EventDataError(f"{path}: no root attribute 'sensor_resolution' (H, W); add it, e.g. "
                             "h5py.File(path, 'r+').attrs['sensor_resolution'] = (H, W)")
    sensor_size = _size_value(path, f.attrs["sensor_resolution"], "the attribute sensor_resolution")
    ts = f["events/ts"]
    n = ts.shape[0] if ts.ndim == 1 else -1
    if any(f[name].shape != (n,) for name in names):
        raise EventDataError(f"{path}: {names} must be 1-D with the same length, got "
                             f"{[f[name].shape for name in names]}")
    for name in names:
        if f[name].dtype.kind not in "iufb":
            raise EventDataError(f"{path}: {name} must be numeric, got dtype {f[name].dtype}")
    unit = resolve_time_unit(ts.dtype.kind if n else "f", time_unit, f"{path}: events/ts")
    per_s = 1.0 / TIME_UNITS[unit]
    if n and not (math.isfinite(float(ts[0])) and math.isfinite(float(ts[n - 1]))):
        raise EventDataError(f"{path}: events/ts holds non-finite timestamps; the file is damaged")
    if n and ts.dtype.kind == "f" and ts.dtype.itemsize < 8:   # float32 on an absolute clock rounds to minutes
        step = float(np.spacing(np.abs(np.asarray([ts[0], ts[n - 1]], dtype=ts.dtype)).max())) / per_s
        if step > 1e-6:
            raise EventDataError(f"{path}: events/ts is {ts.dtype}, which at these values resolves only "
                                 f"{step:.3g} s; the timestamps were rounded when the file was written: write "
                                 "them as float64 (or integer microseconds)")
    origin = auto_origin(float(ts[0]) / per_s) if n else 0.0
    if t_start is not None and t_end is not None and t_end <= t_start:
        raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
    lo = 0 if t_start is None else _bisect_h5(ts, (t_start + origin) * per_s, 0, n)
    hi = n if t_end is None else _bisect_h5(ts, (t_end + origin) * per_s, lo, n)
    if hi <= lo:
        span = f"[{float(ts[0]) / per_s - origin:.6f}, {float(ts[n - 1]) / per_s - origin:.6f}] s" if n else "nothing"
        raise EventDataError(f"{path}: no events in the window [{t_start}, {t_end}) s; the events cover "
                             f"{span} (relative to t_origin = {origin}); choose a window inside that range")
    raw_t = ts[lo:hi]
    if raw_t.dtype.kind in "iu":
        t = (raw_t.astype(np.int64) - int(round(origin * per_s))) / per_s
    else:
        t = raw_t.astype(np.float64) / per_s - origin
    check_time_span(t, f"{path}: events/ts", unit)
    x, y, p = (f[name][lo:hi] for name in ("events/xs", "events/ys", "events/ps"))
    events = _build_events(path, t, x, y, p, sensor_size, polarity="auto", t_origin=origin)

    frames, meta = None, {"format": "h5", "path": str(path), "attrs": {k: _plain(v) for k, v in f.attrs.items()},
                          "event_slice": (lo, hi), "time_unit": unit}
    if "images" in f and isinstance(f["images"], h5py.Group) and len(f["images"]):
        group = f["images"]
        keys = np.array(sorted(group))
        stamps = []
        for k in keys:
            value = group[k].attrs.get("timestamp")
            try:
                stamp = float(np.asarray(value).reshape(()))
            except (TypeError, ValueError):
                raise EventDataError(f"{path}: images/{k} has no numeric 'timestamp' attribute (got {value!r}); "
                                     "every frame needs one") from None
            if not math.isfinite(stamp):
                raise EventDataError(f"{path}: images/{k} has a non-finite 'timestamp'; repair or remove that frame")
            stamps.append(stamp)
        stamps = np.array(stamps) / per_s - origin
        keep = np.ones(len(keys), dtype=bool)
        if t_start is not None:
            keep &= stamps >= t_start
        if t_end is not None:
            keep &= stamps < t_end
        order = np.argsort(stamps[keep], kind="stable")  # one HQF sequence has a frame out of order
        keys, stamps = keys[keep][order], stamps[keep][order]
        if len(keys):
            images = [to_grey_uint8(group[k][()], f"{path}:images/{k}") for k in keys]
            if len({im.shape for im in images}) > 1:
                raise EventDataError(f"{path}: the frames have different sizes {sorted({im.shape for im in images})}")
            frames = Frames(np.stack(images), stamps, origin)
            if frames.size != sensor_size:
                raise EventDataError(f"{path}: frames are {frames.size} but sensor_resolution is "
                                     f"{sensor_size} (both (H, W))")
            if all("event_idx" in group[k].attrs for k in keys):  # indices into the file's events
                meta["frame_event_idx"] = np.array([int(np.asarray(group[k].attrs["event_idx"]).reshape(()))
                                                    for k in keys])
    return Recording(events, frames, meta)


def _plain(value):
    """An HDF5 attribute as a plain value (bytes decoded)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    return value


def _looks_like_event_text(path: Path) -> bool:
    """True when the first lines of a file are `t x y p` numbers (after an optional `W H` line)."""
    with open(path, "rb") as f:
        head = f.read(4096)
    try:
        lines = [line.split() for line in head.decode("ascii").splitlines()[:3] if line.strip()]
    except UnicodeDecodeError:
        return False
    if lines and len(lines[0]) == 2:
        lines = lines[1:]
    if not lines or len(lines[0]) != 4:
        return False
    try:
        [float(v) for v in lines[0]]
    except ValueError:
        return False
    return True


def detect_format(path) -> str:
    """The format of a recording, from its content first and its name second.

    Returns one of "ijrr", "evreal" (folders), "canonical", "h5", "aedat4", "prophesee_raw",
    "prophesee_dat", "txt", "npy". Raises EventDataError naming the supported formats otherwise.
    """
    from .formats import sniff_format

    import stat

    if isinstance(path, (str, bytes)) and not path.strip():   # Path("") is ".", the current folder
        raise EventDataError("the recording's path is empty; pass the file or folder to read")
    path = Path(path)
    if not path.exists():
        raise EventDataError(f"no such file or folder: {path}; check the path")
    try:
        mode = path.stat().st_mode
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read ({err.strerror})") from None
    if not (stat.S_ISDIR(mode) or stat.S_ISREG(mode)):
        raise EventDataError(f"{path} is not a regular file or folder (a FIFO, pipe or device); save the recording "
                             "to a file first")
    if path.is_dir():
        if not os.access(path, os.R_OK | os.X_OK):
            raise EventDataError(f"{path}: no permission to read this folder")
        if (path / "events.txt").exists():
            return "ijrr"
        if (path / "events_ts.npy").exists():
            return "evreal"
        raise EventDataError(f"{path}: folder of unknown format (no events.txt or events_ts.npy); "
                             f"supported formats: {SUPPORTED_FORMATS}")
    suffix = path.suffix.lower()
    if path.stat().st_size == 0:
        raise EventDataError(f"{path} is empty (0 bytes); the file was not written completely: copy it again")
    try:
        kind = sniff_format(path)
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read ({err.strerror}); check its permissions") from None
    if kind == "hdf5":
        from .canonical import is_canonical

        return "canonical" if is_canonical(path) else "h5"
    if kind in ("aedat4", "npy", "prophesee_raw", "prophesee_dat"):
        return kind
    if kind in ("aedat2", "aedat3"):
        raise EventDataError(f"{path}: an {kind.upper()} file; only AEDAT4 is read: convert it with iniVation's "
                             "DV software (Convert to AEDAT4) or export the events to a `t x y p` text file")
    if kind == "zip":
        raise EventDataError(f"{path}: a zip archive; unzip it first and pass the folder (IJRR / EVREAL) or "
                             "the file inside")
    if suffix == ".txt" or _looks_like_event_text(path):
        return "txt"
    raise EventDataError(f"{path}: unknown format {suffix or '(no extension)'!r} (and its content is none of "
                         f"the known ones); supported formats: {SUPPORTED_FORMATS}")


def read_recording(path, **kwargs) -> Recording:
    """Read any supported recording; the format is detected by :func:`detect_format`.

    IJRR folder -> :func:`read_ijrr_folder`; EVREAL folder -> :func:`read_evreal_folder`; HDF5 ->
    the canonical data_fetch format (:func:`evinr_lite.io.canonical.read_canonical`) or HQF-style
    :func:`read_h5`; AEDAT4 -> :func:`evinr_lite.io.formats.read_aedat4`; Prophesee .raw / .dat ->
    :func:`evinr_lite.io.formats.read_prophesee`; `t x y p` text -> :func:`read_events_txt`;
    .npy -> :func:`read_events_npy` (the last two without frames). ``kwargs`` go to that reader.
    ``meta["format"]`` names the format read.
    """
    kind = detect_format(path)
    path = Path(path)
    if kind == "ijrr":
        return read_ijrr_folder(path, **kwargs)
    if kind == "evreal":
        return read_evreal_folder(path, **kwargs)
    if kind == "canonical":
        from .canonical import read_canonical

        return read_canonical(path, **kwargs)
    if kind == "h5":
        return read_h5(path, **kwargs)
    if kind == "aedat4":
        from .formats import read_aedat4

        return read_aedat4(path, **kwargs)
    if kind in ("prophesee_raw", "prophesee_dat"):
        from .formats import read_prophesee

        return read_prophesee(path, **kwargs)
    if kind == "txt":
        return Recording(read_events_txt(path, **kwargs), None, {"format": "txt", "path": str(path)})
    return Recording(read_events_npy(path, **kwargs), None, {"format": "npy", "path": str(path)})


def read_events(path, **kwargs) -> Events:
    """Only the events of :func:`read_recording`."""
    return read_recording(path, **kwargs).events
