"""IJRR / Event Camera Dataset text release (a .zip or its unzipped folder) -> canonical file.

events.txt (`t x y p` per line, p in {0, 1}) is read in blocks of whole lines and parsed with
evinr_lite.io.text's vectorised parser (the one the reader uses) (exact: timestamps are split into whole seconds and
nanoseconds as integers before the whole-second origin is subtracted), so a multi-GB events.txt
inside the zip is never held in memory. Frames come from images.txt + images/*.png, the
calibration from calib.txt (kept in the file's meta).
"""
from __future__ import annotations

import io
import logging
import zipfile
import zlib
from pathlib import Path, PurePosixPath

import numpy as np

from evinr_lite.core.events import EventDataError
from evinr_lite.core.frames import to_grey_uint8
from evinr_lite.io.text import NS, blank_leading_comments, parse_event_block, parse_frame_list

from .canonical import CanonicalWriter
from .errors import ConversionError

__all__ = ["convert_ijrr", "IJRRSource", "PolarityMapper"]

log = logging.getLogger("data_fetch")
BLOCK_BYTES = 2 << 20   # events.txt is parsed 2 MiB of whole lines at a time (bounded memory, cache-friendly)


class PolarityMapper:
    """Map raw polarities to -1/+1 consistently over a whole file read in pieces.

    Accepts {0, 1}, {-1, +1} and bool; a file mixing 0 and -1 is refused (it is ambiguous).
    """

    def __init__(self, source: str):
        self.source = source
        self.seen: set[int] = set()

    def __call__(self, p, where: str = "") -> np.ndarray:
        p = np.asarray(p)
        if p.dtype == bool:
            return np.where(p, 1, -1).astype(np.int8)
        values = set(np.unique(p).tolist())
        if not values <= {-1, 0, 1}:
            bad = sorted(values - {-1, 0, 1})[:6]
            raise ConversionError(f"{self.source}{where}: polarity values {bad} are not 0/1 or -1/+1; "
                                  "the file is not an event file of this format or is damaged")
        self.seen |= values
        if 0 in self.seen and -1 in self.seen:
            raise ConversionError(f"{self.source}{where}: polarities mix 0 and -1, so OFF events are encoded "
                                  "two ways; fix the file (OFF must be 0 everywhere, or -1 everywhere)")
        return np.where(p > 0, 1, -1).astype(np.int8)


class IJRRSource:
    """Files of an IJRR sequence inside a zip (at its root or in one sub-folder) or a folder."""

    def __init__(self, path):
        self.path = Path(path)
        self.zip = None
        if self.path.is_dir():
            self.names = [p.relative_to(self.path).as_posix() for p in self.path.rglob("*") if p.is_file()]
        else:
            try:
                self.zip = zipfile.ZipFile(self.path)
            except (zipfile.BadZipFile, OSError) as err:
                raise ConversionError(f"{self.path}: not a readable zip archive ({err}); the download is damaged "
                                      "or incomplete: delete the file and run the command again to download it "
                                      "anew") from None
            self.names = [n for n in self.zip.namelist() if not n.endswith("/") and "__MACOSX" not in n]
        events = sorted((n for n in self.names if PurePosixPath(n).name == "events.txt"),
                        key=lambda n: (n.count("/"), n))
        if not events:
            raise ConversionError(f"{self.path}: no events.txt inside; an IJRR sequence holds events.txt, "
                                  "images.txt, images/ and calib.txt")
        self.prefix = str(PurePosixPath(events[0]).parent)
        self.prefix = "" if self.prefix == "." else self.prefix + "/"

    def member(self, name: str) -> str | None:
        full = self.prefix + name
        return full if full in self.names else None

    def size(self, member: str) -> int:
        if self.zip is not None:
            return self.zip.getinfo(member).file_size
        return (self.path / member).stat().st_size

    def open(self, member: str):
        if self.zip is not None:
            return self.zip.open(member)
        return open(self.path / member, "rb")

    def read(self, member: str) -> bytes:
        with self.open(member) as f:
            return f.read()

    def close(self):
        if self.zip is not None:
            self.zip.close()


def _blocks(fh, size: int):
    """Blocks of whole lines read from a binary stream: yields bytes ending at a newline (or EOF)."""
    rest = b""
    while True:
        data = fh.read(size)
        if not data:
            if rest:
                yield rest
            return
        data = rest + data
        cut = data.rfind(b"\n")
        if cut < 0:
            rest = data
            continue
        yield data[:cut + 1]
        rest = data[cut + 1:]


def _damaged(src: IJRRSource, member: str, err) -> ConversionError:
    return ConversionError(f"{src.path}: {member} cannot be read ({type(err).__name__}: {err}); the archive is "
                           "damaged or was cut off: delete it and run the command again to download it anew")


def _frame_list(src: IJRRSource, origin_ns: int, time_unit: str = "s"):
    """[(t seconds since origin, member name)] from images.txt."""
    listing = src.member("images.txt")
    if listing is None:
        return []
    try:
        t, names, _ = parse_frame_list(src.read(listing), origin_ns, source=f"{src.path}: images.txt",
                                       time_unit=time_unit)
    except EventDataError as err:
        raise ConversionError(str(err)) from None
    return list(zip(t.tolist(), names))


