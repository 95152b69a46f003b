"""AED (ALPIX-Eiger, Quad Bayer) sequence folder placed by hand -> canonical file (grey, demosaiced).

AED is not publicly downloadable and the authors' raw layout is not published, so this converter
reads one documented layout. Put each sequence in a folder (``<cache>/raw/aed/<sequence>/`` or
anywhere) and run ``python -m data_fetch convert <folder> --dataset aed``::

    <sequence>/
      events.npy | events.h5 | events.txt   exactly one of them: the colour events, Quad Bayer
                                            photosites, sorted by time
          events.npy  [N, 4] numbers, columns t, x, y, p (or a structured array with fields t, x, y, p)
          events.h5   datasets t, x, y, p (at the root or in a group events/)
          events.txt  one event per line: t x y p (whitespace separated, '#' starts a comment)
      frames/                               one PNG per frame: RGB (8-bit) [2448, 3264, 3], or the
                                            raw Quad Bayer mosaic, grey 8- or 16-bit [2448, 3264]
      frames.txt                            one line per frame, sorted by time: <t> <file name in frames/>
      meta.json                             optional, keys:
          "time_unit": "s" | "ms" | "us" | "ns"  (events and frames.txt; default: integer timestamps
                       are microseconds, decimals are seconds)
          "event_sensor_size": [H, W]  raw event sensor (default [1224, 1632], AED's)
          "phase": [dy, dx]            Quad Bayer phase of the events (default [0, 0]; recorded only:
                                       the grey reduction does not depend on it)
          "note": any text

x is the column, y the row (0-based); p is 0/1 or -1/+1. frames/ and frames.txt come together or
not at all (events only).

What is written (C = 0.25, the paper's value for AED, unless given):

- events: every event kept, timestamp and polarity unchanged, (x, y) -> (x // 4, y // 4): one grey
  pixel per 4 x 4 Quad Bayer tile, 1632 x 1224 -> 408 x 306
  (:func:`evinr_lite.sim.quadbayer.demosaic_events`; each merged event stands for C_photosite / 16 of
  grey log intensity, see that module).
- ``frames/images``: grey frames **at the events' grid** (306 x 408), because reconstructions have
  the events' size and are scored against these: the frame is reduced to grey at a quarter of its
  resolution per axis (816 x 612, the paper's frames: the mean of each 4 x 4 tile, i.e.
  (R + 2 G + B) / 4, the same weights as the merged events), then averaged over 2 x 2 blocks.
- ``frames_full/images`` and ``frames_full/t``: the paper's 816 x 612 grey frames (uint8), when they
  are larger than the event grid.
- meta: raw sizes, phase, time unit, frame kind (rgb / mosaic), the reduction factors.

Values are averaged as stored in the PNG (no gamma decoding), then rounded to uint8.
"""
from __future__ import annotations

import io
import itertools
import json
import logging
import math
from pathlib import Path

import numpy as np

from evinr_lite.core.events import TIME_UNITS, LARGE_T
from evinr_lite.io.canonical import COMPRESSION
from evinr_lite.sim.quadbayer import demosaic_grey, reduce_mean

from .canonical import CanonicalWriter
from .convert_ijrr import PolarityMapper
from .errors import ConversionError

__all__ = ["convert_aed", "write_aed_folder", "AED_EVENT_SENSOR", "TILE", "EVENT_FILES", "LAYOUT"]

log = logging.getLogger("data_fetch")
AED_EVENT_SENSOR = (1224, 1632)     # (H, W) raw Quad Bayer event photosites
TILE = 4                            # Quad Bayer period: one grey pixel per 4 x 4 photosites
EVENT_FILES = ("events.npy", "events.h5", "events.txt")
META_KEYS = {"time_unit", "event_sensor_size", "phase", "note"}
CHUNK = 1 << 20
LAYOUT = ("expected layout: <sequence>/ with exactly one of events.npy ([N, 4]: t, x, y, p), events.h5 "
          "(datasets t, x, y, p) or events.txt (t x y p per line); frames/ (PNG, RGB or Quad Bayer mosaic) with "
          "frames.txt ('<t> <file>' per line); optional meta.json (time_unit, event_sensor_size, phase). "
          "See data_fetch/convert_aed.py")


