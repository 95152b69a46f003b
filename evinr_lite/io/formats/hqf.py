"""An HQF-style HDF5 file (the layout of the HQF / EVREAL h5 releases and of event_utils).

Layout: events/xs, events/ys (int), events/ts (float64 s, sorted), events/ps (bool, 0/1 or -1/+1);
images/image%09d (uint8) with attrs 'timestamp' (and 'event_idx'); root attr 'sensor_resolution'
(H, W). A window is found by bisection on events/ts on disk and only its slice is read.
"""
from __future__ import annotations

import math

import numpy as np

from ...core.events import TIME_UNITS, EventDataError, Events, check_time_span, resolve_time_unit
from ...core.frames import Frames, in_window, to_grey_uint8
from ...core.recording import Recording
from ..notes import note
from .base import (Clock, FileFormat, build_events, check_declared_size, check_finite_images, check_time_spread,
                   frames_on_event_clock, note_decimal_seconds, plain_attr, size_value)
from .h5window import HDF5_MAGIC, H5Source, TimeIndexed, check_filters, column_count, read_window

__all__ = ["read_h5", "HqfSource", "FORMAT"]

EVENT_NAMES = ("events/xs", "events/ys", "events/ts", "events/ps")


class _Layout(TimeIndexed):
    """The checked layout of an open HQF file: sensor size, event count, clock, time unit."""

    def __init__(self, f, path, time_unit, sensor_size=None):
        import h5py

        self.f, self.path = f, path
        missing = [n for n in EVENT_NAMES if n not in f or not isinstance(f[n], h5py.Dataset)]
        if missing and isinstance(f.get("CD/events"), h5py.Dataset):   # Metavision SDK 4+ writes this layout
            raise EventDataError(f"{path}: a Prophesee Metavision HDF5 file (CD/events, compressed with Prophesee's "
                                 "ECF codec, which no h5py plugin here decodes); convert it with Metavision's "
                                 "metavision_file_to_dat (a .dat file) or metavision_file_to_csv (a .csv file) and "
                                 "read that")
        if missing and isinstance(f.get("log_intensity"), h5py.Dataset) and f.attrs.get("writer") == "evinr-lite":
            raise EventDataError(f"{path}: a reconstruction's log intensity (evinr-lite reconstruct --save-log), not "
                                 "a recording: it holds frames, not events; read it with "
                                 "evinr_lite.io.export.read_log_intensity, and give reconstruct or info the "
                                 "recording it came from (its run.json's \"input\")")
        if missing:
            raise EventDataError(f"{path}: missing datasets {missing} (or groups where datasets belong); expected "
                                 f"the HQF layout {list(EVENT_NAMES)}, each a 1-D dataset")
        if "sensor_resolution" in f.attrs:
            self.sensor_size = check_declared_size(
                path, size_value(path, f.attrs["sensor_resolution"], "the attribute sensor_resolution"), sensor_size,
                "attribute sensor_resolution")
        elif sensor_size is not None:   # a writer that left the attribute out: the size given stands in for it
            self.sensor_size = size_value(path, sensor_size, "sensor_size")
        else:
            raise EventDataError(f"{path}: no root attribute 'sensor_resolution' (H, W), so the sensor size is "
                                 "unknown; pass it (sensor_size=(H, W)), or add the attribute, e.g. "
                                 "h5py.File(path, 'r+').attrs['sensor_resolution'] = (H, W)")
        ts = self.t = f["events/ts"]
        self.time_unit = time_unit
        n = self.n = column_count(f, path, ("events/ts", "events/xs", "events/ys", "events/ps"), "iufb", "numeric")
        check_filters(f, path, EVENT_NAMES)
        self.unit = resolve_time_unit(ts.dtype.kind if n else "f", time_unit, f"{path}: events/ts")
        per_s = 1.0 / TIME_UNITS[self.unit]
        if n and not (math.isfinite(float(ts[0])) and math.isfinite(float(ts[n - 1]))):
            raise EventDataError(f"{path}: events/ts holds non-finite timestamps; the file is damaged")
        if n and ts.dtype.kind == "f" and ts.dtype.itemsize < 8:   # float32 on an absolute clock rounds to minutes
            step = float(np.spacing(np.abs(np.asarray([ts[0], ts[n - 1]], dtype=ts.dtype)).max())) / per_s
            if step > 1e-6:
                raise EventDataError(f"{path}: events/ts is {ts.dtype}, which at these values resolves only "
                                     f"{step:.3g} s; the timestamps were rounded when the file was written: write "
                                     "them as float64 (or integer microseconds)")
        self.clock = Clock(ts[0] if n else 0, self.unit, ts.dtype.kind in "iu")
        self.origin = self.clock.origin
        if n >= 2:   # every event at one instant: a damaged events/ts, refused before any window is read
            check_time_spread(*self.span(), n, f"{path}: events/ts")

    def meta(self) -> dict:
        """The reading's meta, with a note when decimal timestamps detected as seconds come too slowly
        for seconds."""
        meta = {"format": "h5", "path": str(self.path), "attrs": {k: plain_attr(v) for k, v in self.f.attrs.items()},
                "time_unit": self.unit}
        if self.n > 1:
            note_decimal_seconds(*self.span(), self.n, self.time_unit, self.unit, f"{self.path}: events/ts", meta)
        return meta

    def events(self, lo: int, hi: int) -> Events:
        t = self.clock.seconds(self.t[lo:hi])
        check_time_span(t, f"{self.path}: events/ts", self.unit)
        x, y, p = (self.f[name][lo:hi] for name in ("events/xs", "events/ys", "events/ps"))
        return build_events(self.path, t, x, y, p, self.sensor_size, polarity="auto", t_origin=self.origin)

    def frames(self, t_start=None, t_end=None, meta=None) -> Frames | None:
        """The frames in [t_start, t_end) on the events' clock, sorted by time (one HQF sequence has a frame
        out of order); their 'event_idx' attributes go to ``meta["frame_event_idx"]``."""
        import h5py

        f, path = self.f, self.path
        if "images" not in f or not isinstance(f["images"], h5py.Group) or not len(f["images"]):
            return None
        group = f["images"]
        keys = np.array(sorted(group))
        stamps = []
        for k in keys:
            if not isinstance(group[k], h5py.Dataset):
                raise EventDataError(f"{path}: images/{k} is a group, not an image dataset; remove it or store the "
                                     "frame as a dataset")
            value = group[k].attrs.get("timestamp")
            try:
                stamp = float(np.asarray(value).reshape(()))
            except (TypeError, ValueError):
                raise EventDataError(f"{path}: images/{k} has no numeric 'timestamp' attribute (got {value!r}); "
                                     "every frame needs one") from None
            if not math.isfinite(stamp):
                raise EventDataError(f"{path}: images/{k} has a non-finite 'timestamp'; repair or remove that frame")
            stamps.append(stamp)
        raw = np.array(stamps, dtype=np.float64)   # float64 holds whole microseconds exactly for 285 years

        def seconds(unit):   # the stamps in ``unit`` on the events' clock (the events' own unit: exactly as they)
            if unit == self.unit:
                return ((raw - self.clock.origin_units) / self.clock.per_s if self.clock.integer
                        else raw / self.clock.per_s - self.origin)
            return raw * TIME_UNITS[unit] - self.origin

        span = self.span() if self.n else None
        stamps, _ = frames_on_event_clock(seconds, self.unit, span, f"{path}: images/*.attrs['timestamp']", meta)
        if np.any(np.diff(stamps) < 0):   # one HQF sequence has a frame out of order
            note(meta, f"{path}: the frames' timestamps are not in the order of their names; they are read sorted "
                       "by time")
        keep = in_window(stamps, t_start, t_end)
        order = np.argsort(stamps[keep], kind="stable")
        keys, stamps = keys[keep][order], stamps[keep][order]
        if not len(keys):
            return None
        images = []
        for k in keys:
            image = group[k][()]
            check_finite_images(image, f"{path}:images/{k}")
            images.append(to_grey_uint8(image, f"{path}:images/{k}"))
        if len({im.shape for im in images}) > 1:
            raise EventDataError(f"{path}: the frames have different sizes {sorted({im.shape for im in images})}")
        frames = Frames(np.stack(images), stamps, self.origin)
        if frames.size != self.sensor_size:
            raise EventDataError(f"{path}: frames are {frames.size} but sensor_resolution is "
                                 f"{self.sensor_size} (both (H, W)); one of them is wrong: if the frames are the "
                                 "camera's, set the attribute to their size, e.g. h5py.File(path, 'r+').attrs"
                                 f"['sensor_resolution'] = {tuple(frames.size)}")
        if meta is not None and all("event_idx" in group[k].attrs for k in keys):  # indices into the file's events
            meta["frame_event_idx"] = np.array([int(np.asarray(group[k].attrs["event_idx"]).reshape(()))
                                                for k in keys])
        return frames