def _load_image(src: IJRRSource, name: str) -> np.ndarray:
    from PIL import Image

    member = src.member(name)
    if member is None:
        raise ConversionError(f"{src.path}: images.txt lists {name}, which is not in the archive; the archive is "
                              "incomplete: delete it and download it again")
    try:
        with Image.open(io.BytesIO(src.read(member))) as im:
            array = np.asarray(im)
    except (zipfile.BadZipFile, zlib.error, EOFError) as err:
        raise _damaged(src, member, err) from None
    except OSError as err:
        raise ConversionError(f"{src.path}: {member} is not a readable image ({err}); the archive is damaged: "
                              "delete it and download it again") from None
    try:
        return to_grey_uint8(array, f"{src.path}:{member}")
    except EventDataError as err:
        raise ConversionError(str(err)) from None


def _parse_block(block: bytes, origin_ns, line_base: int, src, first: bool, time_unit: str = "s"):
    """One block of whole lines -> (t, x, y, p raw or None, header (H, W) or None, origin_ns, n_lines, unit)."""
    try:
        b = parse_event_block(block, origin_ns, source=f"{src.path}: events.txt", line_base=line_base, first=first,
                              time_unit=time_unit)
    except EventDataError as err:
        raise ConversionError(str(err)) from None
    parsed = (b.t, b.x, b.y, b.p) if len(b.t) else None
    return parsed, b.header, b.origin_ns, b.n_lines, (b.time_unit if parsed is not None else time_unit)


def convert_ijrr(path, out, *, sensor_size=None, C: float = 1.0, eval_window=None, dataset: str = "ijrr",
                 sequence: str | None = None, source: str = "", source_url: str = "",
                 progress: bool = True, t_origin=None, time_unit: str = "auto") -> Path:
    """Convert an IJRR text sequence (zip or folder) to the canonical file ``out``.

    Args:
        path: ``<sequence>.zip`` as downloaded, or the unzipped folder.
        out: canonical ``.h5`` to write (atomically).
        sensor_size: (H, W); None: from a `W H` header line or the frames.
        C, eval_window, dataset, sequence, source, source_url: stored as attributes.
        t_origin: seconds subtracted from all timestamps; None: the whole seconds of the first
            event when the clock is absolute (>= 1e5 s), else 0.
        time_unit: unit of events.txt and images.txt timestamps ('s', 'ms', 'us', 'ns'); 'auto':
            decimals are seconds, plain integers microseconds (with a warning).
    """
    from tqdm.auto import tqdm

    path = Path(path)
    src = IJRRSource(path)
    try:
        sequence = sequence or (path.stem if path.is_file() else path.name)
        origin_ns = None if t_origin is None else int(round(t_origin * NS))
        events_member = src.member("events.txt")
        # The sensor size must be known before the first event is checked: take it from the frames.
        frame_size = None
        listing = _frame_list(src, 0)
        if listing:
            frame_size = _load_image(src, listing[0][1]).shape
        if sensor_size is not None:
            sensor_size = tuple(int(v) for v in sensor_size)
            if frame_size is not None and frame_size != sensor_size:
                raise ConversionError(f"{path}: the frames are {frame_size} (H, W) but the sensor size is "
                                      f"{sensor_size}; pass the right sensor size")
        calib = None
        calib_member = src.member("calib.txt")
        if calib_member:
            values = src.read(calib_member).split()
            try:
                values = [float(v) for v in values]
                names = ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")
                calib = dict(zip(names, values)) if len(values) == len(names) else values
            except ValueError:
                log.warning("data_fetch: %s: calib.txt is not a list of numbers; ignored", path)
        meta = {"calib": calib} if calib is not None else {}
        polarity = PolarityMapper(f"{path}: events.txt")
        writer = None
        line_base, first = 0, True
        bar = tqdm(total=src.size(events_member), unit="B", unit_scale=True, unit_divisor=1024,
                   desc=f"{sequence}: events.txt", disable=not progress)
        try:
            with src.open(events_member) as fh:
                for block in _blocks(fh, BLOCK_BYTES):
                    bar.update(len(block))
                    if first:   # `#` / `%` notes on top, as evinr-lite's own reader skips them
                        block, _ = blank_leading_comments(block)
                    parsed, header, origin_ns, n_lines, time_unit = _parse_block(block, origin_ns, line_base, src,
                                                                                 first, time_unit)
                    if first and header is not None:
                        if sensor_size is not None and header != sensor_size:
                            raise ConversionError(f"{path}: events.txt's header `{header[1]} {header[0]}` (W H) "
                                                  f"disagrees with the sensor size {sensor_size} (H, W)")
                        sensor_size = header
                    first = False
                    if parsed is not None:
                        t, x, y, p = parsed
                        if writer is None:
                            size = sensor_size or frame_size
                            if size is None:
                                raise ConversionError(
                                    f"{path}: the sensor size is unknown (no frames, no `W H` header); pass "
                                    "sensor_size=(H, W) (e.g. --sensor-size 180 240 for a DAVIS240C)")
                            writer = CanonicalWriter(
                                out, sensor_size=size, t_origin=origin_ns / NS, dataset=dataset,
                                sequence=sequence, source=source, source_url=source_url, raw_file=path.name,
                                C=C, eval_window=eval_window, converter="data_fetch.convert_ijrr", meta=meta)
                        writer.add_events(t, x, y, polarity(p, f", events.txt lines {line_base + 1}.."),
                                          where=f"events.txt lines {line_base + 1}-{line_base + n_lines}")
                    line_base += n_lines
            if writer is None:
                raise ConversionError(f"{path}: events.txt holds no events")
            for t_frame, name in _frame_list(src, origin_ns, "s" if time_unit == "auto" else time_unit):
                writer.add_frame(_load_image(src, name), t_frame)
            return writer.close()
        except (zipfile.BadZipFile, zlib.error, EOFError) as err:
            raise _damaged(src, events_member, err) from None
        finally:
            bar.close()
            if writer is not None:
                writer.abort()
    finally:
        src.close()