# ---- the folder -------------------------------------------------------------------------

def _read_meta(folder: Path) -> dict:
    path = folder / "meta.json"
    if not path.exists():
        return {}
    try:
        meta = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise ConversionError(f"{path}: not valid JSON ({err}); fix it or delete it (it is optional)") from None
    if not isinstance(meta, dict):
        raise ConversionError(f"{path}: must hold a JSON object like {{\"time_unit\": \"us\"}}, got {type(meta).__name__}")
    unknown = sorted(set(meta) - META_KEYS)
    if unknown:
        raise ConversionError(f"{path}: unknown keys {unknown}; allowed keys: {sorted(META_KEYS)}")
    if "time_unit" in meta and meta["time_unit"] not in TIME_UNITS:
        raise ConversionError(f"{path}: time_unit {meta['time_unit']!r} is not one of {sorted(TIME_UNITS)}")
    return meta


def _pair(value, what: str, source) -> tuple[int, int]:
    try:
        a, b = (int(v) for v in value)
        if not np.allclose(np.asarray(value, dtype=np.float64), (a, b)):
            raise ValueError
    except (TypeError, ValueError):
        raise ConversionError(f"{source}: {what} must be two whole numbers, got {value!r}") from None
    return a, b


def _event_file(folder: Path) -> Path:
    found = [folder / name for name in EVENT_FILES if (folder / name).exists()]
    if not found:
        present = sorted(p.name for p in folder.iterdir())[:12]
        raise ConversionError(f"{folder}: no events file (looked for {', '.join(EVENT_FILES)}; the folder holds "
                              f"{present or 'nothing'}); {LAYOUT}")
    if len(found) > 1:
        raise ConversionError(f"{folder}: several events files {[p.name for p in found]}; keep exactly one")
    return found[0]


# ---- events, chunk by chunk ---------------------------------------------------------------

def _npy_chunks(path: Path):
    try:
        arr = np.load(path, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError) as err:
        raise ConversionError(f"{path}: not a readable .npy array ({err}); {LAYOUT}") from None
    if arr.dtype.names is not None:
        missing = [k for k in "txyp" if k not in arr.dtype.names]
        if missing:
            raise ConversionError(f"{path}: structured array without fields {missing} (has {list(arr.dtype.names)}); "
                                  "expected fields t, x, y, p")
        n = arr.shape[0]
        cols = lambda a, b: tuple(np.asarray(arr[k][a:b]) for k in "txyp")    # noqa: E731
    else:
        if arr.ndim != 2 or arr.shape[1] != 4 or arr.dtype.kind not in "biuf":
            raise ConversionError(f"{path}: expected an [N, 4] numeric array (columns t, x, y, p), got "
                                  f"{arr.dtype} {arr.shape}; {LAYOUT}")
        n = arr.shape[0]
        cols = lambda a, b: tuple(np.asarray(arr[a:b, k]) for k in range(4))   # noqa: E731
    return n, (cols(a, min(a + CHUNK, n)) for a in range(0, n, CHUNK))


def _h5_chunks(path: Path):
    import h5py

    try:
        f = h5py.File(path, "r")
    except OSError as err:
        raise ConversionError(f"{path}: not a readable HDF5 file ({err})") from None
    group = f["events"] if "events" in f and isinstance(f["events"], h5py.Group) else f
    missing = [k for k in "txyp" if k not in group]
    if missing:
        found = sorted(group.keys())
        f.close()
        raise ConversionError(f"{path}: missing datasets {missing} (expected t, x, y, p at the root or in events/; "
                              f"found {found})")
    ds = [group[k] for k in "txyp"]
    n = ds[0].shape[0]
    if any(d.ndim != 1 or d.shape[0] != n for d in ds):
        f.close()
        raise ConversionError(f"{path}: t, x, y, p must be 1-D of one length, got {[d.shape for d in ds]}")

    def gen():
        try:
            for a in range(0, n, CHUNK):
                yield tuple(d[a:a + CHUNK] for d in ds)
        finally:
            f.close()
    return n, gen()


