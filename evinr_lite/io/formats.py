"""Camera vendors' recording formats: AEDAT4 (iniVation DAVIS / DV) and Prophesee .raw / .dat.

Both are decoded by `faery` (a maintained Rust decoder for neuromorphic file formats, which also
writes them; the tests use its writer to make fixtures). Timestamps in these files are integer
microseconds; they are turned into float64 seconds relative to a whole-second ``t_origin`` in
integer arithmetic (exact), as everywhere in the package.

- AEDAT4 (``.aedat4``): the first event track, and the first frame track when present (DAVIS APS
  frames; a frame's time is the timestamp the file gives it). The sensor size is the track's.
- Prophesee EVT 2 / 3 (``.raw``; EVT 2.1 is not decoded by faery yet) and DAT (``.dat``): the sensor size comes from the header
  (``% geometry`` / ``% format ...;width=;height=`` / ``% Width`` ``% Height``); some files carry none,
  and then ``sensor_size`` must be given. No frames.

:func:`sniff_format` tells these formats (and HDF5, .npy, zip) apart by their first bytes.
"""
from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..core.events import LARGE_T, EventDataError, Events
from ..core.frames import Frames

__all__ = ["read_aedat4", "read_prophesee", "sniff_format", "RAW_VERSIONS"]

US = 10**6  # microseconds per second
RAW_VERSIONS = ("evt2", "evt3")   # faery 0.7.1 does not decode EVT 2.1 yet
MAGIC = {  # first bytes -> format name
    b"#!AER-DAT4": "aedat4",
    b"#!AER-DAT3": "aedat3",
    b"#!AER-DAT2": "aedat2",
    b"#!AER-DAT1": "aedat2",
    b"\x89HDF\r\n\x1a\n": "hdf5",
    b"\x93NUMPY": "npy",
    b"PK\x03\x04": "zip",
}


def _decoder_failed(err: BaseException) -> bool:
    """True for what faery's decoders raise on damaged or unsupported input: plain exceptions, and Rust
    panics (pyo3's PanicException derives from BaseException); False for Ctrl-C and exits."""
    return not isinstance(err, (KeyboardInterrupt, SystemExit, GeneratorExit))


@contextmanager
def _decoder_stderr():
    """Catch what faery's Rust code prints on the process's stderr (a panic message, before pyo3
    turns the panic into an exception): dropped when the block raises (the clean EventDataError
    says what went wrong), passed on otherwise."""
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):
        yield
        return
    import tempfile

    failed = False
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        except BaseException:
            failed = True
            raise
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            if not failed:
                tmp.seek(0)
                text = tmp.read()
                if text:
                    sys.stderr.write(text.decode("utf-8", "replace"))


def _prophesee_header(path: Path, limit: int = 1 << 16) -> list[str]:
    """The `% ...` header lines at the start of a Prophesee file (without the '% ')."""
    lines = []
    with open(path, "rb") as f:
        head = f.read(limit)
    pos = 0
    while pos < len(head) and head[pos:pos + 1] == b"%":
        end = head.find(b"\n", pos)
        if end < 0:
            break
        lines.append(head[pos + 1:end].decode("latin-1").strip())
        pos = end + 1
        if lines[-1].lower() == "end":
            break
    return lines


def sniff_format(path) -> str | None:
    """The format of a file from its first bytes: 'aedat4', 'aedat2', 'aedat3', 'hdf5', 'npy',
    'zip', 'prophesee_raw', 'prophesee_dat', or None (not recognised: maybe text)."""
    path = Path(path)
    with open(path, "rb") as f:
        head = f.read(16)
    for magic, name in MAGIC.items():
        if head.startswith(magic):
            return name
    if head.startswith(b"%"):
        header = [line.lower() for line in _prophesee_header(path)]
        if any(line.startswith(("evt ", "format evt")) for line in header):
            return "prophesee_raw"
        if any(line.startswith(("data file containing", "version ")) for line in header):
            return "prophesee_dat"
        suffix = path.suffix.lower()
        return {".raw": "prophesee_raw", ".dat": "prophesee_dat"}.get(suffix)
    return None


# ---- microseconds -> Events, a packet at a time -------------------------------------------

