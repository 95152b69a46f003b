"""An MVSEC HDF5 file (``*_data.hdf5`` of the Multi Vehicle Stereo Event Camera dataset).

Layout (it mirrors the ROS bags): davis/left/events, float64 [N, 4] rows (x, y, t, p) with t in
seconds on the ROS clock (about 1.5e9 s) and p -1/+1; davis/left/image_raw, uint8 [F, H, W] APS
frames, with their times in davis/left/image_raw_ts [F] (seconds); the same under davis/right. The
sensor size is the frames' (H, W) (DAVIS 346: (260, 346)); a file without frames needs it passed. A
window is found by bisection on the time column on disk and only its rows are read.
"""
from __future__ import annotations

import numpy as np

from ...core.events import EventDataError, Events, check_time_span
from ...core.frames import Frames, in_window, to_grey_uint8
from ...core.recording import Recording
from .base import (Clock, FileFormat, build_events, check_declared_size, check_finite_images, check_time_spread,
                   frames_on_event_clock, size_value)
from .h5window import H5Source, TimeIndexed, check_filters, read_window, sniff_h5

__all__ = ["read_mvsec", "MvsecSource", "FORMAT", "CAMERAS"]

CAMERAS = ("left", "right")
SIZE_FIX = "pass sensor_size=(H, W) (rows, columns; MVSEC's DAVIS 346: (260, 346))"


def mvsec_camera(f) -> str | None:
    """The first of CAMERAS with an events dataset of rows (x, y, t, p) in the open file, or None."""
    import h5py

    for camera in CAMERAS:
        ds = f.get(f"davis/{camera}/events")
        if isinstance(ds, h5py.Dataset) and ds.ndim == 2 and ds.shape[1] == 4:
            return camera
    return None


class _TimeColumn:
    """The time column of the events dataset, read element by element (bisection) or by slices."""

    def __init__(self, ds):
        self.ds, self.shape = ds, (ds.shape[0],)

    def __getitem__(self, i):
        return self.ds[i, 2]


