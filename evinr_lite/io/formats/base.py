"""What every format module declares (:class:`FileFormat`), and the checks the readers share.

A format module (``npy.py``, ``txt.py``, ``ijrr.py``, ...) defines its reader and one
``FORMAT = FileFormat(...)`` (or ``FORMATS = (...)``) that says how to recognise the format and what
its reader accepts. :mod:`.registry` collects them; detection, ``read_recording``,
``SUPPORTED_FORMATS`` and the capability tables are derived from these declarations.
"""
from __future__ import annotations

import json
import math
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

# check_reader_window is re-exported: the readers' window check lives in core.checks
from ...core.checks import ArgumentTypeError, check_path_type, check_reader_window
from ...core.events import (MAX_SENSOR_SIDE, EventDataError, Events, check_sensor_size, check_time_span, fall_back_hint,
                            relative_seconds, resolve_time_unit)
from ..text import read_text_bytes

__all__ = ["FileFormat", "existing", "load_npy", "to_seconds", "build_events", "size_hint", "sensor_from_header",
           "json_file", "size_value", "plain_attr", "check_declared_size", "declared_or_given_size",
           "check_reader_window", "Clock", "bisect_seconds", "probe_sorted",
           "note_decimal_seconds", "frames_on_event_clock", "SLOW_SECONDS_RATE",
           "check_time_spread", "same_time_message", "check_frame_times", "check_finite_images", "own_meta",
           "file_path"]



@dataclass(frozen=True)
class FileFormat:
    """One recording format, as its module declares it.

    Attributes:
        name: the format's name (``detect_format``'s answer, ``meta["format"]``).
        description: one phrase for the list of supported formats.
        reader: ``reader(path, **options) -> Recording``.
        folder: True for a folder format (IJRR, EVREAL), False for a single file.
        suffixes: file name endings taken as this format when a folder of recordings is scanned (lower case).
        sniff: ``sniff(path, head) -> bool``: the content is this format (``head``: the file's first
            64 bytes; None for a folder). Formats are tried in the registry's order.
        by_suffix: also taken by its suffix alone when no format's content matched (text files).
        needs_sensor_size: the file may not record the sensor size (then ``sensor_size=`` is needed).
        takes_sensor_size: the reader accepts ``sensor_size=`` (to supply or check it).
        time_unit: the unit the format fixes for its timestamps ('us', 's'), or None when the reader
            takes ``time_unit=`` (the file does not say).
        windowed: the reader takes ``t_start=`` / ``t_end=`` and reads only that window from disk.
        open_source: ``open_source(path, **options) -> RecordingSource`` that reads only each window
            (None: the recording is read once and sliced in memory).
        options: the reader's other keyword options (for messages and the command line).
        priority: formats are tried by ascending priority (a more specific format first: the
            canonical h5 before the generic HQF h5; text, recognised by its suffix, last).
    """

    name: str
    description: str
    reader: Callable
    folder: bool = False
    suffixes: tuple[str, ...] = ()
    sniff: Callable | None = None
    by_suffix: bool = False
    needs_sensor_size: bool = False
    takes_sensor_size: bool = False
    time_unit: str | None = None
    windowed: bool = False
    open_source: Callable | None = None
    options: tuple[str, ...] = field(default=())
    priority: int = 50


# ---- checks shared by the readers -----------------------------------------------------------

def existing(path, kind: str = "file") -> Path:
    """``path`` as a Path when it is an existing non-empty regular file (``kind='file'``) or a folder; None, a
    number or a list is an ArgumentTypeError naming ``path=`` (``folder=`` for a folder), not Python's TypeError."""
    name = "folder" if kind == "folder" else "path"
    path = Path(check_path_type(path, name, f"the recording's {kind}"))
    if not path.exists():
        raise EventDataError(f"no such {kind}: {path}; check the path")
    mode = path.stat().st_mode
    if kind == "folder" and not stat.S_ISDIR(mode):
        raise EventDataError(f"{path} is not a folder; pass the recording's folder")
    if kind == "file" and stat.S_ISDIR(mode):
        raise EventDataError(f"{path} is a folder, not a file; pass the file")
    if kind == "file" and not stat.S_ISREG(mode):
        raise EventDataError(f"{path} is not a regular file (a FIFO, pipe or device); save the data to a file first")
    if kind == "file" and path.stat().st_size == 0:
        raise EventDataError(f"{path} is empty (0 bytes): a copy, download or export that did not finish; get "
                             "the recording again")
    return path