class _Collector:
    """Gathers decoded packets (structured arrays with t [us], x, y, on) inside a time window.

    The clock's origin (whole seconds of the first event on an absolute clock, else 0) is fixed
    by the first packet; the window [t_start, t_end) is in seconds relative to it.
    """

    def __init__(self, t_start, t_end):
        if t_start is not None and t_end is not None and t_end <= t_start:
            raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
        self.t_start, self.t_end = t_start, t_end
        self.origin_us: int | None = None
        self.parts: list[tuple] = []
        self.n_seen = 0
        self.span_us = [None, None]

    def seconds(self, t_us: np.ndarray) -> np.ndarray:
        return (t_us.astype(np.int64) - self.origin_us) / US

    def add(self, packet: np.ndarray) -> bool:
        """Keep the packet's events inside the window; False once the window is passed."""
        if len(packet) == 0:
            return True
        t_us = packet["t"]
        if self.origin_us is None:
            first = int(t_us[0])
            self.origin_us = (first // US) * US if first >= LARGE_T * US else 0
        self.span_us[0] = int(t_us[0]) if self.span_us[0] is None else self.span_us[0]
        self.span_us[1] = int(t_us[-1])
        self.n_seen += len(packet)
        t = self.seconds(t_us)
        keep = np.ones(len(t), bool)
        if self.t_start is not None:
            keep &= t >= self.t_start
        if self.t_end is not None:
            keep &= t < self.t_end
        if keep.any():
            self.parts.append((t[keep], packet["x"][keep], packet["y"][keep], packet["on"][keep]))
        return self.t_end is None or t.min() < self.t_end

    def events(self, path, sensor_size) -> Events:
        windowed = self.t_start is not None or self.t_end is not None
        if not self.parts and windowed:
            if self.n_seen:
                lo, hi = self.seconds(np.array(self.span_us))
                span = f"[{lo:.6f}, {hi:.6f}] s (relative to t_origin = {self.origin_us // US})"
            else:
                span = "nothing (the file has no events)"
            raise EventDataError(f"{path}: no events in the window [{self.t_start}, {self.t_end}) s; the events "
                                 f"cover {span}; choose a window inside that range")
        if not self.parts:
            return Events.empty(sensor_size)
        t, x, y, on = (np.concatenate(c) for c in zip(*self.parts))
        try:  # packets are sorted in time; a stable sort repairs rare out-of-order packets
            return Events.from_arrays(t, x, y, on, sensor_size, polarity="bool", sort=True,
                                      t_origin=float(self.origin_us // US))
        except EventDataError as err:
            raise EventDataError(f"{path}: {err}") from None


def _check_size(path, declared, sensor_size, where: str):
    """The file's (H, W), or an error when a different sensor_size was asked for."""
    if sensor_size is not None and tuple(int(v) for v in sensor_size) != declared:
        H, W = declared
        raise EventDataError(f"{path}: the {where} says the sensor is (H, W) = {declared} ({H}x{W}), but sensor "
                             f"size {tuple(int(v) for v in sensor_size)} was given; leave the sensor size out "
                             "(the file's is used) or pass the file's")
    return declared


def _check_aedat4_header(path: Path) -> None:
    """Check what faery 0.7.1 cannot survive: its decoder aborts the whole process (a Rust panic
    inside a panic) when the header's description XML is not UTF-8, so the header is read here first:
    its size must fit in the file and its XML must decode."""
    size_on_disk = path.stat().st_size
    with open(path, "rb") as f:
        head = f.read(18)
        if len(head) < 18 or not head.startswith(b"#!AER-DAT4"):
            raise EventDataError(f"{path}: not an AEDAT4 file (no `#!AER-DAT4` header); the file is damaged or not AEDAT4")
        n = int.from_bytes(head[14:18], "little", signed=True)
        if n <= 0 or 18 + n > size_on_disk:
            raise EventDataError(f"{path}: the AEDAT4 header claims {n} bytes but the file holds {size_on_disk}; the "
                                 "file is damaged or truncated")
        region = f.read(min(n, 1 << 24))
    start = region.find(b"<")
    xml = region[start:].split(b"\0")[0] if start >= 0 else b""
    try:
        xml.decode("utf-8")
    except UnicodeDecodeError as err:
        raise EventDataError(f"{path}: the AEDAT4 header's description is not valid text ({err}); the file is "
                             "damaged") from None


def _existing_file(path) -> Path:
    path = Path(path)
    if not path.is_file():
        raise EventDataError(f"no such file: {path}; check the path")
    return path


# ---- AEDAT4 ---------------------------------------------------------------------------------

def read_aedat4(path, *, sensor_size=None, t_start: float | None = None, t_end: float | None = None):
    """An AEDAT4 recording (DV software, DAVIS / DVXplorer cameras) as a Recording.

    Args:
        path: the ``.aedat4`` file.
        sensor_size: (H, W) to check against the file's (optional; a mismatch is an error).
        t_start, t_end: seconds relative to ``t_origin`` (the whole seconds of the first event on
            an absolute clock); only events and frames with t_start <= t < t_end are kept. The
            file is decoded packet by packet, so memory holds only the window.
    Returns:
        Recording(events, frames or None, meta) with meta["format"] = "aedat4" and the tracks.
    Raises:
        EventDataError for a damaged or truncated file (the decoder's own messages are not printed).
    """
    with _decoder_stderr():
        return _read_aedat4(path, sensor_size=sensor_size, t_start=t_start, t_end=t_end)


def _read_aedat4(path, *, sensor_size=None, t_start: float | None = None, t_end: float | None = None):
    """:func:`read_aedat4`'s body, run inside its guard of the decoder's stderr."""
    from faery.extension import aedat

    from ..core.recording import Recording
    from ..core.frames import to_grey_uint8 as _to_grey_uint8

    path = _existing_file(path)
    _check_aedat4_header(path)
    try:
        decoder = aedat.Decoder(path)
    except BaseException as err:
        if not _decoder_failed(err):
            raise
        raise EventDataError(f"{path}: not a readable AEDAT4 file ({err}); the file is damaged or not AEDAT4") from None
    with decoder:
        tracks = decoder.tracks()
        event_tracks = [tr for tr in tracks if tr.data_type == "events"]
        if not event_tracks:
            raise EventDataError(f"{path}: the AEDAT4 file has no event track (tracks: "
                                 f"{[tr.data_type for tr in tracks]}); record events with DV")
        events_track = event_tracks[0]
        frame_track = next((tr for tr in tracks if tr.data_type == "frame"), None)
        W, H = events_track.dimensions
        size = _check_size(path, (int(H), int(W)), sensor_size, "event track")
        collect = _Collector(t_start, t_end)
        frame_t, frame_images = [], []
        try:
            for track, packet in decoder:
                if track.id == events_track.id:
                    if not collect.add(packet):
                        break
                elif frame_track is not None and track.id == frame_track.id:
                    frame_t.append(int(packet.t))
                    frame_images.append(_to_grey_uint8(packet.pixels, f"{path}: frame at {packet.t} us"))
        except BaseException as err:
            if isinstance(err, EventDataError) or not _decoder_failed(err):
                raise
            raise EventDataError(f"{path}: the AEDAT4 file is damaged or truncated ({err})") from None
    events = collect.events(path, size)
    frames = None
    if frame_images:
        if collect.origin_us is None:  # frames but no events: the frames set the clock
            collect.origin_us = (frame_t[0] // US) * US if frame_t[0] >= LARGE_T * US else 0
        shapes = {im.shape for im in frame_images}
        if shapes != {size}:
            raise EventDataError(f"{path}: frames are {sorted(shapes)} but the events' sensor is {size} (H, W); "
                                 "frames with a region of interest are not supported")
        frames = Frames(np.stack(frame_images), collect.seconds(np.array(frame_t, np.int64)),
                        float(collect.origin_us // US)).sorted().slice_time(t_start, t_end)
        frames = frames if len(frames) else None
    meta = {"format": "aedat4", "path": str(path),
            "tracks": [{"id": tr.id, "type": tr.data_type, "dimensions": tr.dimensions} for tr in tracks]}
    return Recording(events, frames, meta)


# ---- Prophesee ------------------------------------------------------------------------------

def read_prophesee(path, *, sensor_size=None, version: str | None = None,
                   t_start: float | None = None, t_end: float | None = None):
    """A Prophesee recording: EVT 2 / 3 ``.raw`` or DAT ``.dat`` (CD events) as a Recording.

    See :func:`_read_prophesee` for the arguments; the decoder's own messages (Rust panics on
    damaged input) are not printed, the EventDataError says what is wrong.
    """
    with _decoder_stderr():
        return _read_prophesee(path, sensor_size=sensor_size, version=version, t_start=t_start, t_end=t_end)


def _read_prophesee(path, *, sensor_size=None, version: str | None = None,
                    t_start: float | None = None, t_end: float | None = None):
    """A Prophesee recording: EVT 2 / 2.1 / 3 ``.raw`` or DAT ``.dat`` (CD events) as a Recording.

    Args:
        path: the file.
        sensor_size: (H, W); needed only when the header does not give the size (then it is an
            error to leave it out); checked against the header otherwise.
        version: for a .raw whose header does not name its encoding: "evt2", "evt2.1" or "evt3"
            (default "evt3"); ignored when the header names it.
        t_start, t_end: seconds relative to ``t_origin``; see :func:`read_aedat4`.
    Returns:
        Recording(events, None, meta) with meta["format"] = "prophesee_raw" or "prophesee_dat".
    """
    from faery.extension import dat, evt

    from ..core.recording import Recording

    path = _existing_file(path)
    kind = sniff_format(path) or {".raw": "prophesee_raw", ".dat": "prophesee_dat"}.get(path.suffix.lower())
    if kind not in ("prophesee_raw", "prophesee_dat"):
        raise EventDataError(f"{path}: not a Prophesee .raw or .dat file (no `%` header and no .raw/.dat extension)")
    if version is not None and version not in RAW_VERSIONS:
        raise EventDataError(f"version must be one of {RAW_VERSIONS}, got {version!r}")
    module, fallback_version = (evt, version or "evt3") if kind == "prophesee_raw" else (dat, "dat2")
    fallback_size = None if sensor_size is None else (int(sensor_size[1]), int(sensor_size[0]))  # (W, H)

    def open_decoder(size):
        return module.Decoder(path, size, fallback_version)

    try:
        decoder = open_decoder(None)
        header_size = True
    except BaseException as err:
        if not _decoder_failed(err):
            raise
        if "size" not in str(err):
            raise EventDataError(f"{path}: not a readable Prophesee file ({err})") from None
        header_size = False
        if fallback_size is None:
            raise EventDataError(f"{path}: the header does not give the sensor size; pass sensor_size=(H, W), "
                                 "e.g. (720, 1280) for an IMX636 / "
                                 "Gen4 sensor, (480, 640) for Gen3") from None
        decoder = open_decoder(fallback_size)
    with decoder:
        W, H = decoder.dimensions
        size = (int(H), int(W))
        if header_size:
            size = _check_size(path, size, sensor_size, "header")
        if kind == "prophesee_dat" and getattr(decoder, "event_type", "cd") != "cd":
            raise EventDataError(f"{path}: a DAT file of {decoder.event_type!r} events; only CD (change "
                                 "detection) events can be reconstructed")
        collect = _Collector(t_start, t_end)
        try:
            for packet in decoder:
                if kind == "prophesee_raw":
                    packet = packet.get("events")
                    if packet is None:
                        continue
                else:
                    packet = _dat_to_events(packet)
                if not collect.add(packet):
                    break
        except BaseException as err:
            if not _decoder_failed(err):
                raise
            if "overflow" in str(err):
                raise EventDataError(f"{path}: events lie outside the sensor size {size} (H, W) ({err}); pass the "
                                     "camera's real sensor size") from None
            hint = ("; if the header does not name the encoding (EVT 3 is assumed), pass version='evt2'"
                    if kind == "prophesee_raw" else "")
            raise EventDataError(f"{path}: could not decode the events ({err}){hint}") from None
        encoding = getattr(decoder, "version", fallback_version)
    events = collect.events(path, size)
    meta = {"format": kind, "path": str(path), "encoding": encoding,
            "sensor_size_from": "header" if header_size else "sensor_size argument"}
    return Recording(events, None, meta)


def _dat_to_events(packet: np.ndarray) -> np.ndarray:
    """DAT CD packet (t, x, y, payload 0/1) -> the (t, x, y, on) layout of the other decoders."""
    out = np.empty(len(packet), dtype=[("t", "<u8"), ("x", "<u2"), ("y", "<u2"), ("on", "?")])
    out["t"], out["x"], out["y"] = packet["t"], packet["x"], packet["y"]
    out["on"] = packet["payload"] > 0
    return out
