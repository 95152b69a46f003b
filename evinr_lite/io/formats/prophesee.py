"""Prophesee recordings: EVT 2 / 3 ``.raw`` and DAT ``.dat`` (CD events), decoded by faery, and EVT 2.1
``.raw``, which faery 0.7.1 does not decode, by :mod:`.evt21` (numpy).

The sensor size comes from the header (``% geometry`` / ``% format ...;width=;height=`` /
``% Width`` ``% Height``); some files carry none, and then ``sensor_size`` must be given. No frames.
Timestamps are integer microseconds (see :mod:`.decoding`); a window is read by decoding packets in
order and stopping after it.
"""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ...core.checks import whole_number
from ...core.events import EventDataError
from ...core.recording import Recording
from .base import FileFormat, check_declared_size, check_reader_window, declared_or_given_size, existing, file_path
from .decoding import PacketCollector, decoder_failed, decoder_stderr, percent_header
from .evt21 import evt21_packets, header_sensor_size, is_evt21, word_order
from .packets import PacketSource

__all__ = ["read_prophesee", "prophesee_header", "prophesee_kind", "RAW_VERSIONS", "FORMATS"]

RAW_VERSIONS = ("evt2", "evt21", "evt3")   # evt21 by .evt21 (faery 0.7.1 does not decode it)
SUFFIX_KIND = {".raw": "prophesee_raw", ".dat": "prophesee_dat"}


def prophesee_header(path: Path, limit: int = 1 << 16) -> list[str]:
    """The `% ...` header lines at the start of a Prophesee file (without the '% ')."""
    return percent_header(file_path(path), whole_number(limit, "limit", lo=1))[0]


def _names_encoding(header: list[str]) -> bool:
    """Whether a `%` header names a .raw file's encoding (an `evt ...` or `format EVT...` line)."""
    return any(line.lower().startswith(("evt ", "format evt")) for line in header)


def prophesee_kind(path, head: bytes | None) -> str | None:
    """'prophesee_raw' or 'prophesee_dat' for a file that opens with a `%` header (the header's words
    first, the suffix second), else None."""
    if head is None or not head.startswith(b"%"):
        return None
    header = [line.lower() for line in prophesee_header(Path(path))]
    if _names_encoding(header):
        return "prophesee_raw"
    if any(line.startswith(("data file containing", "version ")) for line in header):
        return "prophesee_dat"
    return SUFFIX_KIND.get(Path(path).suffix.lower())


@contextmanager
def _decoded(path: Path, sensor_size=None, version: str | None = None):
    """Open the file: yields (sensor size (H, W), meta, packets), packets yielding ("events", packet)
    with packet a structured array (t [us], x, y, on)."""
    from faery.extension import dat, evt

    with open(path, "rb") as f:
        head = f.read(64)
    kind = prophesee_kind(path, head) or SUFFIX_KIND.get(path.suffix.lower())
    if kind is None:
        raise EventDataError(f"{path}: not a Prophesee .raw or .dat file (no `%` header and no .raw/.dat extension)")
    if version is not None and version not in RAW_VERSIONS:
        raise EventDataError(f"version must be one of {RAW_VERSIONS}, got {version!r}")
    if kind == "prophesee_raw":
        header, offset = percent_header(path)
        if is_evt21(header) or (version == "evt21" and not _names_encoding(header)):
            yield _evt21(path, header, offset, sensor_size)
            return
    elif version == "evt21":
        raise EventDataError(f"{path}: version='evt21' applies to .raw files, not to a DAT file")
    module, fallback_version = (evt, version or "evt3") if kind == "prophesee_raw" else (dat, "dat2")
    fallback_size = None if sensor_size is None else (int(sensor_size[1]), int(sensor_size[0]))  # (W, H)
    try:
        decoder = module.Decoder(path, None, fallback_version)
        header_size = True
    except BaseException as err:
        if not decoder_failed(err):
            raise
        if "size" not in str(err):
            raise EventDataError(f"{path}: not a readable Prophesee file ({err})") from None
        header_size = False
        if fallback_size is None:
            raise EventDataError(f"{path}: the header does not give the sensor size; pass sensor_size=(H, W), "
                                 "e.g. (720, 1280) for an IMX636 / "
                                 "Gen4 sensor, (480, 640) for Gen3") from None
        decoder = module.Decoder(path, fallback_size, fallback_version)
    with decoder:
        W, H = decoder.dimensions
        size = (int(H), int(W))
        if header_size:
            size = check_declared_size(path, size, sensor_size, "header")
        if kind == "prophesee_dat" and getattr(decoder, "event_type", "cd") != "cd":
            raise EventDataError(f"{path}: a DAT file of {decoder.event_type!r} events; only CD (change "
                                 "detection) events can be reconstructed")
        meta = {"format": kind, "path": str(path), "encoding": getattr(decoder, "version", fallback_version),
                "sensor_size_from": "header" if header_size else "sensor_size argument"}

        def packets():
            try:
                for packet in decoder:
                    if kind == "prophesee_raw":
                        packet = packet.get("events")
                        if packet is None:
                            continue
                    else:
                        packet = _dat_to_events(packet)
                    yield "events", packet
            except BaseException as err:
                if isinstance(err, (EventDataError, GeneratorExit)) or not decoder_failed(err):
                    raise
                if "overflow" in str(err):
                    raise EventDataError(f"{path}: events lie outside the sensor size {size} (H, W) ({err}); pass "
                                         "the camera's real sensor size") from None
                hint = ("; if the header does not name the encoding (EVT 3 is assumed), pass version='evt2'"
                        if kind == "prophesee_raw" else "")
                raise EventDataError(f"{path}: could not decode the events ({err}){hint}") from None

        yield size, meta, packets()