def file_path(path) -> Path:
    """``path`` as a Path when it names something that exists and is no folder: a regular file (an empty one too:
    a header helper reads nothing there), or a FIFO or device such as /dev/null (read as any file: its first bytes);
    None, a number, a folder or a missing file is :func:`existing`'s error (Python's TypeError or OSError)."""
    path = Path(check_path_type(path, "path", "the recording's file"))
    return path if path.exists() and not path.is_dir() else existing(path)


def own_meta(reader: str, fmt: str, path, options: dict) -> dict:
    """The meta dict a ``read_<fmt>(path, **options)`` Recording reader makes itself; a ``meta=`` among the options
    (Python's "got multiple values for keyword argument 'meta'") is an ArgumentTypeError naming the fix."""
    if "meta" in options:
        raise ArgumentTypeError(f"{reader}: meta= is not an option here; the Recording's .meta holds the notes (or "
                                f"call read_events_{fmt}(path, meta=your_dict))")
    return {"format": fmt, "path": str(path)}


def _holds_objects(path: Path) -> bool:
    """Whether the .npy file's header (read without loading anything) declares a dtype that holds Python objects."""
    try:
        with open(path, "rb") as f:
            version = np.lib.format.read_magic(f)
            header = (np.lib.format.read_array_header_1_0 if version == (1, 0) else
                      np.lib.format.read_array_header_2_0)(f)
        return header[2].hasobject
    except Exception:   # a damaged header: the caller's message says so
        return False


def load_npy(path: Path, *, mmap: bool = False):
    """np.load of one plain array (memory-mapped when ``mmap``), every failure an EventDataError naming the file."""
    try:   # memory-mapped first: a damaged header that claims more data than the file holds fails, not allocates
        array = np.load(path, allow_pickle=False, mmap_mode="r")
        return array if mmap or not isinstance(array, np.memmap) else np.array(array)
    except Exception as err:   # numpy raises ValueError, SyntaxError, TokenError, OSError, ... on a damaged header
        if _holds_objects(path):   # a whole file, saved with allow_pickle: not damaged, but never unpickled here
            raise EventDataError(f"{path}: not a readable numeric .npy array: it holds Python objects (dtype object, "
                                 "saved with allow_pickle), which are not loaded (unpickling can run any code); save "
                                 "the numbers themselves: np.save(path, np.asarray(a, dtype=np.float64))") from None
        raise EventDataError(f"{path}: not a readable numeric .npy array ({type(err).__name__}: {err}); the file is "
                             "damaged or incomplete, or not saved with np.save(path, array)") from None


def to_seconds(source, t, time_unit):
    """Timestamps in their unit (detected when time_unit is 'auto'/None) -> (seconds relative to origin,
    origin, unit), the span checked for plausibility (and refused when every timestamp is the same)."""
    unit = resolve_time_unit(t, time_unit, source)
    t, origin = relative_seconds(t, unit)
    if t.size >= 2 and np.all(np.isfinite(t)):
        check_time_spread(float(np.min(t)), float(np.max(t)), t.size, source)
    check_time_span(t, source, unit)
    return t, origin, unit


