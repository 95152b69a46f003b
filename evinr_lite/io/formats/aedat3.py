"""AEDAT 3.1 (``.aedat``): recordings of iniVation's cAER / libcaer (DVS128, DAVIS240, DAVIS346, ...; the
DVS128 Gesture dataset among them), decoded here with numpy.

The layout is libcaer's (its event definitions, ``include/libcaer/events/*.h``), little-endian:

- a text header of lines opened by '#': the first ``#!AER-DAT3.1``, the last ``#!END-HEADER``;
  ``#Format: RAW`` (a compressed format is refused), ``#Source N: NAME`` naming source N's device;
- then packets: a 28-byte header (int16 eventType, int16 eventSource, int32 eventSize, int32
  eventTSOffset, int32 eventTSOverflow, int32 eventCapacity, int32 eventNumber, int32 eventValid) and
  the events, eventSize bytes each. libcaer's packet holds eventCapacity slots of which eventNumber are
  used; a file written from it holds one or the other, so where they differ the next packet's header
  tells which (:func:`_payload_bytes`);
- POLARITY_EVENT (type 1), 8 bytes: uint32 data (bit 0 valid, bit 1 polarity (1: ON), bits 2-16 y,
  bits 17-31 x) and int32 timestamp;
- FRAME_EVENT (type 2): uint32 info (bit 0 valid, bits 1-3 the colour channels, bits 4-7 the colour
  filter), int32 ts_startframe, ts_endframe, ts_startexposure, ts_endexposure, lengthX, lengthY,
  positionX, positionY, then uint16 pixels row by row from the top;
- a timestamp is (eventTSOverflow << 31) | timestamp, in microseconds.

(0, 0) is the upper-left pixel, x the column and y the row, as everywhere in the kit. Invalid events
(valid bit 0) are skipped. The events of the first source that records polarity events are read, with
its full-sensor grey frames (a frame's time is the middle of its exposure; frames with a region of
interest or a colour filter are skipped and counted in ``meta["frames_skipped"]``). The sensor size
comes from the source's device name, from ``dvsSizeX`` / ``dvsSizeY`` in the header, or from
``sensor_size``. AEDAT 3.0 and 2.0 (jAER), whose coordinate conventions differ by device and version,
are not read: DV converts them to AEDAT4.
"""
from __future__ import annotations

import re
import struct
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ...core.events import EventDataError
from ...core.frames import to_grey_uint8
from .base import FileFormat, check_reader_window, declared_or_given_size, existing, file_path
from .packets import PacketSource, frames_from, read_packets

__all__ = ["read_aedat3", "open_aedat3", "aedat3_header", "PacketHeader", "MAGIC", "DEVICE_SIZES", "FORMAT"]

MAGIC = b"#!AER-DAT3.1"
END_HEADER = b"#!END-HEADER"
HEADER_LIMIT = 1 << 20              # bytes searched for the header's end
POLARITY, FRAME = 1, 2
POLARITY_EVENT = np.dtype([("data", "<u4"), ("ts", "<i4")])
FRAME_FIELDS = 9                    # int32 info and eight int32 fields before a frame's pixels
EVENT_DTYPE = np.dtype([("t", "<u8"), ("x", "<u2"), ("y", "<u2"), ("on", "?")])
BATCH_EVENTS = 1 << 16              # polarity packets are handed on in batches of at least this many events
DEVICE_SIZES = {                    # (H, W) of the devices libcaer names in '#Source N: NAME', by prefix
    "DVS128": (128, 128), "DAVIS128": (128, 128), "DAVIS208": (192, 208), "DAVIS240": (180, 240),
    "DAVIS346": (260, 346), "DAVIS640": (480, 640),
}
_FIX = ("convert it with iniVation's DV software (Convert to AEDAT4), which evinr-lite reads, or export the "
        "events to a `t x y p` text file")