def _txt_chunks(path: Path):
    def parse(lines, first_line):
        text = "".join(lines)
        try:
            try:
                a = np.loadtxt(io.StringIO(text), dtype=np.int64, comments="#", ndmin=2)
            except ValueError:
                a = np.loadtxt(io.StringIO(text), dtype=np.float64, comments="#", ndmin=2)
        except ValueError as err:
            raise ConversionError(f"{path}: lines {first_line}..{first_line + len(lines) - 1} are not 't x y p' "
                                  f"numbers ({err})") from None
        if a.size == 0:
            return None
        if a.shape[1] != 4:
            raise ConversionError(f"{path}: lines from {first_line} have {a.shape[1]} columns, expected 4 (t x y p)")
        return a[:, 0], a[:, 1], a[:, 2], a[:, 3]

    def gen():
        with open(path) as fh:
            line = 1
            while True:
                lines = list(itertools.islice(fh, CHUNK))
                if not lines:
                    return
                cols = parse(lines, line)
                line += len(lines)
                if cols is not None:
                    yield cols
    return None, gen()


class _Clock:
    """Raw timestamps (one unit) -> float64 seconds since a whole-second origin set by the first one."""

    def __init__(self, unit: str):
        self.unit = unit
        self.per_s = round(1 / TIME_UNITS[unit])
        self.origin_s = None

    def __call__(self, t) -> np.ndarray:
        t = np.asarray(t)
        if t.dtype.kind not in "iuf":
            raise ConversionError(f"timestamps must be numbers, got {t.dtype}")
        if self.origin_s is None:
            first = float(t[0]) / self.per_s
            self.origin_s = int(math.floor(first)) if abs(first) >= LARGE_T else 0
        if t.dtype.kind in "iu":
            return (t.astype(np.int64) - self.origin_s * self.per_s).astype(np.float64) / self.per_s
        return t.astype(np.float64) / self.per_s - self.origin_s


def _whole(v: np.ndarray, name: str, source) -> np.ndarray:
    if v.dtype.kind == "f":
        if not np.all(np.isfinite(v)) or np.any(v != np.round(v)):
            raise ConversionError(f"{source}: {name} coordinates must be whole pixel indices; found fractions or NaN")
    return v.astype(np.int64)


# ---- frames ------------------------------------------------------------------------------