def same_time_message(source, n: int, t: float, window=None) -> str:
    """The message for ``n`` >= 2 events that all have the timestamp ``t`` (seconds): they span no time."""
    if window is not None:
        return (f"{source}: the {n:,} events in the window [{window[0]}, {window[1]}) s all have the same timestamp "
                f"({t!r} s), so they span no time and nothing can be reconstructed; choose a longer window (see "
                "`evinr-lite info` for the time span)")
    return (f"{source}: all {n:,} events have the same timestamp ({t!r} s on the recording's clock), so they span no "
            "time and nothing can be reconstructed; the timestamps are damaged (or another column was read as the "
            "time): re-export the recording with each event's own timestamp")


def check_time_spread(first: float, last: float, n: int, source) -> None:
    """Refuse ``n`` >= 2 events whose earliest and latest timestamps (seconds) are equal: every event at one
    instant is a damaged time column (or another column read as the time), not a recording. Checked before
    :func:`~evinr_lite.core.events.check_time_span`, whose advice (another time unit) would not help."""
    if n >= 2 and first == last:
        raise EventDataError(same_time_message(source, n, first))


def check_frame_times(frames, source) -> None:
    """Refuse ground-truth frames two of which share a timestamp (seconds): each frame is scored against the
    reconstruction at its own time, so two frames at one instant are a damaged frame list."""
    if frames is None or len(frames) < 2:
        return
    t = np.sort(np.asarray(frames.t, dtype=np.float64))
    same = np.flatnonzero(np.diff(t) == 0)
    if same.size:
        verb = "repeats" if same.size == 1 else "repeat"
        raise EventDataError(f"{source}: {same.size} of the {len(t)} frames {verb} the timestamp of another frame "
                             f"(e.g. two frames at t = {t[same[0]]:.6f} s); each ground-truth frame needs its own "
                             "time: correct the frame timestamps or remove the duplicated frames")


def check_finite_images(images, source) -> None:
    """Refuse floating-point frames holding NaN or infinity (a damaged image; uint8 frames cannot)."""
    images = np.asarray(images)
    if images.dtype.kind == "f" and not np.all(np.isfinite(images)):
        raise EventDataError(f"{source}: the frame holds NaN or infinite pixel values; the image is damaged: "
                             "replace it, or remove the frame")


def build_events(source, t, x, y, p, sensor_size, *, polarity, t_origin=0.0, sort=False) -> Events:
    """Events.from_arrays with the file named in any error message."""
    try:
        return Events.from_arrays(t, x, y, p, sensor_size, polarity=polarity, sort=sort, t_origin=t_origin)
    except EventDataError as err:
        raise EventDataError(f"{source}: {err}") from None


def size_hint(x, y) -> str:
    """The smallest sensor the coordinates fit, as a hint for a message asking for the sensor size."""
    if len(x) == 0:
        return ""
    return (f"; the events span x (column) 0..{int(np.max(x))} and y (row) 0..{int(np.max(y))}, "
            f"so the smallest sensor that fits is ({int(np.max(y)) + 1}, {int(np.max(x)) + 1}), "
            "but use the camera's real size, e.g. (180, 240) for a DAVIS240C")


def sensor_from_header(path, header, sensor_size):
    """Reconcile a `W H` header (given as (H, W)) with a sensor_size argument; a header of 0 or beyond
    :data:`MAX_SENSOR_SIDE` pixels per side is refused (a damaged first line)."""
    if sensor_size is not None:   # 5, "a", (nan, W): Python's errors; (12.5, W): 12 rows without a word
        sensor_size = check_sensor_size(sensor_size)
    if header is not None and not all(0 < v <= MAX_SENSOR_SIDE for v in header):
        H, W = header
        raise EventDataError(f"{path}: the header line `{W} {H}` (width first) gives a sensor of {H}x{W} (H x W), "
                             f"which no event camera has (1 to {MAX_SENSOR_SIDE} pixels per side); the first line is "
                             "damaged: write the camera's `W H` there, or remove it and pass sensor_size=(H, W)")
    if header is None or sensor_size is None:
        return sensor_size if header is None else header
    if tuple(int(v) for v in sensor_size) != header:
        H, W = header
        raise EventDataError(
            f"{path}: the header line `{W} {H}` (width first) means sensor_size (H, W) = {header}, "
            f"but sensor_size={tuple(sensor_size)} was passed; pass sensor_size={header} or leave it out"
        )
    return header


