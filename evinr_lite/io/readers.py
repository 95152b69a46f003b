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
from pathlib import Path

import numpy as np

from ..core.events import EventDataError, Events, auto_origin, relative_seconds
from ..core.frames import Frames, to_grey_uint8
from ..core.recording import Recording
from .text import NS, origin_to_ns, parse_event_text, parse_frame_list

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
    path = Path(path)
    if not path.exists():
        raise EventDataError(f"no such {kind}: {path}; check the path")
    return path


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

def read_events_npy(path, sensor_size=None, *, columns="txyp", polarity="auto", time_unit="s",
                    sort=False) -> Events:
    """Events from an .npy array [N, 4].

    Args:
        path: .npy file holding an [N, 4] numeric array.
        sensor_size: (H, W); required (an .npy array does not record it).
        columns: order of the columns, a permutation of 'txyp' (e.g. 'xytp' for MVSEC).
        polarity: encoding of p, see :func:`~evinr_lite.core.events.normalize_polarity`.
        time_unit: unit of t: 's', 'ms', 'us' or 'ns'.
        sort: sort the events by time instead of raising on unsorted input.
    """
    path = _existing(path)
    try:
        a = np.load(path, allow_pickle=False)
    except ValueError as err:
        raise EventDataError(f"{path}: not a plain numeric .npy array ({err}); "
                             "save it with np.save(path, array)") from None
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
    t, origin = relative_seconds(col["t"], time_unit)
    return _build_events(path, t, col["x"], col["y"], col["p"], sensor_size,
                         polarity=polarity, t_origin=origin, sort=sort)


def read_events_txt(path, sensor_size=None, *, polarity="auto", t_origin=None) -> Events:
    """Events from a text file of `t x y p` lines (IJRR events.txt, rpg_e2vid .txt).

    Args:
        path: text file; t in seconds, x column, y row, p polarity. An optional first line `W H`
            (two integers, width first: the rpg_e2vid header) gives the sensor size.
        sensor_size: (H, W); required unless the file has the header (then they must agree).
        polarity: encoding of p ('auto', '01', 'pm1').
        t_origin: seconds subtracted from every timestamp (exactly). None: the whole seconds of the
            first timestamp when it is >= 1e5 s (an absolute clock), else 0.
    """
    path = _existing(path)
    raw = parse_event_text(path, None if t_origin is None else origin_to_ns(t_origin))
    sensor_size = _sensor_from_header(path, raw.header, sensor_size)
    if sensor_size is None:
        raise EventDataError(
            f"{path}: the sensor size is unknown (no `W H` header line); pass sensor_size=(H, W) "
            f"(rows, columns){_size_hint(raw.x, raw.y)}"
        )
    return _build_events(path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                         polarity=polarity, t_origin=raw.origin_ns / NS)


def read_frames_ijrr(folder, t_origin=0.0) -> Frames:
    """Frames listed in ``folder/images.txt`` (`t images/frame_%08d.png` per line), in time order.

    Args:
        folder: the IJRR sequence folder.
        t_origin: seconds subtracted exactly from the timestamps (pass the events' ``t_origin``);
            None: automatic, as for the events.
    Returns:
        Frames with grey uint8 images [F, H, W] (RGB is converted to grey).
    """
    from skimage.io import imread

    folder = _existing(folder, "folder")
    listing = folder / "images.txt"
    if not listing.exists():
        raise EventDataError(f"{folder}: no images.txt, so no frames; expected lines `t images/frame_%08d.png`")
    t, names, origin_ns = parse_frame_list(listing.read_bytes(), None if t_origin is None else origin_to_ns(t_origin),
                                           source=listing)
    if not names:
        raise EventDataError(f"{listing} lists no frames; expected lines `t images/frame_%08d.png`")
    images = []
    for name in names:
        image_path = folder / name
        if not image_path.exists():
            raise EventDataError(f"{listing} lists {image_path.name}, but {image_path} does not exist")
        images.append(to_grey_uint8(imread(image_path), image_path))
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