def _frame_list(folder: Path, clock: _Clock) -> list[tuple[float, Path]]:
    listing, images = folder / "frames.txt", folder / "frames"
    if not listing.exists() and not images.exists():
        log.warning("data_fetch: %s has no frames/ and frames.txt; converting the events only", folder)
        return []
    if not listing.exists():
        raise ConversionError(f"{folder}: frames/ is there but frames.txt is missing; write one line per frame: "
                              "'<t> <file name in frames/>', in the events' time unit")
    if not images.is_dir():
        raise ConversionError(f"{folder}: frames.txt is there but the folder frames/ (the PNG files) is missing")
    rows = []
    for k, line in enumerate(listing.read_text().splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        if len(parts) != 2:
            raise ConversionError(f"{listing}: line {k} has {len(parts)} columns, expected '<t> <file name>' "
                                  f"(line reads {line!r})")
        token, name = parts
        try:
            t = np.array([int(token)], np.int64) if token.lstrip("+-").isdigit() else np.array([float(token)])
        except ValueError:
            raise ConversionError(f"{listing}: line {k}: the timestamp {token!r} is not a number") from None
        if not np.all(np.isfinite(t)):
            raise ConversionError(f"{listing}: line {k}: the timestamp {token!r} is not finite")
        path = images / name
        if not path.is_file():
            raise ConversionError(f"{listing}: line {k} names {name}, which is not in {images}/")
        rows.append((float(clock(t)[0]), path))
    if not rows:
        raise ConversionError(f"{listing}: lists no frames; remove frames/ and frames.txt or list the frames")
    times = [t for t, _ in rows]
    if any(b < a for a, b in zip(times, times[1:])):
        raise ConversionError(f"{listing}: timestamps are not in time order; sort the lines by time")
    return rows


def _load_frame(path: Path) -> tuple[np.ndarray, str]:
    """A PNG -> (float64 in [0, 1], kind): [H, W, 3] "rgb" or [H, W] "mosaic"."""
    from PIL import Image

    try:
        with Image.open(path) as im:
            mode = im.mode
            a = np.asarray(im)
    except OSError as err:
        raise ConversionError(f"{path}: not a readable image ({err})") from None
    if a.ndim == 3 and a.shape[-1] in (3, 4):
        if a.dtype != np.uint8:
            raise ConversionError(f"{path}: RGB frames must be 8-bit, got {a.dtype}")
        return a[..., :3].astype(np.float64) / 255.0, "rgb"
    if a.ndim == 2:
        if a.dtype == np.uint8:
            return a.astype(np.float64) / 255.0, "mosaic"
        if a.dtype.kind in "iu" and mode.startswith("I"):
            return a.astype(np.float64) / 65535.0, "mosaic"
    raise ConversionError(f"{path}: expected an RGB PNG [H, W, 3] or a grey Quad Bayer mosaic [H, W], got mode "
                          f"{mode} {a.dtype} {a.shape}")


def _grey_full(frame: np.ndarray, kind: str) -> np.ndarray:
    """The paper's grey frame: one pixel per 4 x 4 tile, weights R : G : B = 1 : 2 : 1."""
    if kind == "rgb":
        frame = frame @ np.array([0.25, 0.5, 0.25])
    return demosaic_grey(frame, block=TILE // 2)


def _uint8(v: np.ndarray) -> np.ndarray:
    return np.clip(np.round(v * 255.0), 0, 255).astype(np.uint8)


# ---- the converter -----------------------------------------------------------------------

def convert_aed(folder, out, *, raw_sensor_size=None, time_unit: str | None = None, C: float = 0.25,
                eval_window=None, dataset: str = "aed", sequence: str | None = None,
                source: str = "ALPIX Event Dataset (AED), ALPIX-Eiger", progress: bool = True) -> Path:
    """Convert one AED sequence folder (layout in the module docstring) to the canonical file.

    Args:
        folder: the sequence folder. out: the ``.h5`` to write (atomically).
        raw_sensor_size: (H, W) of the raw event photosites; default meta.json's
            ``event_sensor_size``, else AED's (1224, 1632). Multiples of 4.
        time_unit: unit of events and frames.txt; default meta.json's, else inferred (integers:
            us, decimals: s).
        C: contrast threshold stored for the demosaiced events (paper: 0.25).
        eval_window: (start, end) s after the sequence's zero, None = whole sequence.
        sequence: name stored in the file (default: the folder's name).

    Returns:
        The path written. Raises ConversionError naming the problem and the expected layout.
    """
    from tqdm.auto import tqdm

    folder = Path(folder).expanduser()
    if not folder.is_dir():
        raise ConversionError(f"{folder}: an AED sequence is a folder, not a file; {LAYOUT}")
    meta = _read_meta(folder)
    events_path = _event_file(folder)
    if raw_sensor_size is None:
        raw_sensor_size = meta.get("event_sensor_size", AED_EVENT_SENSOR)
    H, W = _pair(raw_sensor_size, "event_sensor_size (H, W)", folder / "meta.json")
    if H <= 0 or W <= 0 or H % TILE or W % TILE:
        raise ConversionError(f"raw event sensor (H, W) = {(H, W)} must be positive multiples of the Quad Bayer "
                              f"tile {TILE} (AED: {AED_EVENT_SENSOR}); fix event_sensor_size in meta.json")
    phase = _pair(meta.get("phase", (0, 0)), "phase (dy, dx)", folder / "meta.json")
    h, w = H // TILE, W // TILE

    n, chunks = {"events.npy": _npy_chunks, "events.h5": _h5_chunks, "events.txt": _txt_chunks}[events_path.name](events_path)
    writer = None
    polarity = PolarityMapper(str(events_path))
    bar = tqdm(total=n, unit="ev", unit_scale=True, desc=f"aed {folder.name}", disable=not progress, leave=False)
    try:
        clock = None
        done = 0
        for t_raw, x, y, p in chunks:
            if clock is None:
                unit = time_unit or meta.get("time_unit") or ("us" if np.asarray(t_raw).dtype.kind in "iu" else "s")
                if unit not in TIME_UNITS:
                    raise ConversionError(f"time_unit {unit!r} is not one of {sorted(TIME_UNITS)}")
                clock = _Clock(unit)
            where = f"{events_path.name}, events {done}..{done + len(t_raw) - 1}"
            x, y = _whole(np.asarray(x), "x", where), _whole(np.asarray(y), "y", where)
            for name, v, size, key in (("x", x, W, "W"), ("y", y, H, "H")):
                if v.size and (v.min() < 0 or v.max() >= size):
                    raise ConversionError(
                        f"{where}: {name} spans [{v.min()}, {v.max()}] but the raw event sensor has {key} = {size} "
                        f"(sensor (H, W) = {(H, W)}); set event_sensor_size in meta.json, or check the column order "
                        "t, x, y, p (x = column, y = row)")
            t = clock(t_raw)
            if writer is None:
                writer = CanonicalWriter(
                    out, sensor_size=(h, w), t_origin=float(clock.origin_s), dataset=dataset,
                    sequence=sequence or folder.name, source=source, raw_file=folder.name, C=C,
                    eval_window=eval_window, converter="data_fetch.convert_aed", meta={})
            writer.add_events(t, x // TILE, y // TILE, polarity(np.asarray(p), f" ({where})"), where=where)
            done += len(t)
            bar.update(len(t))
        if writer is None:
            raise ConversionError(f"{events_path}: holds no events")
        span = writer.t_last - writer.t_first
        if clock.unit == "s" and "time_unit" not in meta and time_unit is None and span > 1e4:
            raise ConversionError(f"{events_path}: the events span {span:.3g} s if the timestamps are seconds (an AED "
                                  "sequence lasts about 10 s); if they are microseconds, set \"time_unit\": \"us\" "
                                  "in meta.json")
        frames = _frame_list(folder, clock)
        frame_info = _write_frames(writer, frames, (h, w), folder, span)
        writer.meta.update({
            "raw_event_sensor_size": [H, W], "phase": list(phase), "time_unit": clock.unit,
            "event_reduction": f"(x, y) -> (x // {TILE}, y // {TILE}): every event kept, one grey pixel per "
                               f"{TILE}x{TILE} Quad Bayer tile; each event stands for C_photosite / {TILE * TILE} "
                               "of grey log intensity (evinr_lite.sim.quadbayer)",
            **frame_info})
        path = writer.close()
    finally:
        bar.close()
        if writer is not None:
            writer.abort()
    return path


def _write_frames(writer: CanonicalWriter, frames, event_grid, folder: Path, event_span: float) -> dict:
    """Grey frames at the event grid into frames/, the paper's full grey frames into frames_full/."""
    if not frames:
        return {"frames": "none"}
    h, w = event_grid
    times = np.array([t for t, _ in frames])
    if len(frames) > 1 and event_span > 0:
        t0, t1 = writer.t_first, writer.t_last
        if times[-1] < t0 or times[0] > t1 or (times[-1] - times[0]) < 0.01 * event_span:
            raise ConversionError(
                f"{folder / 'frames.txt'}: the frames span [{times[0]:.6g}, {times[-1]:.6g}] s but the events "
                f"[{t0:.6g}, {t1:.6g}] s (relative to t_origin {writer.t_origin:.0f} s); frames.txt must use the "
                "events' clock and time unit (set time_unit in meta.json)")
    full = None
    kind0 = shape0 = None
    for k, (t, path) in enumerate(frames):
        frame, kind = _load_frame(path)
        if shape0 is None:
            kind0, shape0 = kind, frame.shape
            Hf, Wf = shape0[:2]
            if Hf % TILE or Wf % TILE or (Hf // TILE) % h or (Wf // TILE) % w or \
                    (Hf // TILE) // h != (Wf // TILE) // w or (Hf // TILE) < h:
                raise ConversionError(
                    f"{path}: frames of {Wf} x {Hf} (W x H) do not fit the events: after the {TILE}x{TILE} reduction "
                    f"({Wf / TILE:g} x {Hf / TILE:g}) they must be a whole multiple of the event grid {w} x {h} "
                    f"(AED: 3264 x 2448 frames, 1632 x 1224 events -> 816 x 612 and 408 x 306)")
            factor = (Hf // TILE) // h
        elif (kind, frame.shape) != (kind0, shape0):
            raise ConversionError(f"{path}: a {kind} frame of shape {frame.shape}, but the first frame is a {kind0} "
                                  f"frame of shape {shape0}; all frames of a sequence must match")
        grey = _grey_full(frame, kind)
        writer.add_frame(_uint8(reduce_mean(grey, factor) if factor > 1 else grey), t)
        if factor > 1:
            if full is None:
                full = writer.f.create_dataset("frames_full/images", shape=(0,) + grey.shape,
                                               maxshape=(None,) + grey.shape, dtype=np.uint8,
                                               chunks=(1,) + grey.shape, **COMPRESSION)
            full.resize((k + 1,) + grey.shape)
            full[k] = _uint8(grey)
    if full is not None:
        writer.f.create_dataset("frames_full/t", data=times, dtype=np.float64)
    return {"frame_kind": kind0, "raw_frame_size": list(shape0[:2]),
            "frames_full_size": list(grey.shape) if factor > 1 else None,
            "frame_reduction": f"grey = mean of each {TILE}x{TILE} tile (R:G:B = 1:2:1), then a {factor}x{factor} "
                               "mean to the event grid; frames_full/ holds the grey frames before that last step"}


def write_aed_folder(folder, events, frames=None, frame_times=None, *, phase=(0, 0), overwrite: bool = False) -> Path:
    """Write raw Quad Bayer events (and frames) in the layout :func:`convert_aed` reads.

    For examples and tests, or to bring a recording of your own into this layout. The folder is
    written atomically (a temporary folder renamed into place).

    Args:
        folder: the sequence folder to create.
        events: evinr_lite ``Events`` on the raw photosite grid; written as events.npy [N, 4] int64
            (absolute microseconds t_origin + t, x, y, p as 0/1).
        frames: optional [F, Hf, Wf, 3] uint8 RGB or [F, Hf, Wf] uint8/uint16 mosaics; one PNG each.
        frame_times: [F] seconds on the events' clock (relative to ``events.t_origin``).
        phase: the CFA phase, recorded in meta.json.

    Returns:
        The folder.
    """
    from PIL import Image

    from evinr_lite.io.output import atomic_output_dir

    origin_us = int(round(events.t_origin)) * 10**6
    if events.t_origin != int(round(events.t_origin)):
        raise ConversionError(f"events.t_origin must be whole seconds to write microseconds exactly, got {events.t_origin}")
    t_us = origin_us + np.round(np.asarray(events.t) * 1e6).astype(np.int64)
    meta = {"time_unit": "us", "event_sensor_size": list(events.sensor_size), "phase": [int(v) for v in phase]}
    with atomic_output_dir(folder, overwrite=overwrite) as tmp:
        np.save(tmp / "events.npy", np.stack([t_us, events.x, events.y, (events.p > 0)], axis=1).astype(np.int64))
        (tmp / "meta.json").write_text(json.dumps(meta, indent=2) + "\n")
        if frames is not None:
            frames = np.asarray(frames)
            times = np.asarray(frame_times, dtype=np.float64)
            if times.shape != (len(frames),):
                raise ConversionError(f"{len(frames)} frames but frame_times has shape {times.shape}")
            (tmp / "frames").mkdir()
            lines = []
            for k, (img, t) in enumerate(zip(frames, times)):
                name = f"frame_{k:06d}.png"
                Image.fromarray(img).save(tmp / "frames" / name)
                lines.append(f"{origin_us + int(round(t * 1e6))} {name}\n")
            (tmp / "frames.txt").write_text("".join(lines))
    return Path(folder)