def check_declared_size(path, declared, sensor_size, where: str):
    """The file's (H, W), or an error when a different sensor_size was asked for (or one that is no (H, W))."""
    if sensor_size is not None:
        sensor_size = check_sensor_size(sensor_size)
    if sensor_size is not None and tuple(int(v) for v in sensor_size) != declared:
        H, W = declared
        raise EventDataError(f"{path}: the {where} says the sensor is (H, W) = {declared} ({H}x{W}), but sensor "
                             f"size {tuple(int(v) for v in sensor_size)} was given; leave the sensor size out "
                             "(the file's is used) or pass the file's")
    return declared


def declared_or_given_size(path, declared, sensor_size, where: str, missing: str) -> tuple[int, int]:
    """The sensor size (H, W) of a file that may declare one: ``declared`` (checked as :func:`size_value` does,
    then against ``sensor_size`` by :func:`check_declared_size`), else ``sensor_size``; with neither, an
    EventDataError "{path}: {missing}" (which should say what to pass)."""
    if declared is not None:
        return check_declared_size(path, size_value(path, declared, f"the {where}'s sensor size"), sensor_size, where)
    if sensor_size is None:
        raise EventDataError(f"{path}: {missing}")
    return check_sensor_size(sensor_size)   # int() of each made (12.5, W) 12 rows; 5 or "a" were Python's errors


def json_file(path: Path) -> dict:
    """A JSON object from a file, or an EventDataError naming the file."""
    try:
        data = json.loads(read_text_bytes(path, "JSON file").decode("utf-8"))
    except UnicodeDecodeError as err:
        raise EventDataError(f"{path}: not UTF-8 text ({err}); save it as UTF-8 JSON") from None
    except json.JSONDecodeError as err:
        raise EventDataError(f"{path}: not valid JSON ({err}); expected e.g. {{\"sensor_resolution\": [H, W]}}") from None
    if not isinstance(data, dict):
        raise EventDataError(f"{path}: expected a JSON object such as {{\"sensor_resolution\": [H, W]}}, "
                             f"got {type(data).__name__}")
    return data


def size_value(source, value, name) -> tuple[int, int]:
    """A stored (H, W) -> two positive ints, or an EventDataError naming where it came from."""
    try:
        a = np.asarray(value).ravel()
        if a.size != 2 or a.dtype.kind not in "iuf" or not np.all(np.isfinite(a)) or np.any(a != np.round(a)) \
                or np.any(a <= 0):
            raise ValueError
    except (ValueError, TypeError):
        raise EventDataError(f"{source}: {name} must be (H, W), two positive whole numbers; got {value!r}") from None
    if np.any(a > MAX_SENSOR_SIDE):
        raise EventDataError(f"{source}: {name} is {int(a[0])}x{int(a[1])} (H x W), larger than any event camera (at "
                             f"most {MAX_SENSOR_SIDE} pixels per side); the value is damaged: write the camera's real "
                             "size (H, W)")
    return int(a[0]), int(a[1])


