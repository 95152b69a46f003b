"""An IJRR / Event Camera Dataset sequence folder (the unzipped text release): events.txt,
images.txt with images/, calib.txt.

Absolute clocks (IJRR: about 1.47e9 s written with 9 decimals) do not fit float64 at nanosecond
resolution; the text parser (:mod:`evinr_lite.io.text`) subtracts a whole-second ``t_origin``
exactly before any float is formed, and the frames are read on the events' origin.
"""
from __future__ import annotations

from collections.abc import Mapping, MutableMapping, Set as AbstractSet
from pathlib import Path

import numpy as np

from ...core.checks import checked_span, require, short_repr
from ...core.events import EventDataError, check_sensor_size, check_time_span
from ...core.frames import Frames, to_grey_uint8
from ...core.recording import Recording
from ..text import NS, origin_to_ns, parse_event_text, parse_frame_list, read_text_bytes
from ..notes import note
from .base import (FileFormat, build_events, check_time_spread, existing, frames_on_event_clock, note_decimal_seconds,
                   sensor_from_header, size_hint)

__all__ = ["read_ijrr_folder", "read_frames_ijrr", "FORMAT", "IMAGE_SIGNATURES"]

IMAGE_SIGNATURES = {   # first bytes of the image files a frame list may name -> their kind
    b"\x89PNG\r\n\x1a\n": "PNG", b"\xff\xd8\xff": "JPEG", b"II*\x00": "TIFF", b"MM\x00*": "TIFF", b"BM": "BMP",
    b"GIF87a": "GIF", b"GIF89a": "GIF", b"P2": "PGM", b"P5": "PGM", b"P3": "PPM", b"P6": "PPM",
}


def _check_image_file(image_path: Path, listing: Path) -> None:
    """Refuse a listed frame that is empty, or text where an image belongs (the common mistakes), by its
    first bytes, before an image library tries each of its plugins on it (and prints their notes). Binary
    files of a kind not listed in IMAGE_SIGNATURES are left to the image library, which may know them."""
    with open(image_path, "rb") as f:
        head = f.read(16)
    if not head:
        raise EventDataError(f"{image_path}: the image file is empty (0 bytes); copy it again, or remove its line "
                             f"from {listing.name}")
    text_like = all(32 <= b < 127 or b in b"\t\r\n" for b in head)
    if text_like and not any(head.startswith(magic) for magic in IMAGE_SIGNATURES):
        raise EventDataError(f"{image_path}: not an image file (it starts with {head[:8]!r}, no PNG, JPEG, TIFF, "
                             f"BMP, GIF or PGM signature); replace it with the frame, or remove its line from "
                             f"{listing.name}")


def _pair(span) -> tuple:
    """``span`` as two values (``checked_span`` checks them), or an EventDataError naming events_span=."""
    try:
        if isinstance(span, (str, bytes, Mapping, AbstractSet)):   # a dict or set: its keys, in hash order
            raise TypeError
        a, b = span
    except (TypeError, ValueError):
        raise EventDataError(f"events_span= must be (t_start, t_end) in seconds on the frames' clock (a tuple, list "
                             f"or array, not a dict or set), or None; got {short_repr(span)}") from None
    return a, b


def read_frames_ijrr(folder, t_origin=0.0, *, time_unit: str = "s", events_span=None, meta: dict | None = None) -> Frames:
    """Frames listed in ``folder/images.txt`` (`t images/frame_%08d.png` per line), in time order.

    Args:
        folder: the IJRR sequence folder.
        t_origin: seconds subtracted exactly from the timestamps (pass the events' ``t_origin``);
            None: automatic, as for the events.
        time_unit: unit of the timestamps (the events' unit), 's' by default.
        events_span: (first, last) event time in seconds on the same origin: the frames are checked to
            be on the events' clock (another unit that evidently fits is taken with a note, anything
            else refused; see :func:`~evinr_lite.io.formats.base.frames_on_event_clock`).
        meta: where notes go (``meta["read_notes"]``).
    Returns:
        Frames with grey uint8 images [F, H, W] (RGB is converted to grey), sorted by time (with a
        note when images.txt lists them out of order).
    """
    from skimage.io import imread

    folder = existing(folder, "folder")
    require(meta, MutableMapping, "meta", none_ok=True)   # a number or text: the notes were dropped without a word
    if events_span is not None:   # "a" or 5: an IndexError; (1, 0) or NaN: taken as no span, without a word
        events_span = checked_span(*_pair(events_span), "events_span")
    listing = folder / "images.txt"
    if not listing.exists():
        raise EventDataError(f"{folder}: no images.txt, so no frames; expected lines `t images/frame_%08d.png`")
    try:
        data = read_text_bytes(listing, "frame list")
    except EventDataError as err:
        if "is empty" not in str(err):
            raise
        data = b""
    origin = None if t_origin is None else origin_to_ns(t_origin)
    t, names, origin_ns = parse_frame_list(data, origin, source=listing, time_unit=time_unit)
    if not names:
        raise EventDataError(f"{listing} lists no frames; expected lines `t images/frame_%08d.png` "
                             "(or remove images.txt and give the sensor size)")
    if events_span is not None:
        t, _ = frames_on_event_clock(
            lambda u: t if u == time_unit else parse_frame_list(data, origin_ns, source=listing, time_unit=u)[0],
            time_unit, events_span, listing, meta)
    if np.any(np.diff(t) < 0):
        note(meta, f"{listing}: the frames are not listed in time order; they are read sorted by their timestamps")
    images = []
    for name in names:
        image_path = folder / name
        if not image_path.is_file():
            missing = sum(not (folder / n).is_file() for n in names)
            raise EventDataError(f"{listing} lists {image_path.name}, but {image_path} does not exist (or is not a file)"
                                 + (f"; {missing} of its {len(names)} frames are missing" if missing > 1 else "")
                                 + ": copy the images back, remove the missing ones' lines from images.txt, or move "
                                 "images.txt aside to read the events alone (with --sensor HxW)")
        _check_image_file(image_path, listing)
        try:
            image = imread(image_path)
        except Exception as err:   # Pillow / imageio raise many types on a damaged image
            raise EventDataError(f"{image_path}: not a readable image ({type(err).__name__}: {err}); the file is "
                                 "damaged: replace it or remove its line from images.txt") from None
        images.append(to_grey_uint8(image, image_path))
    shapes = {im.shape for im in images}
    if len(shapes) > 1:
        raise EventDataError(f"{listing}: the frames have different sizes {sorted(shapes)}; all must share one (H, W)")
    try:
        return Frames(np.stack(images), t, origin_ns / NS).sorted()
    except EventDataError as err:
        raise EventDataError(f"{listing}: {err}") from None


