"""Writing the canonical HDF5 file (the layout and its reader live in :mod:`evinr_lite.canonical`).

:class:`CanonicalWriter` takes events and frames in pieces (a converter streams a raw file chunk
by chunk or message by message), checks them, writes full compressed chunks, builds the coarse
time index on the way, and at the end sets the attributes (sensor size, C, evaluation window, ...).
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

from evinr_lite.canonical import FORMAT_NAME, FORMAT_VERSION

from .errors import ConversionError

__all__ = ["CanonicalWriter", "CHUNK_EVENTS", "repair_frame_times"]

log = logging.getLogger("data_fetch")
CHUNK_EVENTS = 1 << 16          # events per HDF5 chunk, and the stride of events/t_index
COMPRESSION = dict(compression="gzip", compression_opts=4, shuffle=True)
DTYPES = {"t": np.float64, "x": np.uint16, "y": np.uint16, "p": np.int8}


def repair_frame_times(t: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """Repair isolated wrong frame timestamps (a stamp out of order between two good ones).

    A decreasing step t[i] > t[i+1] is blamed on the one stamp whose neighbours are in order
    (t[i-1] <= t[i+1]: t[i] is too late; else t[i] <= t[i+2]: t[i+1] is too early); that stamp is
    replaced by the midpoint of its neighbours. Returns (repaired copy, indices repaired). Steps
    that cannot be blamed on one interior stamp are left (the caller then sorts the frames).
    """
    t = np.array(t, dtype=np.float64)
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


class CanonicalWriter:
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

    Use as a context manager; leaving the block with an exception deletes the partial file.
    """

    def __init__(self, out, *, sensor_size, t_origin: float = 0.0, dataset: str = "", sequence: str = "",
                 source: str = "", source_url: str = "", raw_file: str = "", C: float = 1.0,
                 eval_window=None, converter: str = "", meta: dict | None = None):
        import h5py

        self.out = Path(out)
        self.out.parent.mkdir(parents=True, exist_ok=True)
        self.tmp = self.out.with_name(f".{self.out.name}.partial")
        self.H, self.W = (int(v) for v in sensor_size)
        self.t_origin = float(t_origin)
        self.attrs = dict(dataset=dataset, sequence=sequence, source=source, source_url=source_url,
                          raw_file=raw_file, C=float(C), converter=converter)
        self.eval_window = None if eval_window is None else tuple(float(v) for v in eval_window)
        self.meta = dict(meta or {})
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
        self.closed = False

    # ---- events -----------------------------------------------------------------------------
    def add_events(self, t, x, y, p, *, where: str = "") -> None:
        """Append events (t float64 s since t_origin, non-decreasing; p in -1/+1).

        ``where`` names the position in the raw file for error messages (e.g. "line 1200").
        """
        t = np.asarray(t, dtype=np.float64)
        if t.size == 0:
            return
        x, y, p = np.asarray(x), np.asarray(y), np.asarray(p)
        at = f" ({where})" if where else ""
        if not (t.shape == x.shape == y.shape == p.shape) or t.ndim != 1:
            raise ConversionError(f"t, x, y, p of a block differ in shape{at}: {t.shape}, {x.shape}, {y.shape}, {p.shape}")
        if not np.all(np.isfinite(t)):
            raise ConversionError(f"non-finite timestamp{at}; the raw file is damaged")
        steps = np.diff(t, prepend=self.t_last)
        if np.any(steps < 0):
            i = int(np.flatnonzero(steps < 0)[0])
            prev = self.t_last if i == 0 else t[i - 1]
            raise ConversionError(f"timestamps go back in time{at}: {t[i]!r} s after {prev!r} s (event "
                                  f"{self.n + self.buffered + i}); the raw events are not sorted by time")
        for name, v, size in (("x", x, self.W), ("y", y, self.H)):
            if v.min() < 0 or v.max() >= size:
                raise ConversionError(
                    f"{name} coordinates span [{v.min()}, {v.max()}] but the sensor is (H, W) = "
                    f"{(self.H, self.W)}{at}; the sensor size is wrong for this recording (pass the camera's "
                    "real size) or the raw file is damaged")
        if not np.all((p == 1) | (p == -1)):
            raise ConversionError(f"polarities must be -1/+1 when written{at}; got {np.unique(p)[:6]}")
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
        """Append one grey uint8 frame [H, W] taken at ``t`` (s since t_origin)."""
        image = np.asarray(image)
        if image.dtype != np.uint8 or image.ndim != 2:
            raise ConversionError(f"frames must be grey uint8 [H, W]; got {image.dtype} {image.shape}")
        if not math.isfinite(t):
            raise ConversionError(f"frame {len(self.frame_t)} has a non-finite timestamp")
        if self.frames is None:
            h, w = image.shape
            self.frames = self.f.create_dataset("frames/images", shape=(0, h, w), maxshape=(None, h, w),
                                                dtype=np.uint8, chunks=(1, h, w), **COMPRESSION)
        if image.shape != self.frames.shape[1:]:
            raise ConversionError(f"frame {len(self.frame_t)} is {image.shape} but the first frame is "
                                  f"{self.frames.shape[1:]}; all frames of a sequence must share one size")
        k = len(self.frame_t)
        self.frames.resize((k + 1, *self.frames.shape[1:]))
        self.frames[k] = image
        self.frame_t.append(float(t))

    # ---- finishing --------------------------------------------------------------------------
    def _finish_frames(self) -> list[int]:
        ft = np.array(self.frame_t, dtype=np.float64)
        repaired: list[int] = []
        if ft.size > 1 and np.any(np.diff(ft) < 0):
            ft, repaired = repair_frame_times(ft)
            if repaired:
                log.warning("data_fetch: frame timestamps out of order at %s; repaired as the midpoint of their "
                            "neighbours", repaired)
                self.meta["frame_times_repaired"] = repaired
            if np.any(np.diff(ft) < 0):
                order = np.argsort(ft, kind="stable")
                log.warning("data_fetch: frames are not in time order; sorting them")
                images = self.frames[()]
                self.frames[...] = images[order]
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
            raise ConversionError(f"no events were found for {self.out.name}; the raw file holds no events "
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

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.close()
        else:
            self.abort()
        return False