def aedat3_header(path: Path) -> tuple[list[str], int]:
    """The header's lines (without the '#', stripped) and the byte where the packets start."""
    with open(file_path(path), "rb") as f:
        head = f.read(HEADER_LIMIT)
    if not head.startswith(MAGIC):
        raise EventDataError(f"{path}: not an AEDAT 3.1 file (no `#!AER-DAT3.1` first line); {_FIX}")
    end = head.find(END_HEADER)
    if end < 0:
        raise EventDataError(f"{path}: the AEDAT 3.1 header has no `#!END-HEADER` line in its first "
                             f"{HEADER_LIMIT >> 20} MiB; the file is damaged or truncated")
    stop = head.find(b"\n", end)
    start = len(head) if stop < 0 else stop + 1
    lines = [line.decode("latin-1").strip().lstrip("#").strip() for line in head[:end].split(b"\n")]
    return [line for line in lines if line], start


def _header_fields(path: Path, lines: list[str]) -> tuple[dict, tuple | None]:
    """({source id: device name}, (H, W) from ``dvsSizeX`` / ``dvsSizeY`` or None); refuses a compressed format."""
    sources, width, height = {}, None, None
    for line in lines:
        m = re.match(r"format\s*:\s*(\S+)", line, re.IGNORECASE)
        if m and m.group(1).upper() != "RAW":
            raise EventDataError(f"{path}: an AEDAT 3.1 file in the {m.group(1)!r} format, which is not read "
                                 f"(only RAW); {_FIX}")
        m = re.match(r"-?source\s+(-?[0-9]+)\s*:\s*(.*)$", line, re.IGNORECASE)
        if m and m.group(2).strip() and not m.group(2).lstrip().startswith("<"):
            sources.setdefault(int(m.group(1)), m.group(2).strip())
        for key, value in re.findall(r'key="dvsSize([XY])"[^>]*>\s*([0-9]+)\s*<', line):
            width, height = (int(value), height) if key == "X" else (width, int(value))
    return sources, ((height, width) if width and height else None)


def _device_size(name: str | None):
    """(H, W) of a device libcaer names (``DAVIS346B``, ``DVS128``, ...), or None when unknown."""
    key = re.sub(r"[^A-Z0-9]", "", (name or "").upper())
    return next((size for prefix, size in DEVICE_SIZES.items() if key.startswith(prefix)), None)


class PacketHeader(NamedTuple):
    """A packet's 28-byte header (libcaer's caer_event_packet_header)."""
    type: int
    source: int
    size: int
    ts_offset: int
    overflow: int
    capacity: int
    number: int
    valid: int


_HEADER = struct.Struct("<hhiiiiii")


def _plausible_header(h: PacketHeader) -> bool:
    """Whether 28 bytes read as a packet header fit libcaer's rules (a type it defines or a user type,
    a positive event size with the timestamp inside it, eventValid <= eventNumber <= eventCapacity)."""
    return (h.type >= 0 and 0 < h.size <= 1 << 26 and 0 <= h.ts_offset <= h.size - 4 and h.overflow >= 0
            and 0 <= h.valid <= h.number <= h.capacity)


def _payload_bytes(f, h: PacketHeader, here: int, file_size: int, path: Path) -> int:
    """The bytes of events after the packet header ``h`` (the packet's header ends at ``here``): eventCapacity
    x eventSize, or eventNumber x eventSize where the file stores only the used slots; when they differ, the
    one after which the next packet's header fits (or the file ends) is taken."""
    if h.capacity == h.number:
        return h.number * h.size
    fits = []
    for n in (h.number * h.size, h.capacity * h.size):
        if here + n == file_size:
            fits.append(n)
        elif here + n + _HEADER.size <= file_size:
            f.seek(here + n)
            if _plausible_header(PacketHeader(*_HEADER.unpack(f.read(_HEADER.size)))):
                fits.append(n)
    f.seek(here)
    if len(fits) == 1:
        return fits[0]
    at = here - _HEADER.size
    if not fits:
        raise EventDataError(f"{path}: the AEDAT 3.1 packet at byte {at:,} claims {h.capacity * h.size:,} bytes of "
                             "events but no packet follows them (a truncated or damaged file); copy the file again")
    raise EventDataError(f"{path}: the AEDAT 3.1 packet at byte {at:,} can be read two ways (with its used and with "
                         "all its event slots); the file is ambiguous or damaged")