def _evt21(path: Path, header: list[str], offset: int, sensor_size):
    """(size, meta, packets) of an EVT 2.1 file (``header`` and the data's ``offset``: :func:`percent_header`),
    as :func:`_decoded` yields them."""
    declared = header_sensor_size(header)
    size = declared_or_given_size(path, declared, sensor_size, "header",
                                  "the header does not give the sensor size; pass sensor_size=(H, W), e.g. (320, 320) "
                                  "for a GenX320 sensor, (720, 1280) for an IMX636")
    order = word_order(path, offset, size)
    meta = {"format": "prophesee_raw", "path": str(path), "encoding": "evt21", "word_order": order,
            "sensor_size_from": "header" if declared is not None else "sensor_size argument"}
    return size, meta, (("events", packet) for packet in evt21_packets(path, offset, order))


def read_prophesee(path, *, sensor_size=None, version: str | None = None,
                   t_start: float | None = None, t_end: float | None = None):
    """A Prophesee recording: EVT 2 / 2.1 / 3 ``.raw`` or DAT ``.dat`` (CD events) as a Recording.

    Args:
        path: the file.
        sensor_size: (H, W); needed only when the header does not give the size (then it is an
            error to leave it out); checked against the header otherwise.
        version: for a .raw whose header does not name its encoding: "evt2", "evt21" or "evt3"
            (default "evt3"); ignored when the header names it.
        t_start, t_end: seconds relative to ``t_origin`` (the whole seconds of the first event on an
            absolute clock); only events with t_start <= t < t_end are kept, memory holds only them.
    Returns:
        Recording(events, None, meta) with meta["format"] = "prophesee_raw" or "prophesee_dat".
    Raises:
        EventDataError naming the problem; the decoder's own messages (Rust panics on damaged
        input) are not printed.
    """
    with decoder_stderr():
        path = existing(path)
        t_start, t_end = check_reader_window(t_start, t_end)   # 0-d, Fraction, Decimal: floats
        collect = PacketCollector(t_start, t_end)
        with _decoded(path, sensor_size, version) as (size, meta, packets):
            for _, packet in packets:
                if not collect.add(packet):
                    break
        events = collect.events(path, size)
    return Recording(events, None, meta)


def open_prophesee(path, *, sensor_size=None, version: str | None = None) -> PacketSource:
    """A :class:`~evinr_lite.io.source.RecordingSource` over a Prophesee file (windows decoded in order)."""
    path = existing(path)
    with open(path, "rb") as f:
        kind = prophesee_kind(path, f.read(64)) or SUFFIX_KIND.get(path.suffix.lower())
    return PacketSource(path, _decoded, sensor_size=sensor_size, format=kind, version=version)


def _dat_to_events(packet: np.ndarray) -> np.ndarray:
    """DAT CD packet (t, x, y, payload 0/1) -> the (t, x, y, on) layout of the other decoders."""
    out = np.empty(len(packet), dtype=[("t", "<u8"), ("x", "<u2"), ("y", "<u2"), ("on", "?")])
    out["t"], out["x"], out["y"] = packet["t"], packet["x"], packet["y"]
    out["on"] = packet["payload"] > 0
    return out


def _sniff_raw(path, head) -> bool:
    return prophesee_kind(path, head) == "prophesee_raw"


def _sniff_dat(path, head) -> bool:
    return prophesee_kind(path, head) == "prophesee_dat"


_COMMON = dict(reader=read_prophesee, takes_sensor_size=True, time_unit="us", windowed=True,
               open_source=open_prophesee, options=("version",))
FORMATS = (
    FileFormat(name="prophesee_raw", description="a Prophesee EVT2/EVT2.1/EVT3 .raw file", suffixes=(".raw",),
               sniff=_sniff_raw, **_COMMON),
    FileFormat(name="prophesee_dat", description="a Prophesee DAT .dat file", suffixes=(".dat",), sniff=_sniff_dat,
               **_COMMON),
)
