"""An EVREAL per-sequence folder of .npy files (events_ts, events_xy, events_p, images, images_ts,
metadata.json with the sensor resolution)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...core.events import TIME_UNITS, EventDataError
from ...core.frames import Frames
from ...core.recording import Recording
from ..notes import note
from .base import (FileFormat, build_events, check_finite_images, existing, frames_on_event_clock, json_file,
                   load_npy, note_decimal_seconds, size_value, to_seconds)

__all__ = ["read_evreal_folder", "FORMAT"]


def read_evreal_folder(folder, *, time_unit="auto") -> Recording:
    """An EVREAL per-sequence folder of .npy files.

    Files: events_ts.npy [N] float64 s, events_xy.npy [N, 2] (x first), events_p.npy [N] in {0, 1}
    (or -1/+1), images.npy [F, H, W, 1] uint8, images_ts.npy [F], metadata.json
    {"sensor_resolution": [H, W]}, image_event_indices.npy (optional, kept in ``meta``).

    Args:
        time_unit: unit of events_ts.npy and images_ts.npy; 'auto': integers are microseconds (with a
            TimeUnitWarning), floats seconds.
    """
    folder = existing(folder, "folder")
    needed = ("events_ts.npy", "events_xy.npy", "events_p.npy", "metadata.json")
    missing = [name for name in needed if not (folder / name).exists()]
    if missing:
        raise EventDataError(f"{folder}: missing {', '.join(missing)}; an EVREAL folder holds {', '.join(needed)} "
                             "(and images.npy, images_ts.npy for frames)")
    metadata = json_file(folder / "metadata.json")
    if "sensor_resolution" not in metadata:
        raise EventDataError(f"{folder / 'metadata.json'}: no 'sensor_resolution'; add \"sensor_resolution\": [H, W]")
    sensor_size = size_value(folder / "metadata.json", metadata["sensor_resolution"], "sensor_resolution")
    load = lambda name: load_npy(existing(folder / name))  # noqa: E731
    ts, xy, p = load("events_ts.npy"), load("events_xy.npy"), load("events_p.npy")
    if ts.ndim != 1 or ts.dtype.kind not in "iuf":
        raise EventDataError(f"{folder / 'events_ts.npy'}: expected a 1-D numeric array of timestamps, got shape "
                             f"{ts.shape} dtype {ts.dtype}")
    if xy.ndim != 2 or xy.shape[1] != 2 or xy.dtype.kind not in "iuf":
        raise EventDataError(f"{folder / 'events_xy.npy'}: expected a numeric array of shape [N, 2] (x, y), got "
                             f"{xy.shape} dtype {xy.dtype}")
    if p.dtype.kind not in "iufb":
        raise EventDataError(f"{folder / 'events_p.npy'}: expected numeric polarities, got dtype {p.dtype}")
    t, origin, unit = to_seconds(folder / "events_ts.npy", ts, time_unit)
    events = build_events(folder, t, xy[:, 0], xy[:, 1], p, sensor_size, polarity="auto", t_origin=origin)
    meta = {"format": "evreal", "path": str(folder), "metadata": metadata, "time_unit": unit}
    span = (float(events.t[0]), float(events.t[-1])) if len(events) else None
    if span is not None:
        note_decimal_seconds(*span, len(events), time_unit, unit, folder / "events_ts.npy", meta)
    frames = None
    if (folder / "images.npy").exists():
        if not (folder / "images_ts.npy").exists():
            raise EventDataError(f"{folder}: images.npy without images_ts.npy; add the frame timestamps or remove "
                                 "images.npy")
        images, images_ts = load("images.npy"), load("images_ts.npy")
        if images_ts.ndim != 1 or images_ts.dtype.kind not in "iuf":
            raise EventDataError(f"{folder / 'images_ts.npy'}: expected a 1-D numeric array, got shape "
                                 f"{images_ts.shape} dtype {images_ts.dtype}")
        stamps = np.asarray(images_ts, np.float64)
        bad = np.flatnonzero(~np.isfinite(stamps))
        if bad.size:
            raise EventDataError(f"{folder / 'images_ts.npy'}: frame {int(bad[0])}'s timestamp is {stamps[bad[0]]} "
                                 f"({bad.size} non-finite in all); repair those timestamps, or remove the frames "
                                 "(images.npy and images_ts.npy together)")
        check_finite_images(images, folder / "images.npy")
        frame_t, _ = frames_on_event_clock(lambda u: stamps * TIME_UNITS[u] - origin, unit, span,
                                           folder / "images_ts.npy", meta)
        if np.any(np.diff(frame_t) < 0):
            note(meta, f"{folder / 'images_ts.npy'}: the frames are not in time order; they are read sorted by "
                       "their timestamps")
        try:
            frames = Frames(images, frame_t, origin).sorted()
        except EventDataError as err:
            raise EventDataError(f"{folder / 'images.npy'}: {err}") from None
        if frames.size != sensor_size:
            raise EventDataError(f"{folder}: frames are {frames.size} but sensor_resolution is "
                                 f"{sensor_size} (both (H, W)); one of them is wrong: if the frames are the "
                                 f"camera's, set metadata.json's sensor_resolution to {list(frames.size)}")
    if (folder / "image_event_indices.npy").exists():
        meta["image_event_indices"] = load("image_event_indices.npy")
    return Recording(events, frames, meta)


def _sniff(path, head) -> bool:
    return head is None and (Path(path) / "events_ts.npy").exists()


FORMAT = FileFormat(
    name="evreal", description="an EVREAL folder (events_ts.npy, events_xy.npy, events_p.npy, images.npy, "
    "images_ts.npy, metadata.json)", reader=read_evreal_folder, folder=True, sniff=_sniff, options=("time_unit",), priority=1)