def _packet_headers(f, start: int, file_size: int, path: Path):
    """Yield (header, payload bytes) of every packet from ``start``, the file positioned at the payload."""
    pos = start
    f.seek(pos)
    while pos < file_size:
        if pos + _HEADER.size > file_size:
            raise EventDataError(f"{path}: the AEDAT 3.1 file ends inside a packet header at byte {pos:,} (a "
                                 "truncated copy?); copy the file again")
        if f.tell() != pos:
            f.seek(pos)
        h = PacketHeader(*_HEADER.unpack(f.read(_HEADER.size)))
        if not _plausible_header(h):
            raise EventDataError(f"{path}: bytes {pos:,}.. are not an AEDAT 3.1 packet header (type {h.type}, "
                                 f"event size {h.size}); the file is damaged")
        here = pos + _HEADER.size
        n = _payload_bytes(f, h, here, file_size, path)
        if here + n > file_size:
            raise EventDataError(f"{path}: the AEDAT 3.1 packet at byte {pos:,} claims {n:,} bytes of events but the "
                                 f"file ends {file_size - here:,} bytes after its header (a truncated copy?); copy the "
                                 "file again")
        yield h, n
        pos = here + n


def _polarity(parts: list, path: Path) -> np.ndarray:
    """The valid events of polarity packets ``parts`` [(header, payload bytes)] as EVENT_DTYPE (t in
    microseconds), each packet's first eventNumber slots, decoded together."""
    for h, _ in parts:
        if h.size != POLARITY_EVENT.itemsize or h.ts_offset != 4:
            raise EventDataError(f"{path}: a polarity packet with {h.size}-byte events (libcaer's are 8 bytes, the "
                                 "timestamp at byte 4); the file is damaged or not AEDAT 3.1")
    used = [raw[:POLARITY_EVENT.itemsize * h.number] for h, raw in parts]
    ev = np.frombuffer(b"".join(used), POLARITY_EVENT)
    high = np.repeat(np.array([h.overflow for h, _ in parts], np.uint64) << np.uint64(31),
                     [len(u) // POLARITY_EVENT.itemsize for u in used])
    valid = (ev["data"] & 1) == 1
    ev, high = ev[valid], high[valid]
    if len(ev) and ev["ts"].min() < 0:          # libcaer's timestamps count up from 0 in 31 bits
        raise EventDataError(f"{path}: a polarity event with a negative timestamp ({int(ev['ts'].min())}); the file "
                             "is damaged")
    out = np.empty(len(ev), EVENT_DTYPE)
    out["t"] = high | ev["ts"].astype(np.uint64)
    out["x"] = (ev["data"] >> 17) & 0x7FFF
    out["y"] = (ev["data"] >> 2) & 0x7FFF
    out["on"] = (ev["data"] >> 1) & 1 == 1
    return out


def _frames(raw: bytes, h: PacketHeader, size, path: Path, meta: dict):
    """(t_us, grey uint8 [H, W]) of one frame packet's valid full-sensor grey frames (the middle of the
    exposure); frames with a region of interest or a colour filter are counted in meta["frames_skipped"]."""
    step = h.size
    if step < 4 * FRAME_FIELDS:
        raise EventDataError(f"{path}: a frame packet with {step}-byte events (a frame event's fields alone take "
                             f"{4 * FRAME_FIELDS}); the file is damaged")
    for k in range(min(h.number, len(raw) // step)):     # the used slots
        fields = np.frombuffer(raw, "<i4", FRAME_FIELDS, k * step)
        info = int(fields[0]) & 0xFFFFFFFF
        if not info & 1:
            continue
        channels, colour_filter = (info >> 1) & 0x7, (info >> 4) & 0xF
        length_x, length_y, pos_x, pos_y = (int(v) for v in fields[5:9])
        if channels != 1 or colour_filter != 0 or (length_y, length_x) != tuple(size) or pos_x or pos_y:
            meta["frames_skipped"] = meta.get("frames_skipped", 0) + 1
            continue
        n = length_x * length_y
        if 4 * FRAME_FIELDS + 2 * n > step:
            raise EventDataError(f"{path}: a frame of {length_x}x{length_y} pixels does not fit its {step}-byte "
                                 "event; the file is damaged")
        pixels = np.frombuffer(raw, "<u2", n, k * step + 4 * FRAME_FIELDS).reshape(length_y, length_x)
        if fields[3] < 0 or fields[4] < fields[3]:
            raise EventDataError(f"{path}: a frame exposed from {int(fields[3])} to {int(fields[4])} us (a negative or "
                                 "reversed exposure); the file is damaged")
        t_us = ((h.overflow << 32) + int(fields[3]) + int(fields[4])) // 2     # the middle of the exposure
        yield t_us, to_grey_uint8(pixels, f"{path}: frame at {t_us} us")


@contextmanager
def _decoded(path: Path, sensor_size=None):
    """Open the file: yields (sensor size (H, W), meta, packets), packets yielding ("events", packet) with packet
    a structured array (t [us], x, y, on), and ("frame", t_us, grey uint8 image)."""
    lines, start = aedat3_header(path)
    sources, xml_size = _header_fields(path, lines)
    file_size = path.stat().st_size
    with open(path, "rb") as f:
        source = next((h.source for h, n in _packet_headers(f, start, file_size, path) if h.type == POLARITY and n),
                      None)
        if source is None:
            raise EventDataError(f"{path}: the AEDAT 3.1 file holds no polarity (DVS) events; record events "
                                 "with the camera's DVS enabled")
        device = sources.get(source)
        declared = xml_size or _device_size(device)
        size = declared_or_given_size(path, declared, sensor_size, "header",
                                      f"the header does not give the sensor size (source {source}: "
                                      f"{device or 'no device named'}); pass sensor_size=(H, W), e.g. (128, 128) for a "
                                      "DVS128, (180, 240) for a DAVIS240, (260, 346) for a DAVIS346")
        meta = {"format": "aedat3", "path": str(path), "source": source, "device": device,
                "sources": {str(k): v for k, v in sorted(sources.items())},
                "sensor_size_from": ("header" if xml_size else "device name") if declared is not None
                else "sensor_size argument"}

        def packets():
            batch, n_batch = [], 0          # polarity packets (header, bytes), decoded together
            for h, n in _packet_headers(f, start, file_size, path):
                if h.source != source or h.type not in (POLARITY, FRAME) or n == 0:
                    continue
                raw = f.read(n)
                if len(raw) != n:
                    raise EventDataError(f"{path}: the file ended inside a packet (a truncated copy?); copy it again")
                if h.type == POLARITY:
                    batch.append((h, raw))
                    n_batch += h.number
                    if n_batch >= BATCH_EVENTS:
                        yield "events", _polarity(batch, path)
                        batch, n_batch = [], 0
                else:
                    if batch:
                        yield "events", _polarity(batch, path)
                        batch, n_batch = [], 0
                    for t_us, image in _frames(raw, h, size, path, meta):
                        yield "frame", t_us, image
            if batch:
                yield "events", _polarity(batch, path)

        yield size, meta, packets()


def read_aedat3(path, *, sensor_size=None, t_start: float | None = None, t_end: float | None = None):
    """An AEDAT 3.1 recording (cAER / libcaer: DVS128, DAVIS) as a Recording.

    Args:
        path: the ``.aedat`` file.
        sensor_size: (H, W): needed when the header names no known device and no size (then it is an error
            to leave it out); checked against the header's otherwise.
        t_start, t_end: seconds relative to ``t_origin``; only events and frames with t_start <= t < t_end
            are kept, memory holds only them.
    Returns:
        Recording(events, frames or None, meta) with meta["format"] = "aedat3", the source read and its device.
    """
    path = existing(path)
    t_start, t_end = check_reader_window(t_start, t_end)   # 0-d, Fraction, Decimal: floats
    return read_packets(path, _decoded, sensor_size=sensor_size, t_start=t_start, t_end=t_end, frames_from=frames_from)


def open_aedat3(path, *, sensor_size=None) -> PacketSource:
    """A :class:`~evinr_lite.io.source.RecordingSource` over an AEDAT 3.1 file (windows decoded in order)."""
    return PacketSource(existing(path), _decoded, sensor_size=sensor_size, format="aedat3", frames_from=frames_from)


def _sniff(path, head) -> bool:
    return head is not None and head.startswith(MAGIC)


FORMAT = FileFormat(
    name="aedat3", description="an AEDAT 3.1 file (.aedat, cAER / DVS128 / DAVIS, with its frames)",
    reader=read_aedat3, suffixes=(".aedat",), sniff=_sniff, takes_sensor_size=True, time_unit="us", windowed=True,
    open_source=open_aedat3)