class _Layout(TimeIndexed):
    """The checked layout of an open MVSEC file for one camera."""

    def __init__(self, f, path, camera, sensor_size):
        import h5py

        camera = (mvsec_camera(f) or "left") if camera is None else camera
        if camera not in CAMERAS:
            raise EventDataError(f"camera must be one of {CAMERAS}, got {camera!r}")
        self.f, self.path, self.camera = f, path, camera
        name = f"davis/{camera}/events"
        ds = f.get(name)
        if not isinstance(ds, h5py.Dataset) or ds.ndim != 2 or ds.shape[1] != 4:
            found = mvsec_camera(f)
            raise EventDataError(f"{path}: no {name} dataset of rows (x, y, t, p)"
                                 + (f"; the file has the {found} camera's: pass camera={found!r}" if found else ""))
        if ds.dtype.kind not in "iuf":
            raise EventDataError(f"{path}: {name} must be numeric, got dtype {ds.dtype}")
        self.ds, self.name, self.n = ds, name, ds.shape[0]
        check_filters(f, path, [name])
        self.t = _TimeColumn(ds)
        self.images, self.image_ts = f.get(f"davis/{camera}/image_raw"), f.get(f"davis/{camera}/image_raw_ts")
        has_frames = (isinstance(self.images, h5py.Dataset) and self.images.ndim == 3 and self.images.shape[0] > 0
                      and isinstance(self.image_ts, h5py.Dataset))
        if has_frames:
            declared = tuple(int(v) for v in self.images.shape[1:])
            check_declared_size(path, declared, sensor_size, f"davis/{camera}/image_raw's frame size")
            self.sensor_size = declared
        elif sensor_size is None:
            raise EventDataError(f"{path}: no davis/{camera}/image_raw frames to take the sensor size from; {SIZE_FIX}")
        else:
            self.sensor_size = size_value(path, sensor_size, "sensor_size")
        self.has_frames = has_frames
        first = float(self.t[0]) if self.n else 0.0
        if self.n and not (np.isfinite(first) and np.isfinite(float(self.t[self.n - 1]))):
            raise EventDataError(f"{path}: {name} holds non-finite timestamps; the file is damaged")
        self.clock = Clock(first, "s", ds.dtype.kind in "iu")
        self.origin = self.clock.origin
        if self.n >= 2:
            check_time_spread(*self.span(), self.n, f"{path}: {name}")

    def events(self, lo: int, hi: int) -> Events:
        rows = self.ds[lo:hi]
        t = self.clock.seconds(rows[:, 2])
        check_time_span(t, f"{self.path}: {self.name}", "s")
        return build_events(self.path, t, rows[:, 0], rows[:, 1], rows[:, 3], self.sensor_size, polarity="auto",
                            t_origin=self.origin)

    def frames(self, t_start=None, t_end=None, meta=None) -> Frames | None:
        """The APS frames in [t_start, t_end) on the events' clock, sorted by time."""
        if not self.has_frames:
            return None
        raw = np.asarray(self.image_ts[()], np.float64).reshape(-1)
        if raw.shape[0] != self.images.shape[0]:
            raise EventDataError(f"{self.path}: davis/{self.camera}/image_raw holds {self.images.shape[0]} frames but "
                                 f"image_raw_ts {raw.shape[0]} times; the file is damaged")
        if not np.all(np.isfinite(raw)):
            raise EventDataError(f"{self.path}: davis/{self.camera}/image_raw_ts holds non-finite times; the file is "
                                 "damaged")
        from ...core.events import TIME_UNITS

        def seconds(unit):
            return raw * TIME_UNITS[unit] - self.origin

        stamps, _ = frames_on_event_clock(seconds, "s", self.span() if self.n else None,
                                          f"{self.path}: davis/{self.camera}/image_raw_ts", meta)
        index = np.flatnonzero(in_window(stamps, t_start, t_end))
        if not len(index):
            return None
        index = index[np.argsort(stamps[index], kind="stable")]   # in time order
        images = self.images[index] if np.all(np.diff(index) > 0) else np.stack([self.images[i] for i in index])
        source = f"{self.path}:davis/{self.camera}/image_raw"
        check_finite_images(images, source)
        images = images if images.dtype == np.uint8 else np.stack([to_grey_uint8(im, source) for im in images])
        return Frames(images, stamps[index], self.origin)

    def meta(self) -> dict:
        return {"format": "mvsec", "path": str(self.path), "camera": self.camera}


def read_mvsec(path, sensor_size=None, *, t_start=None, t_end=None, camera=None) -> Recording:
    """An MVSEC ``*_data.hdf5`` file (events and APS frames of one DAVIS), optionally only [t_start, t_end).

    Args:
        sensor_size: (H, W); taken from the frames when the file has them (then it must agree).
        t_start, t_end: seconds on the returned clock (the ROS clock minus ``t_origin``, its whole
            seconds). The window is found by bisection on disk and only its rows are read.
        camera: 'left' or 'right'; None: the left camera, or the right one in a file that has only it.
    Raises:
        EventDataError for a missing, damaged or incomplete file, a missing events dataset, an empty window.
    """
    return read_window(path, lambda f, p: _Layout(f, p, camera, sensor_size), t_start, t_end)


class MvsecSource(H5Source):
    """Windows of an MVSEC file: each found by bisection on the time column, only its rows read. Holds the file open."""

    def __init__(self, path, *, sensor_size=None, camera=None):
        super().__init__(path, lambda f, p: _Layout(f, p, camera, sensor_size), "mvsec")


def _sniff(path, head) -> bool:
    """An HDF5 file with davis/left/events or davis/right/events rows (x, y, t, p)."""
    return sniff_h5(path, head, mvsec_camera)


FORMAT = FileFormat(
    name="mvsec", description="an MVSEC .hdf5 (davis/left/events rows x, y, t, p, and the image_raw frames)",
    reader=read_mvsec, suffixes=(".h5", ".hdf5"), sniff=_sniff, needs_sensor_size=True, takes_sensor_size=True,
    time_unit="s", windowed=True, open_source=MvsecSource, options=("camera",), priority=16)