def plain_attr(value):
    """An HDF5 attribute as a plain value (bytes decoded)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    return value


class Clock:
    """File timestamps (in ``unit``, integer or float) <-> float64 seconds relative to a whole-second origin.

    The origin is that of :func:`~evinr_lite.core.events.relative_seconds` for a recording whose
    earliest timestamp is ``first`` (its whole seconds on an absolute clock, else 0): reading a window
    through a Clock gives the same seconds as reading the whole file and slicing it. Integer
    timestamps are shifted in integer arithmetic before the division, so nothing is lost.
    """

    def __init__(self, first, unit: str, integer: bool):
        from ...core.events import LARGE_T, TIME_UNITS, auto_origin

        self.unit, self.integer = unit, integer
        self.per_s = round(1 / TIME_UNITS[unit])
        if integer:
            first = int(first)
            self.origin_units = (first // self.per_s) * self.per_s if abs(first) >= LARGE_T * self.per_s else 0
            self.origin = float(self.origin_units // self.per_s)
        else:
            self.origin = auto_origin(float(first) / self.per_s)

    def seconds(self, raw) -> np.ndarray:
        """File timestamps -> float64 seconds relative to the origin."""
        raw = np.asarray(raw)
        if self.integer:
            return (raw.astype(np.int64) - self.origin_units) / self.per_s
        return raw.astype(np.float64) / self.per_s - self.origin


def bisect_seconds(column, clock: Clock, value: float, lo: int, hi: int, source=None) -> int:
    """First index in [lo, hi) whose time (in seconds, through ``clock``) is >= ``value``, reading
    single elements of ``column`` (an on-disk dataset or memory map: O(log N) reads, not N). A non-finite
    element met on the way is refused (it compares as neither earlier nor later, so the search would silently
    cut the window there and skip the events after it)."""
    while lo < hi:
        mid = (lo + hi) // 2
        seconds = float(clock.seconds(column[mid]))
        if not math.isfinite(seconds):
            where = f"{source}: " if source is not None else ""
            raise EventDataError(f"{where}timestamp {mid} is {seconds} (non-finite); drop or repair those events "
                                 "before loading")
        if seconds < value:
            lo = mid + 1
        else:
            hi = mid
    return lo


def probe_sorted(column, source, n_probe: int = 1025, also: str = "") -> None:
    """Refuse a timestamp column that is evidently not sorted, from about ``n_probe`` evenly spaced
    elements (a window is found by bisection, which needs sorted times); a full read checks them all.
    ``also``: a format's own way out, added to the fix (e.g. its reader's ``sort=True``)."""
    n = column.shape[0]
    if n < 2:
        return
    idx = np.unique(np.linspace(0, n - 1, min(n, n_probe)).astype(np.int64))
    values = np.array([column[int(i)] for i in idx])
    if values.dtype.kind == "f" and not np.all(np.isfinite(values)):   # a window search would stop at it
        bad = int(idx[np.flatnonzero(~np.isfinite(values))[0]])
        raise EventDataError(f"{source}: timestamp {bad} is {float(column[bad])} (non-finite); drop or repair those "
                             "events before loading")
    down = np.flatnonzero(np.diff(values) < 0)
    if down.size:
        a, b = int(idx[down[0]]), int(idx[down[0] + 1])
        raise EventDataError(f"{source}: the timestamps are not sorted (t[{a}] = {float(values[down[0]])!r} > "
                             f"t[{b}] = {float(values[down[0] + 1])!r}), so a time window cannot be found without "
                             f"reading everything; sort the events by time and save the file again{also}"
                             + fall_back_hint(down.size, values[down[0]], values[down[0] + 1]))


# ---- one clock, plausible units ------------------------------------------------------------

SLOW_SECONDS_RATE = 1e3   # events per second; decimal timestamps read as seconds that come slower get a note


def note_decimal_seconds(t_first: float, t_last: float, n: int, time_unit, unit: str, source, meta) -> None:
    """Decimal timestamps taken as seconds by detection (``time_unit`` 'auto' / None) that come at under
    :data:`SLOW_SECONDS_RATE` events per second look like milliseconds (0.5 s written in ms reads as
    500 s): say so, with the override, in a note. A unit given explicitly is taken as given."""
    from ...core.events import MAX_RATE_PER_S, MAX_SPAN_S, MIN_RATE_PER_S
    from ..notes import note

    span = float(t_last - t_first)
    if time_unit not in (None, "auto") or unit != "s" or n < 1000 or not span > 0:
        return
    rate = n / span
    if span > MAX_SPAN_S or rate < MIN_RATE_PER_S:   # implausible in seconds: check_time_span's error says it all
        return
    if rate < SLOW_SECONDS_RATE and rate * 1e3 <= MAX_RATE_PER_S:
        note(meta, f"{source}: the decimal timestamps were read as seconds, so the {n:,} events span {span:,.6g} s "
                   f"at only {rate:,.3g} events per second; that is more like milliseconds ({span / 1e3:,.6g} s at "
                   f"{rate * 1e3:,.3g} per second): if they are milliseconds, pass time_unit='ms'")


def _plausible_frames(t: np.ndarray, span: tuple[float, float]) -> bool:
    """Frame times (s) that can belong to events spanning ``span``: finite, within the span widened by half
    its length (at least 1 s) on each side, and at most 100,000 frames per second apart."""
    e0, e1 = span
    pad = max(0.5 * (e1 - e0), 1.0)
    if not np.all(np.isfinite(t)) or np.any(t < e0 - pad) or np.any(t > e1 + pad):
        return False
    steps = np.diff(np.sort(t))
    steps = steps[steps > 0]
    return steps.size == 0 or float(np.median(steps)) >= 1e-5


def _evident_frames(t: np.ndarray, span: tuple[float, float]) -> bool:
    """Frame times (s) read in another unit that evidently belong to events spanning ``span``: plausible,
    at least half of them inside the span, and (two frames or more) spread over at least 1 % of it, so
    that units 1000 times apart cannot both qualify."""
    e0, e1 = span
    if not _plausible_frames(t, span) or np.mean((t >= e0) & (t <= e1)) < 0.5:
        return False
    return len(t) < 2 or float(np.max(t) - np.min(t)) >= 0.01 * (e1 - e0)


def frames_on_event_clock(frame_seconds, unit: str, span: tuple[float, float] | None, source, meta, *,
                          what: str = "the frame timestamps"):
    """The frames' times in seconds on the events' clock, checked to be on it.

    Args:
        frame_seconds: ``frame_seconds(u)`` -> float64 [F]: the stored frame stamps read in unit ``u``
            as seconds relative to the events' ``t_origin``.
        unit: the unit the events were read in (the frames' unit unless evident otherwise).
        span: (first, last) event time in seconds (None: no events, nothing to check against).
    Returns:
        (times [F] seconds, the unit used for the frames).
    Raises:
        EventDataError naming both spans and the fix when the frames are on another clock and no
        other unit (s, ms, us, ns) evidently puts them on the events' (an offset between an absolute
        and a relative clock cannot be derived exactly, so it is refused, not guessed).
    """
    from ...core.events import TIME_UNITS
    from ..notes import note

    t = frame_seconds(unit)
    if span is None or span[1] <= span[0] or not len(t) or _plausible_frames(t, span):
        return t, unit
    fits = [u for u in TIME_UNITS if u != unit and _evident_frames(frame_seconds(u), span)]
    first, last = float(np.min(t)), float(np.max(t))
    if len(fits) == 1:
        note(meta, f"{source}: {what} read in {unit!r} span {first:,.6g} .. {last:,.6g} s, outside the events' "
                   f"{span[0]:,.6g} .. {span[1]:,.6g} s; read in {fits[0]!r} they lie on the events' clock, so they "
                   f"are taken as {fits[0]}")
        return frame_seconds(fits[0]), fits[0]
    raise EventDataError(
        f"{source}: the frames and the events are not on one clock: {what} span {first:,.6g} .. {last:,.6g} s but "
        f"the events span {span[0]:,.6g} .. {span[1]:,.6g} s (both read in {unit!r}, relative to the events' "
        "t_origin), and no other unit (s, ms, us, ns) puts them together; write the frame timestamps on the events' "
        "clock (same unit, same zero: both absolute or both relative to the same start), or pass time_unit= if "
        "the events' unit was guessed wrong")
