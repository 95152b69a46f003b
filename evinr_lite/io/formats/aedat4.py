"""AEDAT4 (``.aedat4``): iniVation DAVIS / DVXplorer recordings written by the DV software.

Decoded by faery, packet by packet. The first event track is read, with the first frame track when
present (DAVIS APS frames; a frame's time is the timestamp the file gives it); the sensor size is
the event track's. Timestamps are integer microseconds (see :mod:`.decoding`). A window is read by
decoding packets from the start, keeping only those inside it and stopping after it; memory holds
only the window.
"""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

from ...core.events import EventDataError
from ...core.frames import to_grey_uint8
from .base import FileFormat, check_declared_size, check_reader_window, existing
from .decoding import decoder_failed, decoder_stderr
from .packets import PacketSource, frames_from, read_packets

__all__ = ["read_aedat4", "FORMAT", "MAGIC"]

MAGIC = b"#!AER-DAT4"


def _check_header(path: Path) -> None:
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


@contextmanager
def _decoded(path: Path, sensor_size=None):
    """Open the file: yields (sensor size (H, W), meta, packets) where packets yields ("events", packet)
    with packet a structured array (t [us], x, y, on) and ("frame", t_us, grey uint8 image)."""
    from faery.extension import aedat

    _check_header(path)
    try:
        decoder = aedat.Decoder(path)
    except BaseException as err:
        if not decoder_failed(err):
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
        size = check_declared_size(path, (int(H), int(W)), sensor_size, "event track")
        meta = {"format": "aedat4", "path": str(path),
                "tracks": [{"id": tr.id, "type": tr.data_type, "dimensions": tr.dimensions} for tr in tracks]}

        def packets():
            try:
                for track, packet in decoder:
                    if track.id == events_track.id:
                        yield "events", packet
                    elif frame_track is not None and track.id == frame_track.id:
                        yield "frame", int(packet.t), to_grey_uint8(packet.pixels, f"{path}: frame at {packet.t} us")
            except BaseException as err:
                if isinstance(err, (EventDataError, GeneratorExit)) or not decoder_failed(err):
                    raise
                raise EventDataError(f"{path}: the AEDAT4 file is damaged or truncated ({err})") from None

        yield size, meta, packets()


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
    with decoder_stderr():
        path = existing(path)
        t_start, t_end = check_reader_window(t_start, t_end)   # 0-d, Fraction, Decimal: floats
        return read_packets(path, _decoded, sensor_size=sensor_size, t_start=t_start, t_end=t_end,
                            frames_from=frames_from)


def open_aedat4(path, *, sensor_size=None) -> PacketSource:
    """A :class:`~evinr_lite.io.source.RecordingSource` over an AEDAT4 file (windows decoded in order)."""
    return PacketSource(existing(path), _decoded, sensor_size=sensor_size, format="aedat4",
                        frames_from=frames_from)


def _sniff(path, head) -> bool:
    return head is not None and head.startswith(MAGIC)


FORMAT = FileFormat(
    name="aedat4", description="an AEDAT4 file (.aedat4, DV / DAVIS, with its frames)", reader=read_aedat4,
    suffixes=(".aedat4",), sniff=_sniff, takes_sensor_size=True, time_unit="us", windowed=True,
    open_source=open_aedat4)