def read_h5(path, *, t_start=None, t_end=None, time_unit="auto", sensor_size=None) -> Recording:
    """An HQF-style h5 file, optionally only the time window [t_start, t_end).

    Args:
        t_start, t_end: seconds on the returned clock (file time minus ``t_origin``). The window
            is found by binary search on the ts dataset on disk and only that slice is read; frames
            are restricted to the same window. Frames come sorted by timestamp.
        time_unit: unit of events/ts and the frames' timestamps; 'auto': an integer dataset is
            microseconds (with a TimeUnitWarning), floats seconds.
        sensor_size: (H, W), for a file without the attribute 'sensor_resolution' (checked against it otherwise).
    Raises:
        EventDataError for a missing, damaged or incomplete file, missing datasets or attributes.
    """
    return read_window(path, lambda f, p: _Layout(f, p, time_unit, sensor_size), t_start, t_end)


class HqfSource(H5Source):
    """Windows of an HQF h5 file: each found by bisection on events/ts, only its slice read. Holds the file open."""

    def __init__(self, path, *, time_unit="auto", sensor_size=None):
        super().__init__(path, lambda f, p: _Layout(f, p, time_unit, sensor_size), "h5")


def _sniff(path, head) -> bool:
    return head is not None and head.startswith(HDF5_MAGIC)


FORMAT = FileFormat(
    name="h5", description="an HQF-style .h5/.hdf5 file", reader=read_h5, suffixes=(".h5", ".hdf5"),
    sniff=_sniff, windowed=True, open_source=HqfSource, takes_sensor_size=True, options=("time_unit",), priority=20)
