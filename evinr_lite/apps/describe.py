"""What a recording holds, read without torch: ``evinr-lite info`` imports only this, io and core.

:func:`read_any` reads any supported format with the sensor size and time unit checked;
:func:`describe_recording` and :func:`format_info` say what it holds. The reconstruct job
(:mod:`evinr_lite.apps.recon_job`) uses the same functions.
"""
from __future__ import annotations

import numpy as np

from ..core.events import EventDataError
from ..core.recording import Recording
from ..io.readers import detect_format, read_recording

__all__ = ["read_any", "describe_recording", "format_info", "SIZE_FREE_FORMATS", "READER_WINDOW_FORMATS",
           "SENSOR_ARG_FORMATS", "TIME_UNIT_FORMATS", "FIXED_UNITS"]

SIZE_FREE_FORMATS = ("txt", "npy")   # formats that may not record the sensor size
READER_WINDOW_FORMATS = ("canonical", "h5", "aedat4", "prophesee_raw", "prophesee_dat")  # read only a window

SENSOR_ARG_FORMATS = SIZE_FREE_FORMATS + ("ijrr", "aedat4", "prophesee_raw", "prophesee_dat")  # take sensor_size=
TIME_UNIT_FORMATS = ("txt", "npy", "ijrr", "evreal", "h5")   # formats whose time unit may differ from seconds
FIXED_UNITS = {"aedat4": "us", "prophesee_raw": "us", "prophesee_dat": "us", "canonical": "s"}


def read_any(path, *, sensor_size=None, t_start: float | None = None, t_end: float | None = None,
             time_unit: str | None = None) -> Recording:
    """Read a recording of any supported format, the sensor size checked or supplied.

    Args:
        path: file or folder; the format is detected (:func:`evinr_lite.io.readers.detect_format`).
        sensor_size: (H, W). Needed for formats that do not record it (.npy, text without a
            `W H` header, an IJRR folder without images.txt, some Prophesee .raw); for the others
            it must match the file's.
        t_start, t_end: passed to readers that read only a window from disk (the others read all).
        time_unit: unit of the timestamps for formats that do not fix it (.npy, text, IJRR, EVREAL,
            HQF h5): 's', 'ms', 'us', 'ns'; None: the reader's detection (integers are taken as
            microseconds, with a warning). For AEDAT4 / Prophesee (microseconds) and canonical files
            (seconds) a different unit is refused.
    Raises:
        EventDataError: missing file, unknown format, wrong or missing sensor size, a time unit the
            format does not allow.
    """
    kind = detect_format(path)
    kwargs = {}
    if kind in SENSOR_ARG_FORMATS and sensor_size is not None:
        kwargs["sensor_size"] = sensor_size
    if kind in READER_WINDOW_FORMATS:
        kwargs.update(t_start=t_start, t_end=t_end)
    if time_unit is not None:
        if kind in TIME_UNIT_FORMATS:
            kwargs["time_unit"] = time_unit
        elif FIXED_UNITS.get(kind) != time_unit:
            raise EventDataError(f"{path}: a {kind} file stores its timestamps in {FIXED_UNITS.get(kind, 's')} "
                                 f"by its format, so time_unit={time_unit!r} cannot apply; leave time_unit= out")
    rec = read_recording(path, **kwargs)
    if sensor_size is not None and tuple(int(v) for v in sensor_size) != rec.events.sensor_size:
        H, W = rec.events.sensor_size
        raise EventDataError(f"{path}: the recording's sensor is (H, W) = {rec.events.sensor_size} ({H}x{W}) but "
                             f"sensor size {tuple(int(v) for v in sensor_size)} was given; leave it out or pass {H}x{W}")
    return Recording(rec.events, rec.frames, {**rec.meta, "format": rec.meta.get("format", kind)})


def describe_recording(rec: Recording) -> dict:
    """What a recording holds: format, sensor, time span, event count and rate, polarity balance,
    frames. Times are seconds on the recording's clock (relative to ``t_origin``)."""
    ev = rec.events
    H, W = ev.sensor_size
    duration = ev.duration
    info = {
        "format": rec.meta.get("format"), "path": rec.meta.get("path"),
        "sensor_size": [H, W], "t_origin": ev.t_origin,
        "t_first": float(ev.t[0]) if len(ev) else None, "t_last": float(ev.t[-1]) if len(ev) else None,
        "duration_s": duration, "n_events": len(ev),
        "event_rate_per_s": len(ev) / duration if duration > 0 else None,
        "events_per_pixel": len(ev) / (H * W),
        "on_fraction": float(np.mean(ev.p > 0)) if len(ev) else None,
        "n_frames": 0,
    }
    if rec.frames is not None and len(rec.frames):
        fr = rec.frames
        info.update(n_frames=len(fr), frame_size=list(fr.size), frames_t_first=float(fr.t[0]),
                    frames_t_last=float(fr.t[-1]),
                    frame_rate_per_s=(len(fr) - 1) / float(fr.t[-1] - fr.t[0]) if len(fr) > 1 and fr.t[-1] > fr.t[0] else None)
    for key in ("C", "eval_window", "dataset", "sequence", "encoding", "cfa"):
        if rec.meta.get(key) is not None:
            value = rec.meta[key]
            info[key] = list(value) if isinstance(value, tuple) else value
    return info


def format_info(info: dict) -> str:
    """Human-readable lines for :func:`describe_recording`'s dict."""
    H, W = info["sensor_size"]
    lines = [f"format        {info['format']}  ({info['path']})",
             f"sensor        {H}x{W} (H x W)"]
    if info["n_events"]:
        rate = info["event_rate_per_s"]
        lines += [f"events        {info['n_events']:,}" + (f"  ({rate:,.0f} per s, {rate / (H * W):.2f} per pixel "
                                                             "per s)" if rate else ""),
                  f"time span     {info['t_first']:.6f} .. {info['t_last']:.6f} s  ({info['duration_s']:.6f} s; "
                  f"times relative to t_origin = {info['t_origin']:.0f} s)",
                  f"polarity      {100 * info['on_fraction']:.1f}% ON, {100 * (1 - info['on_fraction']):.1f}% OFF"]
    else:
        lines.append("events        none")
    if info["n_frames"]:
        fr = info.get("frame_rate_per_s")
        lines.append(f"frames        {info['n_frames']} of {info['frame_size'][0]}x{info['frame_size'][1]}, "
                     f"{info['frames_t_first']:.6f} .. {info['frames_t_last']:.6f} s"
                     + (f" ({fr:.1f} per s)" if fr else "") + "  -> reconstructions are scored against them")
    else:
        lines.append("frames        none (nothing to score against)")
    for key in ("C", "eval_window", "dataset", "sequence", "encoding", "cfa"):
        if key in info:
            lines.append(f"{key:<13} {info[key]}")
    return "\n".join(lines)