def _read_calib(path: Path) -> dict | list:
    """calib.txt's numbers: {fx, fy, cx, cy, k1, k2, p1, p2, k3} when there are nine, else the list ([] when empty)."""
    if not path.read_bytes().strip():   # np.loadtxt would warn (a note on the command line) and give the same []
        return []
    values = np.loadtxt(path, ndmin=1).ravel().tolist()
    names = ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")
    return dict(zip(names, values)) if len(values) == len(names) else values


def read_ijrr_folder(folder, *, t_origin=None, sensor_size=None, time_unit="auto") -> Recording:
    """An IJRR / Event Camera Dataset sequence folder (the unzipped text release).

    Reads events.txt (p in {0, 1}), the frames of images.txt on the events' clock, and calib.txt
    (``meta["calib"] = {fx, fy, cx, cy, k1, k2, p1, p2, k3}``) when present. The sensor size is the
    frames' (H, W) (or a `W H` header of events.txt when there are no frames).

    Args:
        t_origin: seconds subtracted from all timestamps; None: whole seconds of the first event
            when the clock is absolute (>= 1e5 s), else 0.
        sensor_size: (H, W); needed only when there are no frames and no `W H` header (then the
            events' size is unknown); checked against the frames / header otherwise.
        time_unit: unit of the timestamps of events.txt and images.txt ('auto': see
            :func:`read_events_txt`).
    """
    folder = existing(folder, "folder")
    events_path = folder / "events.txt"
    if not events_path.exists():
        raise EventDataError(f"{folder}: no events.txt; an IJRR folder holds events.txt, "
                             "images.txt, images/, calib.txt")
    if sensor_size is not None:   # whole numbers, before reading: (12.5, 12) was compared as (12, 12) and taken
        sensor_size = check_sensor_size(sensor_size)
    raw = parse_event_text(events_path, None if t_origin is None else origin_to_ns(t_origin), time_unit=time_unit)
    check_time_spread(float(raw.t[0]), float(raw.t[-1]), len(raw.t), events_path)   # sorted by the parser
    check_time_span(raw.t, events_path, raw.time_unit)
    meta = {"format": "ijrr", "path": str(folder), "time_unit": raw.time_unit}
    note_decimal_seconds(raw.t[0], raw.t[-1], len(raw.t), time_unit, raw.time_unit, events_path, meta)
    frames = (read_frames_ijrr(folder, t_origin=raw.origin_ns / NS, time_unit=raw.time_unit,
                               events_span=(float(raw.t[0]), float(raw.t[-1])), meta=meta)
              if (folder / "images.txt").exists() else None)
    known = sensor_from_header(events_path, raw.header, frames.size if frames is not None else None)
    if known is not None and sensor_size is not None and tuple(int(v) for v in sensor_size) != tuple(known):
        H, W = known
        raise EventDataError(f"{folder}: the frames (or header) say the sensor is (H, W) = {tuple(known)} ({H}x{W}) "
                             f"but sensor_size={tuple(int(v) for v in sensor_size)} was given; leave it out or pass "
                             f"sensor_size=({H}, {W})")
    sensor_size = known if known is not None else sensor_size
    if sensor_size is None:
        raise EventDataError(
            f"{folder}: no images.txt and no `W H` header in events.txt, so the sensor size is unknown; "
            f"pass sensor_size=(H, W){size_hint(raw.x, raw.y)}"
        )
    events = build_events(events_path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                           polarity="auto", t_origin=raw.origin_ns / NS)
    if (folder / "calib.txt").is_file():
        try:
            meta["calib"] = _read_calib(folder / "calib.txt")
        except (ValueError, OSError) as err:
            raise EventDataError(f"{folder / 'calib.txt'}: not a list of numbers ({err}); repair or remove it") from None
    return Recording(events, frames, meta)


def _sniff(path, head) -> bool:
    return head is None and (Path(path) / "events.txt").exists()


FORMAT = FileFormat(
    name="ijrr", description="an IJRR folder (events.txt, images.txt, images/, calib.txt)", reader=read_ijrr_folder,
    folder=True, sniff=_sniff, takes_sensor_size=True, options=("t_origin", "time_unit"), priority=0)
