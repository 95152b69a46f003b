"""Loading a recording for a job: any format, the sensor size supplied or checked, the time unit
passed where the format allows it, a time window; and what a recording holds, for ``evinr-lite info``.

The options each format takes come from its declaration (:mod:`evinr_lite.io.formats`), so adding a
format needs no change here. Times are seconds on the recording's clock: relative to its
``t_origin`` (the whole seconds of the first event on an absolute clock, else 0).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..core.checks import require, short_repr
from ..core.events import EventDataError, check_sensor_size
from ..core.frames import Frames
from ..core.recording import Recording
from .formats.base import FileFormat, check_frame_times, same_time_message
from .formats.registry import (FIXED_UNITS, READER_WINDOW_FORMATS, SENSOR_ARG_FORMATS, SIZE_FREE_FORMATS,
                               TIME_UNIT_FORMATS, detect_format, get_format, recording_path)
from .source import MemorySource, RecordingSource

__all__ = ["open_recording", "read_any", "load_recording", "describe_recording", "format_info", "reader_options",
           "check_sensor_size_matches", "SIZE_FREE_FORMATS", "READER_WINDOW_FORMATS", "SENSOR_ARG_FORMATS",
           "TIME_UNIT_FORMATS", "FIXED_UNITS", "INFO_SAMPLE_EVENTS"]

INFO_SAMPLE_EVENTS = 2_000_000   # info reads at most about this many events (evenly spread) for the polarity balance


def reader_options(fmt: FileFormat, path, sensor_size=None, time_unit: str | None = None,
                   camera: str | None = None) -> dict:
    """The keyword options for ``fmt``'s reader: ``sensor_size`` where the reader takes it, ``time_unit``
    where the format does not fix it (a different unit for a format that fixes its own is refused), and
    ``camera`` for a format with more than one camera in a file (MVSEC's stereo pair; refused for the others)."""
    require(fmt, FileFormat, "fmt")   # a name or None: "has no attribute 'takes_sensor_size'"; pass get_format(name)
    options = {}
    if camera is not None:
        if "camera" not in fmt.options:
            raise EventDataError(f"{path}: a {fmt.name} recording holds one camera, so camera={camera!r} cannot "
                                 "apply (it picks the left or right camera of an MVSEC stereo file); leave camera= out")
        options["camera"] = camera
    if fmt.takes_sensor_size and sensor_size is not None:
        options["sensor_size"] = sensor_size
    if time_unit is not None:
        if fmt.time_unit is None and "time_unit" in fmt.options:
            options["time_unit"] = time_unit
        elif fmt.time_unit != time_unit:
            raise EventDataError(f"{path}: a {fmt.name} file stores its timestamps in {fmt.time_unit or 's'} "
                                 f"by its format, so time_unit={time_unit!r} cannot apply; leave time_unit= out")
    return options


def check_sensor_size_matches(path, found, sensor_size) -> None:
    """Refuse a ``sensor_size`` argument that differs from the recording's (H, W) (or that is no (H, W): 5, "a", NaN
    were Python's errors, (12.5, W) taken as 12 rows)."""
    try:   # found comes from the recording (its source's or events' sensor size): a bad one is named as found=
        found = check_sensor_size(found)
    except EventDataError:
        raise EventDataError(f"{path}: check_sensor_size_matches: found= (the recording's sensor size) must be (H, W), "
                             f"two positive whole numbers, got {short_repr(found)}") from None
    if sensor_size is not None and check_sensor_size(sensor_size) != found:
        H, W = found
        raise EventDataError(f"{path}: the recording's sensor is (H, W) = {tuple(found)} ({H}x{W}) but "
                             f"sensor size {tuple(int(v) for v in sensor_size)} was given; leave it out or pass {H}x{W}")


def open_recording(path, *, sensor_size=None, time_unit: str | None = None, camera: str | None = None,
                   **options) -> RecordingSource:
    """Open a recording (any format :func:`~evinr_lite.io.detect_format` knows) for reading window by window.

    Args:
        path: file or folder.
        sensor_size: (H, W); supplied to formats that may not record it, checked against the others.
        time_unit: unit of the timestamps for formats that do not fix it ('s', 'ms', 'us', 'ns'; None:
            the reader's detection); refused for formats that fix theirs.
        camera: 'left' or 'right' for an MVSEC stereo file (None: its left camera, or the one it has);
            refused for formats with one camera.
        options: the format's other reader options (e.g. ``columns=`` for .npy).
    Formats that can read a window without the rest (memory-mapped .npy, canonical, HQF, DSEC and MVSEC h5, AEDAT4
    and Prophesee packets) do so; the others (text, IJRR and EVREAL folders) are read once and sliced.
    """
    path = recording_path(path)
    fmt = get_format(detect_format(path))
    options = {**reader_options(fmt, path, sensor_size, time_unit, camera), **options}
    if fmt.open_source is not None:
        source = fmt.open_source(Path(path), **options)
    else:
        recording = fmt.reader(Path(path), **options)
        source = MemorySource(recording.events, recording.frames, recording.meta, path=path,
                              format=recording.meta.get("format", fmt.name))
    try:
        check_sensor_size_matches(path, source.sensor_size, sensor_size)
        first, last = (float(v) for v in source.t_span)
        if not (math.isfinite(first) and math.isfinite(last) and first <= last):
            # what a source reads cheaply (its first and last timestamps) already shows a damaged file
            what = "non-finite" if not (math.isfinite(first) and math.isfinite(last)) else "not sorted"
            raise EventDataError(f"{path}: the timestamps are damaged ({what}): the first event is at {first!r} s "
                                 f"and the last at {last!r} s, where they must be finite and increasing; "
                                 "re-export the recording, or convert the original with python -m data_fetch convert RAW")
        if source.n_events is not None and source.n_events >= 2 and first == last:   # formats whose reader cannot tell
            raise EventDataError(same_time_message(path, source.n_events, first))
        check_frame_times(source.frames, path)
    except EventDataError:
        source.close()
        raise
    return source


def read_any(path, *, sensor_size=None, t_start: float | None = None, t_end: float | None = None,
             time_unit: str | None = None, camera: str | None = None) -> Recording:
    """Read a recording of any supported format, the sensor size checked or supplied.

    Args:
        path: file or folder; the format is detected (:func:`evinr_lite.io.detect_format`).
        sensor_size: (H, W). Needed for formats that do not record it (.npy, text without a
            `W H` header, a .csv without `%geometry`, a DSEC .h5, an MVSEC .hdf5 without frames, an
            IJRR folder without images.txt, some Prophesee .raw); for the others it must match the file's.
        t_start, t_end: passed to readers that read only a window from disk (the others read all).
        time_unit: unit of the timestamps for formats that do not fix it (.npy, text, .csv, IJRR, EVREAL,
            HQF h5): 's', 'ms', 'us', 'ns'; None: the reader's detection (integers are taken as
            microseconds, with a warning). For AEDAT4 / Prophesee (microseconds) and canonical files
            (seconds) a different unit is refused.
        camera: 'left' or 'right' for an MVSEC stereo file (None: its left camera, or the one it has);
            refused for formats with one camera.
    Raises:
        EventDataError: missing file, unknown format, wrong or missing sensor size, a time unit the
            format does not allow.
    """
    path = recording_path(path)
    fmt = get_format(detect_format(path))
    kwargs = reader_options(fmt, path, sensor_size, time_unit, camera)
    if fmt.windowed:
        kwargs.update(t_start=t_start, t_end=t_end)
    rec = fmt.reader(Path(path), **kwargs)
    check_sensor_size_matches(path, rec.events.sensor_size, sensor_size)
    return Recording(rec.events, rec.frames, {**rec.meta, "format": rec.meta.get("format", fmt.name)})


def load_recording(path, *, sensor_size=None, t_start: float | None = None, t_end: float | None = None,
                   time_unit: str | None = None, camera: str | None = None) -> Recording:
    """Read a recording (any supported format) restricted to the window [t_start, t_end).

    Args:
        path, sensor_size, time_unit, camera: see :func:`read_any`.
        t_start, t_end: seconds on the recording's clock; None: from the first / to the last event.
    Returns:
        Recording whose events lie in the window and whose frames lie in [start, end], the span
        to reconstruct, stored as ``meta["window"]`` = (start, end) seconds.
    Raises:
        EventDataError: missing file, unknown format, wrong sensor size, empty window (each
            message says what to do).
    """
    for name, value in (("t_start", t_start), ("t_end", t_end)):
        if value is not None and not math.isfinite(value):
            raise EventDataError(f"{name}= must be a finite number of seconds, got {value}")
    # One window rule for every format, here rather than per reader: events in [start, end), frames in
    # [start, end]. Readers that read only a window from disk are asked for a little more (a frame
    # exactly at t_end included) and everything is cut here.
    reader_end = None if t_end is None else math.nextafter(float(t_end), math.inf)
    rec = read_any(path, sensor_size=sensor_size, t_start=t_start, t_end=reader_end, time_unit=time_unit,
                   camera=camera)
    events, frames = rec.events, rec.frames
    events = events.slice_time(t_start, t_end)
    if len(events) < 2:
        raise EventDataError(f"{path}: only {len(events)} event(s) in the window [{t_start}, {t_end}) s; "
                             "choose a longer window (see `evinr-lite info` for the time span)")
    if events.t[0] == events.t[-1]:   # sorted: every event at one instant
        window = None if t_start is None and t_end is None else (t_start, t_end)
        raise EventDataError(same_time_message(path, len(events), float(events.t[0]), window))
    check_frame_times(frames, path)
    start = float(events.t[0]) if t_start is None else float(t_start)
    end = float(events.t[-1]) if t_end is None else float(t_end)
    if frames is not None:  # only frames the events can reach: inside [start, end]
        keep = (frames.t >= start) & (frames.t <= end)
        frames = Frames(frames.images[keep], frames.t[keep], frames.t_origin) if keep.any() else None
    return Recording(events, frames, {**rec.meta, "window": (start, end)})


def _on_fraction(source: RecordingSource) -> tuple[float | None, int]:
    """(fraction of ON events, events looked at): all of them up to INFO_SAMPLE_EVENTS, else 16 evenly
    spread windows holding about that many in all (so info on a multi-GB file reads a few MB)."""
    n = source.n_events
    t0, t1 = source.t_span
    if n == 0:
        return None, 0
    end = math.nextafter(t1, math.inf)
    if n is not None and n <= INFO_SAMPLE_EVENTS:
        edges = [(t0, end)]
    else:
        width = (t1 - t0) * INFO_SAMPLE_EVENTS / n / 16
        edges = [(a, min(a + width, end)) for a in np.linspace(t0, t1 - width, 16)]
    on = seen = 0
    for a, b in edges:
        if b > a:
            part = source.events(a, b)
            on += int(np.count_nonzero(part.p > 0))
            seen += len(part)
    return (on / seen if seen else None), seen


def describe_recording(rec) -> dict:
    """What a recording holds: format, sensor, time span, event count and rate, polarity balance,
    frames. Times are seconds on the recording's clock (relative to ``t_origin``).

    ``rec`` is a :class:`Recording`, or a :class:`~evinr_lite.io.source.RecordingSource` (from
    :func:`~evinr_lite.io.open_recording`): then only what the format can tell cheaply is read (the
    count and span from the file's structure, the polarity balance from a sample of at most
    :data:`INFO_SAMPLE_EVENTS` events, reported as ``on_fraction_events``), so a multi-GB file
    answers in seconds.
    """
    if isinstance(rec, RecordingSource):
        source, frames, meta = rec, rec.frames, rec.meta
        n, (first, last) = source.n_events, source.t_span
        on_fraction, looked = _on_fraction(source)
        H, W = source.sensor_size
        t_origin = source.t_origin
    else:
        ev, frames, meta = rec.events, rec.frames, rec.meta
        n = len(ev)
        first, last = (float(ev.t[0]), float(ev.t[-1])) if n else (None, None)
        on_fraction, looked = (float(np.mean(ev.p > 0)) if n else None), n
        H, W = ev.sensor_size
        t_origin = ev.t_origin
    duration = float(last - first) if n and n > 1 else 0.0
    info = {
        "format": meta.get("format"), "path": meta.get("path"),
        "sensor_size": [H, W], "t_origin": t_origin,
        "t_first": first if n else None, "t_last": last if n else None,
        "duration_s": duration, "n_events": n,
        "event_rate_per_s": n / duration if n and duration > 0 else None,
        "events_per_pixel": n / (H * W) if n is not None else None,
        "on_fraction": on_fraction,
        "n_frames": 0,
    }
    if n is not None and looked < n:
        info["on_fraction_events"] = looked
    if frames is not None and len(frames):
        fr = frames
        info.update(n_frames=len(fr), frame_size=list(fr.size), frames_t_first=float(fr.t[0]),
                    frames_t_last=float(fr.t[-1]),
                    frame_rate_per_s=(len(fr) - 1) / float(fr.t[-1] - fr.t[0]) if len(fr) > 1 and fr.t[-1] > fr.t[0] else None)
    for key in ("C", "eval_window", "dataset", "sequence", "encoding", "device", "frames_skipped", "cfa", "read_notes"):
        if meta.get(key) is not None:
            value = meta[key]
            info[key] = list(value) if isinstance(value, tuple) else value
    return info


def _origin_text(t_origin) -> str:
    """t_origin in full: a canonical file's origin may have a fraction (1500000000.123456), which
    ``:.0f`` rounded away, so that the printed origin plus the printed times missed the absolute clock."""
    return np.format_float_positional(float(t_origin), trim="-")


_INFO_KEYS = ("format", "path", "sensor_size", "n_events", "n_frames")
_EVENT_KEYS = ("event_rate_per_s", "t_first", "t_last", "duration_s", "t_origin", "on_fraction")
_FRAME_KEYS = ("frame_size", "frames_t_first", "frames_t_last")


def _info_keys(info) -> list:
    """The keys :func:`format_info` reads without .get: the events' keys when there are events, the frames' keys
    when there are frames."""
    keys = list(_INFO_KEYS)
    if info.get("n_events"):
        keys += _EVENT_KEYS
    if info.get("n_frames"):
        keys += _FRAME_KEYS
    return keys


def format_info(info: dict) -> str:
    """Human-readable lines for :func:`describe_recording`'s dict."""
    if not isinstance(info, Mapping):
        raise EventDataError("format_info: info= must be the dict describe_recording(rec) returns (rec: a Recording "
                             f"or a RecordingSource), got {short_repr(info)}")
    missing = [k for k in _info_keys(info) if k not in info]
    if missing:
        raise EventDataError("format_info: info= must be the dict describe_recording(rec) returns (rec: a Recording "
                             f"or a RecordingSource); it has no {', '.join(repr(k) for k in missing)}")
    H, W = info["sensor_size"]
    lines = [f"format        {info['format']}  ({info['path']})",
             f"sensor        {H}x{W} (H x W)"]
    if info["n_events"]:
        rate = info["event_rate_per_s"]
        sampled = (f" (from {info['on_fraction_events']:,} events spread over the recording)"
                   if "on_fraction_events" in info else "")
        lines += [f"events        {info['n_events']:,}" + (f"  ({rate:,.0f} per s, {rate / (H * W):.2f} per pixel "
                                                             "per s)" if rate else ""),
                  f"time span     {info['t_first']:.6f} .. {info['t_last']:.6f} s  ({info['duration_s']:.6f} s; "
                  f"times relative to t_origin = {_origin_text(info['t_origin'])} s)"]
        if info["on_fraction"] is not None:
            lines.append(f"polarity      {100 * info['on_fraction']:.1f}% ON, {100 * (1 - info['on_fraction']):.1f}% "
                         f"OFF{sampled}")
    else:
        lines.append("events        none")
    if info["n_frames"]:
        fr = info.get("frame_rate_per_s")
        lines.append(f"frames        {info['n_frames']} of {info['frame_size'][0]}x{info['frame_size'][1]}, "
                     f"{info['frames_t_first']:.6f} .. {info['frames_t_last']:.6f} s"
                     + (f" ({fr:.1f} per s)" if fr else "") + "  -> reconstructions are scored against them")
    else:
        lines.append("frames        none (nothing to score against)")
    for key in ("C", "eval_window", "dataset", "sequence", "encoding", "device", "cfa"):
        if key in info:
            lines.append(f"{key:<13} {info[key]}")
    if info.get("frames_skipped"):
        lines.append(f"note          {info['frames_skipped']} frame(s) skipped: a region of interest or a colour filter")
    for text in info.get("read_notes", ()):
        lines.append(f"note          {text}")
    return "\n".join(lines)