def read_ijrr_folder(folder, *, t_origin=None) -> Recording:
    """An IJRR / Event Camera Dataset sequence folder (the unzipped text release).

    Reads events.txt (p in {0, 1}), the frames of images.txt on the events' clock, and calib.txt
    (``meta["calib"] = {fx, fy, cx, cy, k1, k2, p1, p2, k3}``) when present. The sensor size is the
    frames' (H, W) (or a `W H` header of events.txt when there are no frames).

    Args:
        t_origin: seconds subtracted from all timestamps; None: whole seconds of the first event
            when the clock is absolute (>= 1e5 s), else 0.
    """
    folder = _existing(folder, "folder")
    events_path = folder / "events.txt"
    if not events_path.exists():
        raise EventDataError(f"{folder}: no events.txt; an IJRR folder holds events.txt, "
                             "images.txt, images/, calib.txt")
    raw = parse_event_text(events_path, None if t_origin is None else origin_to_ns(t_origin))
    frames = read_frames_ijrr(folder, t_origin=raw.origin_ns / NS) if (folder / "images.txt").exists() else None
    sensor_size = _sensor_from_header(events_path, raw.header, frames.size if frames is not None else None)
    if sensor_size is None:
        raise EventDataError(
            f"{folder}: no images.txt and no `W H` header in events.txt, so the sensor size is unknown; "
            f"read the events with read_events_txt(path, sensor_size=(H, W)){_size_hint(raw.x, raw.y)}"
        )
    events = _build_events(events_path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                           polarity="01", t_origin=raw.origin_ns / NS)
    meta = {"format": "ijrr", "path": str(folder)}
    if (folder / "calib.txt").exists():
        meta["calib"] = _read_calib(folder / "calib.txt")
    return Recording(events, frames, meta)


def read_evreal_folder(folder) -> Recording:
    """An EVREAL per-sequence folder of .npy files.

    Files: events_ts.npy [N] float64 s, events_xy.npy [N, 2] (x first), events_p.npy [N] in {0, 1},
    images.npy [F, H, W, 1] uint8, images_ts.npy [F], metadata.json {"sensor_resolution": [H, W]},
    image_event_indices.npy (optional, kept in ``meta``).
    """
    folder = _existing(folder, "folder")
    needed = ("events_ts.npy", "events_xy.npy", "events_p.npy", "metadata.json")
    missing = [name for name in needed if not (folder / name).exists()]
    if missing:
        raise EventDataError(f"{folder}: missing {', '.join(missing)}; an EVREAL folder holds {', '.join(needed)} "
                             "(and images.npy, images_ts.npy for frames)")
    metadata = json.loads((folder / "metadata.json").read_text())
    if "sensor_resolution" not in metadata:
        raise EventDataError(f"{folder / 'metadata.json'}: no 'sensor_resolution'; add \"sensor_resolution\": [H, W]")
    sensor_size = tuple(int(v) for v in metadata["sensor_resolution"])
    load = lambda name: np.load(folder / name, allow_pickle=False)  # noqa: E731
    ts, xy, p = load("events_ts.npy"), load("events_xy.npy"), load("events_p.npy")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise EventDataError(f"{folder / 'events_xy.npy'}: expected shape [N, 2] (x, y), got {xy.shape}")
    t, origin = relative_seconds(ts, "s")
    events = _build_events(folder, t, xy[:, 0], xy[:, 1], p, sensor_size, polarity="01", t_origin=origin)
    frames = None
    if (folder / "images.npy").exists():
        images, images_ts = load("images.npy"), load("images_ts.npy")
        try:
            frames = Frames(images, np.asarray(images_ts, np.float64) - origin, origin).sorted()
        except EventDataError as err:
            raise EventDataError(f"{folder / 'images.npy'}: {err}") from None
        if frames.size != sensor_size:
            raise EventDataError(f"{folder}: frames are {frames.size} but sensor_resolution is "
                                 f"{sensor_size} (both (H, W))")
    meta = {"format": "evreal", "path": str(folder), "metadata": metadata}
    if (folder / "image_event_indices.npy").exists():
        meta["image_event_indices"] = load("image_event_indices.npy")
    return Recording(events, frames, meta)


def _bisect_h5(ts, value: float, origin: float, lo: int, hi: int) -> int:
    """First index in [lo, hi) with ts[i] - origin >= value, reading single elements from disk."""
    while lo < hi:
        mid = (lo + hi) // 2
        if float(ts[mid]) - origin < value:
            lo = mid + 1
        else:
            hi = mid
    return lo


