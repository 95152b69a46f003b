"""HDF5 releases -> canonical file, read in chunks.

- MVSEC ``<sequence>_data.hdf5``: ``davis/left/events`` [N, 4] columns (x, y, t, p) with t in
  absolute seconds and p in -1/+1; ``davis/left/image_raw`` [F, H, W] uint8 and
  ``davis/left/image_raw_ts`` [F].
- HQF-style h5 (events_contrast_maximization's conversion): ``events/xs``, ``events/ys``,
  ``events/ts`` (s), ``events/ps`` (bool or 0/1); ``images/image%09d`` with attr ``timestamp``;
  root attr ``sensor_resolution`` (H, W).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from evinr_lite.core.events import auto_origin
from evinr_lite.core.frames import to_grey_uint8 as _to_grey_uint8

from .canonical import CanonicalWriter
from .convert_ijrr import PolarityMapper
from .errors import ConversionError

__all__ = ["convert_h5", "h5_layout"]

ROWS = 1 << 20   # events read per step


def h5_layout(f) -> str | None:
    """'mvsec', 'hqf' or None for an open h5py.File."""
    if "davis" in f and any(f"davis/{side}/events" in f for side in ("left", "right")):
        return "mvsec"
    if all(f"events/{k}" in f for k in ("xs", "ys", "ts", "ps")):
        return "hqf"
    return None


def _mvsec(f, path, writer_args, sensor_size, side, progress):
    from tqdm.auto import tqdm

    key = f"davis/{side}/events"
    if key not in f:
        raise ConversionError(f"{path}: no {key}; this MVSEC file holds {sorted(f['davis'])}")
    ev = f[key]
    if ev.ndim != 2 or ev.shape[1] != 4:
        raise ConversionError(f"{path}: {key} has shape {ev.shape}, expected [N, 4] columns x, y, t, p")
    n = ev.shape[0]
    if n == 0:
        raise ConversionError(f"{path}: {key} holds no events")
    img_key, ts_key = f"davis/{side}/image_raw", f"davis/{side}/image_raw_ts"
    has_frames = img_key in f and ts_key in f and f[img_key].shape[0] > 0
    if sensor_size is None:
        if not has_frames:
            raise ConversionError(f"{path}: no frames to take the sensor size from; pass sensor_size=(H, W) "
                                  "(--sensor-size 260 346 for MVSEC's DAVIS346)")
        sensor_size = f[img_key].shape[1:3]
    origin = auto_origin(float(ev[0, 2]))
    polarity = PolarityMapper(f"{path}: {key}")
    writer = CanonicalWriter(sensor_size=sensor_size, t_origin=origin, **writer_args)
    try:
        for start in tqdm(range(0, n, ROWS), desc=f"{path.name}: events", disable=not progress):
            block = ev[start:start + ROWS]
            x, y, t, p = block.T
            for name, v in (("x", x), ("y", y)):
                if not np.all(v == np.round(v)):
                    raise ConversionError(f"{path}: {key} rows {start}..: {name} is not a whole pixel index")
            writer.add_events(t.astype(np.float64) - origin, x.astype(np.int64), y.astype(np.int64),
                              polarity(p.astype(np.int64), f" rows {start}.."), where=f"{key} rows {start}..")
        if has_frames:
            images, stamps = f[img_key], f[ts_key][()]
            if images.shape[1:3] != tuple(sensor_size):
                raise ConversionError(f"{path}: frames are {images.shape[1:3]} but the sensor is {tuple(sensor_size)}")
            for k in range(images.shape[0]):
                writer.add_frame(_to_grey_uint8(images[k], f"{path}:{img_key}[{k}]"), float(stamps[k]) - origin)
        return writer.close()
    finally:
        writer.abort()


def _hqf(f, path, writer_args, sensor_size, progress, time_unit=None):
    from tqdm.auto import tqdm

    if "sensor_resolution" in f.attrs:
        file_size = tuple(int(v) for v in f.attrs["sensor_resolution"])
        if sensor_size is not None and tuple(sensor_size) != file_size:
            raise ConversionError(f"{path}: sensor_resolution is {file_size} (H, W) but {tuple(sensor_size)} "
                                  "was expected; pass the right sensor size")
        sensor_size = file_size
    if sensor_size is None:
        raise ConversionError(f"{path}: no root attribute sensor_resolution; pass sensor_size=(H, W) "
                              "(--sensor-size H W)")
    xs, ys, ts, ps = (f[f"events/{k}"] for k in ("xs", "ys", "ts", "ps"))
    n = ts.shape[0]
    if any(d.shape != (n,) for d in (xs, ys, ps)):
        raise ConversionError(f"{path}: events/xs, ys, ts, ps must be 1-D of one length")
    if n == 0:
        raise ConversionError(f"{path}: events/ts holds no events")
    from evinr_lite.core.events import TIME_UNITS, check_time_span, resolve_time_unit

    if ts.dtype.kind not in "iuf":
        raise ConversionError(f"{path}: events/ts must be numeric, got dtype {ts.dtype}")
    unit = resolve_time_unit(ts.dtype.kind, time_unit, f"{path}: events/ts")
    per_s = 1.0 / TIME_UNITS[unit]
    try:
        check_time_span(np.array([float(ts[0]), float(ts[n - 1])]) / per_s, f"{path}: events/ts", unit)
    except Exception as err:
        raise ConversionError(str(err)) from None
    origin = auto_origin(float(ts[0]) / per_s)
    polarity = PolarityMapper(f"{path}: events/ps")
    writer = CanonicalWriter(sensor_size=sensor_size, t_origin=origin, **writer_args)
    try:
        for start in tqdm(range(0, n, ROWS), desc=f"{path.name}: events", disable=not progress):
            sl = slice(start, start + ROWS)
            writer.add_events(ts[sl].astype(np.float64) / per_s - origin, xs[sl], ys[sl], polarity(ps[sl], f" [{start}..]"),
                              where=f"events [{start}..]")
        if "images" in f:
            group = f["images"]
            for k in sorted(group):
                stamp = float(group[k].attrs["timestamp"]) if "timestamp" in group[k].attrs else math.nan
                if not math.isfinite(stamp):
                    raise ConversionError(f"{path}: images/{k} has no 'timestamp' attribute")
                writer.add_frame(_to_grey_uint8(group[k][()], f"{path}:images/{k}"), stamp / per_s - origin)
        return writer.close()
    finally:
        writer.abort()


def convert_h5(path, out, *, sensor_size=None, C: float = 1.0, eval_window=None, dataset: str = "",
               sequence: str | None = None, source: str = "", source_url: str = "", side: str = "left",
               progress: bool = True, time_unit: str | None = None) -> Path:
    """Convert an MVSEC ``_data.hdf5`` or an HQF-style ``.h5`` to the canonical file ``out``."""
    import h5py

    path = Path(path)
    try:
        f = h5py.File(path, "r")
    except OSError as err:
        raise ConversionError(f"{path}: not a readable HDF5 file ({err}); the download is damaged or incomplete: "
                              "delete it and run the command again") from None
    with f:
        layout = h5_layout(f)
        args = dict(out=out, dataset=dataset, sequence=sequence or path.stem.removesuffix("_data"), source=source,
                    source_url=source_url, raw_file=path.name, C=C, eval_window=eval_window,
                    converter=f"data_fetch.convert_h5 ({layout})")
        if layout == "mvsec":
            return _mvsec(f, path, args, sensor_size, side, progress)
        if layout == "hqf":
            return _hqf(f, path, args, sensor_size, progress, time_unit)
    raise ConversionError(f"{path}: unknown HDF5 layout (neither MVSEC davis/left/events nor HQF events/xs..); "
                          "if it is already a canonical file, read it with evinr_lite.io.canonical.read_canonical")