def read_h5(path, *, t_start=None, t_end=None) -> Recording:
    """An HQF-style h5 file, optionally only the time window [t_start, t_end).

    Layout: events/xs, events/ys (int), events/ts (float64 s, sorted), events/ps (bool);
    images/image%09d (uint8) with attrs 'timestamp' (and 'event_idx'); root attr
    'sensor_resolution' (H, W).

    Args:
        t_start, t_end: seconds on the returned clock (file time minus ``t_origin``). The window
            is found by binary search on the ts dataset on disk and only that slice is read; frames
            are restricted to the same window. Frames come sorted by timestamp.
    """
    import h5py

    path = _existing(path)
    with h5py.File(path, "r") as f:
        names = ("events/xs", "events/ys", "events/ts", "events/ps")
        missing = [n for n in names if n not in f]
        if missing:
            raise EventDataError(f"{path}: missing datasets {missing}; expected the HQF layout {list(names)}")
        if "sensor_resolution" not in f.attrs:
            raise EventDataError(f"{path}: no root attribute 'sensor_resolution' (H, W); add it, e.g. "
                                 "h5py.File(path, 'r+').attrs['sensor_resolution'] = (H, W)")
        sensor_size = tuple(int(v) for v in f.attrs["sensor_resolution"])
        ts = f["events/ts"]
        n = ts.shape[0]
        if any(f[name].shape != (n,) for name in names):
            raise EventDataError(f"{path}: {names} must be 1-D with the same length, got "
                                 f"{[f[name].shape for name in names]}")
        origin = auto_origin(float(ts[0])) if n else 0.0
        if t_start is not None and t_end is not None and t_end <= t_start:
            raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
        lo = 0 if t_start is None else _bisect_h5(ts, t_start, origin, 0, n)
        hi = n if t_end is None else _bisect_h5(ts, t_end, origin, lo, n)
        if hi <= lo:
            span = f"[{float(ts[0]) - origin:.6f}, {float(ts[n - 1]) - origin:.6f}] s" if n else "nothing"
            raise EventDataError(f"{path}: no events in the window [{t_start}, {t_end}) s; the events cover "
                                 f"{span} (relative to t_origin = {origin}); choose a window inside that range")
        t = ts[lo:hi].astype(np.float64) - origin
        x, y, p = (f[name][lo:hi] for name in ("events/xs", "events/ys", "events/ps"))
        events = _build_events(path, t, x, y, p, sensor_size, polarity="bool", t_origin=origin)

        frames, meta = None, {"format": "h5", "path": str(path), "attrs": dict(f.attrs), "event_slice": (lo, hi)}
        if "images" in f and len(f["images"]):
            group = f["images"]
            keys = np.array(sorted(group))
            stamps = np.array([float(group[k].attrs["timestamp"]) for k in keys]) - origin
            keep = np.ones(len(keys), dtype=bool)
            if t_start is not None:
                keep &= stamps >= t_start
            if t_end is not None:
                keep &= stamps < t_end
            order = np.argsort(stamps[keep], kind="stable")  # one HQF sequence has a frame out of order
            keys, stamps = keys[keep][order], stamps[keep][order]
            if len(keys):
                images = np.stack([to_grey_uint8(group[k][()], f"{path}:images/{k}") for k in keys])
                frames = Frames(images, stamps, origin)
                if frames.size != sensor_size:
                    raise EventDataError(f"{path}: frames are {frames.size} but sensor_resolution is "
                                         f"{sensor_size} (both (H, W))")
                if all("event_idx" in group[k].attrs for k in keys):  # indices into the file's events
                    meta["frame_event_idx"] = np.array([int(group[k].attrs["event_idx"]) for k in keys])
    return Recording(events, frames, meta)


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

    path = Path(path)
    if not path.exists():
        raise EventDataError(f"no such file or folder: {path}; check the path")
    if path.is_dir():
        if (path / "events.txt").exists():
            return "ijrr"
        if (path / "events_ts.npy").exists():
            return "evreal"
        raise EventDataError(f"{path}: folder of unknown format (no events.txt or events_ts.npy); "
                             f"supported formats: {SUPPORTED_FORMATS}")
    suffix = path.suffix.lower()
    kind = sniff_format(path)
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
    path = Path(path)
    kind = detect_format(path)
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
